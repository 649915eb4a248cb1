/* rcbtool frf: frequency response functions between output and input channels. */
#include <complex.h>
#include <stdlib.h>

#include "cli.h"

const char cli_help_frf[] =
    "usage: rcbtool frf MODEL.ini --out CH[,CH...] --in CH[,CH...] --fmax HZ\n"
    "                   [--fmin HZ] [--points N] [--rpm R | --synchronous]\n"
    "                   [--kind receptance|mobility|inertance]\n"
    "                   [--solver auto|dense|banded] [--json] [-o FILE] [--progress]\n"
    "\n"
    "H(w) = [K - w^2 M + i w (C + Omega G)]^-1 between force inputs and response\n"
    "outputs, at frequencies f_i = fmin + i (fmax - fmin)/(N - 1), i = 0..N-1.\n"
    "  --out CH,...   output channels STATION.DIR (DIR x, y, rx, ry), e.g. DA.x,C.A.y\n"
    "  --in CH,...    input (force) channels, same syntax\n"
    "  --fmin HZ      first frequency, Hz (default 0)\n"
    "  --fmax HZ      last frequency, Hz (required, >= fmin)\n"
    "  --points N     number of frequencies (default 200, >= 1)\n"
    "  --rpm R        fixed rotor speed, rpm (default 0: standstill)\n"
    "  --synchronous  rotor speed equal to the excitation frequency (Omega = w)\n"
    "  --kind K       receptance m/N (default), mobility m/(N s), inertance m/(N s^2)\n"
    "                 (rad instead of m for rotations)\n"
    "  --solver S     linear solver: auto (default), dense (zgesv), banded (zgbsv)\n"
    "\n"
    "CSV: freq_hz,<out>/<in> re,<out>/<in> im,... (outputs outer, inputs inner).\n"
    "JSON: {\"freq_hz\": [...], \"rpm\": R (null if synchronous), \"synchronous\",\n"
    "\"kind\", \"solver\", \"channels\": [{\"output\", \"input\", \"re\": [...],\n"
    "\"im\": [...]}]}\n";

static const char *const kind_names[] = {"receptance", "mobility", "inertance"};
static const char *const solver_names[] = {"auto", "dense", "banded"};

typedef struct frf_job {
  cli_channels out, in;
  size_t npts, nch;     /* frequencies; nch = nout * nin */
  double *freq;         /* Hz */
  double *re, *im;      /* [point * nch + o * nin + i] */
  double rpm;           /* fixed speed, rpm */
  int sync, kind, solver;
} frf_job;

static int parse_grid(const cli_args *a, frf_job *j, double *fmin, double *fmax) {
  int rc;
  if ((rc = cli_opt_require(a, "--fmax", "the last frequency in Hz")) ||
      (rc = cli_opt_nonneg(a, "--fmin", "Hz", 0.0, fmin)) ||
      (rc = cli_opt_nonneg(a, "--fmax", "Hz", 0.0, fmax)) ||
      (rc = cli_opt_count(a, "--points", 200, &j->npts)))
    return rc;
  if (*fmin > *fmax)
    return cli_usage(a->cmd, "--fmin %g Hz is above --fmax %g Hz; expected fmin <= fmax",
                     *fmin, *fmax);
  return 0;
}

static int parse_job(const cli_args *a, frf_job *j, double *fmin, double *fmax) {
  int rc;
  j->sync = cli_opt_value(a, "--synchronous") != NULL;
  if (j->sync && cli_opt_value(a, "--rpm"))
    return cli_usage(a->cmd, "--rpm and --synchronous exclude each other; give one");
  if ((rc = cli_opt_require(a, "--out", "output channels STATION.DIR[,...]")) ||
      (rc = cli_opt_require(a, "--in", "input channels STATION.DIR[,...]")) ||
      (rc = parse_grid(a, j, fmin, fmax)) ||
      (rc = cli_opt_nonneg(a, "--rpm", "rotor speed, rpm", 0.0, &j->rpm)) ||
      (rc = cli_opt_choice(a, "--kind", kind_names, 3, RCB_RECEPTANCE, &j->kind)) ||
      (rc = cli_opt_choice(a, "--solver", solver_names, 3, RCB_SOLVER_AUTO, &j->solver)))
    return rc;
  return 0;
}

static int alloc_job(frf_job *j) {
  j->nch = j->out.n * j->in.n;
  j->freq = malloc(j->npts * sizeof *j->freq);
  j->re = malloc(j->npts * j->nch * sizeof *j->re);
  j->im = malloc(j->npts * j->nch * sizeof *j->im);
  if (!j->freq || !j->re || !j->im) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  return 0;
}

static void free_job(frf_job *j) {
  cli_channels_free(&j->out);
  cli_channels_free(&j->in);
  free(j->freq);
  free(j->re);
  free(j->im);
}

/* The sweep: one rcb_frf_eval (one factorisation) per frequency. */
static int sweep(const cli_args *a, frf_job *j, rcb_frf *f, rcb_complex *H) {
  size_t p, o, i, nout = j->out.n, nin = j->in.n;
  cli_progress pr;
  cli_progress_start(&pr, a, "frf", "frequencies", j->npts);
  for (p = 0; p < j->npts; p++) {
    double w = j->freq[p] * CLI_HZ_TO_RAD_S;
    double speed = j->sync ? w : j->rpm * CLI_RPM_TO_RAD_S;
    rcb_status st = rcb_frf_eval(f, w, speed, (rcb_frf_kind)j->kind, H);
    if (st) {
      cli_progress_end(&pr);
      return cli_fail(cli_status_exit(st), "frf at %.17g Hz: %s", j->freq[p],
                      cli_msg(rcb_frf_errmsg(f), st));
    }
    for (o = 0; o < nout; o++)
      for (i = 0; i < nin; i++) {
        j->re[p * j->nch + o * nin + i] = creal(H[o + nout * i]);
        j->im[p * j->nch + o * nin + i] = cimag(H[o + nout * i]);
      }
    cli_progress_step(&pr, p + 1);
  }
  cli_progress_end(&pr);
  return 0;
}

static int compute(const cli_args *a, const rcb_model *m, frf_job *j) {
  rcb_frf *f = NULL;
  rcb_complex *H;
  int rc;
  rcb_status st = rcb_frf_create(&f, m, j->out.n, j->out.dofs, j->in.n, j->in.dofs,
                                 (rcb_solver_kind)j->solver, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "frf: %s",
                  cli_msg(f ? rcb_frf_errmsg(f) : rcb_model_errmsg(m), st));
    rcb_frf_destroy(f);
    return rc;
  }
  j->solver = (int)rcb_frf_solver(f);
  H = malloc(j->nch * sizeof *H);
  rc = H ? sweep(a, j, f, H) : cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  free(H);
  rcb_frf_destroy(f);
  return rc;
}

static void write_csv(FILE *fp, const frf_job *j) {
  size_t p, c, o, i;
  fputs("freq_hz", fp);
  for (o = 0; o < j->out.n; o++)
    for (i = 0; i < j->in.n; i++)
      fprintf(fp, ",%s/%s re,%s/%s im", j->out.names[o], j->in.names[i], j->out.names[o],
              j->in.names[i]);
  fputc('\n', fp);
  for (p = 0; p < j->npts; p++) {
    cli_csv_num(fp, j->freq[p]);
    for (c = 0; c < j->nch; c++) {
      fputc(',', fp);
      cli_csv_num(fp, j->re[p * j->nch + c]);
      fputc(',', fp);
      cli_csv_num(fp, j->im[p * j->nch + c]);
    }
    fputc('\n', fp);
  }
}

static void write_json(FILE *fp, const frf_job *j) {
  size_t o, i;
  fputs("{\"freq_hz\": ", fp);
  cli_json_nums(fp, j->freq, j->npts, 1);
  fputs(",\n\"rpm\": ", fp);
  if (j->sync)
    fputs("null", fp);
  else
    cli_json_num(fp, j->rpm);
  fprintf(fp, ", \"synchronous\": %s, \"kind\": \"%s\", \"solver\": \"%s\",\n\"channels\": [",
          j->sync ? "true" : "false", kind_names[j->kind], solver_names[j->solver]);
  for (o = 0; o < j->out.n; o++)
    for (i = 0; i < j->in.n; i++) {
      size_t c = o * j->in.n + i;
      fputs(c ? ",\n  {\"output\": " : "\n  {\"output\": ", fp);
      cli_json_str(fp, j->out.names[o]);
      fputs(", \"input\": ", fp);
      cli_json_str(fp, j->in.names[i]);
      fputs(",\n   \"re\": ", fp);
      cli_json_nums(fp, j->re + c, j->npts, j->nch);
      fputs(",\n   \"im\": ", fp);
      cli_json_nums(fp, j->im + c, j->npts, j->nch);
      fputs("}", fp);
    }
  fputs("]}\n", fp);
}

static int run(const cli_args *a, rcb_model *m, frf_job *j, double fmin, double fmax) {
  cli_out o;
  int rc;
  if ((rc = cli_channels_parse(a, m, "--out", &j->out)) ||
      (rc = cli_channels_parse(a, m, "--in", &j->in)) || (rc = alloc_job(j)))
    return rc;
  cli_linspace(fmin, fmax, j->npts, j->freq);
  if ((rc = compute(a, m, j)) || (rc = cli_out_open(&o, a))) return rc;
  (a->json ? write_json : write_csv)(o.fp, j);
  return cli_out_close(&o);
}

int cmd_frf(int argc, char **argv) {
  cli_opt opts[] = {{"--out", "CH,...", NULL},  {"--in", "CH,...", NULL},
                    {"--fmin", "HZ", NULL},     {"--fmax", "HZ", NULL},
                    {"--points", "N", NULL},    {"--rpm", "R", NULL},
                    {"--synchronous", NULL, NULL}, {"--kind", "KIND", NULL},
                    {"--solver", "SOLVER", NULL}};
  frf_job j = {0};
  cli_args a;
  rcb_model *m = NULL;
  double fmin = 0.0, fmax = 0.0;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_frf);
  if ((rc = parse_job(&a, &j, &fmin, &fmax))) return rc;
  if ((rc = cli_load_model(&a, &m))) return rc;
  rc = run(&a, m, &j, fmin, fmax);
  free_job(&j);
  rcb_model_destroy(m);
  return rc;
}
