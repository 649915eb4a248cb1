/* rcbtool frf: frequency response functions between output and input channels. */
#include <complex.h>
#include <math.h>
#include <stdlib.h>

#include "cli.h"

const char cli_help_frf[] =
    "usage: rcbtool frf MODEL.ini --out CH[,CH...] --in CH[,CH...] --fmax HZ\n"
    "                   [--fmin HZ] [--points N] [--rpm R | --synchronous]\n"
    "                   [--kind receptance|mobility|inertance]\n"
    "                   [--solver auto|dense|banded|sparse|modal]\n"
    "                   [--modes N | --modes-fmax HZ] [--threads N]\n"
    "                   [--json] [-o FILE] [--progress]\n"
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
    "  --solver S     auto (default), dense (zgesv), banded (zgbsv), sparse (KLU),\n"
    "                 modal (eq. 7: eigenvectors once per speed, then a sum over\n"
    "                 modes per frequency; best for many frequencies at one speed).\n"
    "                 auto takes modal at one speed from 0.2 x DOF^2 frequencies\n"
    "                 (e.g. 1549 on 88 DOF) if it matches a direct solve at fmax\n"
    "                 to 1e-8, else KLU from 32 DOF, else banded or dense\n"
    "  --modes N      modal: keep the N lowest modes (|lambda|) plus a static\n"
    "                 residual term; default all modes\n"
    "  --modes-fmax HZ  modal: keep the modes with |lambda| <= 2 pi HZ, plus the\n"
    "                 residual term\n"
    "  --threads N    sweep on N threads (default 1); same numbers bit for bit\n"
    "\n"
    "With --solver modal, stderr gets the modes kept and a truncation error\n"
    "estimate: max |H_modal - H_direct| / max |H_direct| at fmax (one direct\n"
    "solve); JSON adds them as \"modal\".\n"
    "\n"
    "CSV: freq_hz,<out>/<in> re,<out>/<in> im,... (outputs outer, inputs inner).\n"
    "JSON: {\"freq_hz\": [...], \"rpm\": R (null if synchronous), \"synchronous\",\n"
    "\"kind\", \"solver\", \"channels\": [{\"output\", \"input\", \"re\": [...],\n"
    "\"im\": [...]}]}\n";

static const char *const kind_names[] = {"receptance", "mobility", "inertance"};
static const char *const solver_names[] = {"auto", "dense", "banded", "sparse", "modal"};

typedef struct frf_job {
  cli_channels out, in;
  size_t npts, nch;     /* frequencies; nch = nout * nin */
  double *freq;         /* Hz */
  double *re, *im;      /* [point * nch + o * nin + i] */
  double rpm;           /* fixed speed, rpm */
  int sync, kind, solver;
  size_t modes, threads; /* modal truncation (0: all); sweep threads */
  double modes_fmax;     /* modal truncation, Hz (0: none) */
  int modal_ok;          /* modal report below is filled */
  rcb_modal_info modal;
  double modal_err;      /* truncation error estimate at fmax (-) */
  int modal_err_set;     /* 1: modal_err already measured (by pick_auto) */
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
      (rc = cli_opt_choice(a, "--solver", solver_names, 5, RCB_SOLVER_AUTO, &j->solver)) ||
      (rc = cli_opt_count(a, "--modes", 0, &j->modes)) ||
      (rc = cli_opt_nonneg(a, "--modes-fmax", "Hz", 0.0, &j->modes_fmax)) ||
      (rc = cli_opt_count(a, "--threads", 1, &j->threads)))
    return rc;
  if ((j->modes || j->modes_fmax > 0.0) && j->solver != RCB_SOLVER_MODAL)
    return cli_usage(a->cmd, "--modes and --modes-fmax need --solver modal");
  if (j->modes && j->modes_fmax > 0.0)
    return cli_usage(a->cmd, "--modes and --modes-fmax exclude each other; give one");
  if (j->threads > RCB_SWEEP_MAX_THREADS)
    return cli_usage(a->cmd, "--threads %zu: at most %d", j->threads, RCB_SWEEP_MAX_THREADS);
  return 0;
}

static int alloc_job(frf_job *j) {
  j->nch = j->out.n * j->in.n;
  j->freq = malloc(j->npts * sizeof *j->freq);
  /* calloc: the static analyzer cannot see the sweep fill them */
  j->re = calloc(j->npts * j->nch, sizeof *j->re);
  j->im = calloc(j->npts * j->nch, sizeof *j->im);
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

/* Modes kept and the truncation error estimate at the last frequency, on
 * stderr (and in JSON). */
static rcb_status modal_report(const cli_args *a, frf_job *j, rcb_frf *f, double w,
                               double speed) {
  rcb_status st = rcb_frf_modal_info(f, speed, &j->modal);
  if (!st && !j->modal_err_set) st = rcb_frf_modal_error(f, w, speed, &j->modal_err);
  if (st) return st;
  j->modal_ok = 1;
  fprintf(stderr,
          "rcbtool: %s: modal: %zu of %zu roots kept (%zu modes, |lambda| <= %.6g Hz) at "
          "%.6g rpm; residual term %s (%.3g of |H(0)|); truncation error estimate at "
          "%.6g Hz: %.3g (max |H_modal - H_direct| / max |H_direct|)\n",
          a->cmd, j->modal.nkept, j->modal.nroots, j->modal.nmodes,
          j->modal.max_kept_wn / CLI_HZ_TO_RAD_S, speed / CLI_RPM_TO_RAD_S,
          j->modal.residual_used ? "added" : "none", j->modal.residual, w / CLI_HZ_TO_RAD_S,
          j->modal_err);
  return RCB_OK;
}

/* The sweep: rcb_frf_sweep on chunks of whole RCB_SWEEP_BLOCK blocks (so
 * the numbers do not depend on the chunking or on --threads), progress
 * between chunks. H holds nch entries per frequency. */
static rcb_status sweep_chunks(frf_job *j, rcb_frf *f, const double *w, const double *sp,
                               rcb_complex *H, cli_progress *pr) {
  size_t p, chunk = RCB_SWEEP_BLOCK * j->threads * 4;
  for (p = 0; p < j->npts; p += chunk) {
    size_t np = j->npts - p < chunk ? j->npts - p : chunk;
    rcb_status st = rcb_frf_sweep(f, np, w + p, sp + p, (rcb_frf_kind)j->kind, H + p * j->nch,
                                  j->threads);
    if (st) return st;
    cli_progress_step(pr, p + np);
  }
  return RCB_OK;
}

static int sweep(const cli_args *a, frf_job *j, rcb_frf *f, rcb_complex *H) {
  size_t p, o, i, nout = j->out.n, nin = j->in.n;
  double *w = malloc(2 * j->npts * sizeof *w), *sp;
  cli_progress pr;
  rcb_status st;
  if (!w) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  sp = w + j->npts;
  for (p = 0; p < j->npts; p++) {
    w[p] = j->freq[p] * CLI_HZ_TO_RAD_S;
    sp[p] = j->sync ? w[p] : j->rpm * CLI_RPM_TO_RAD_S;
  }
  cli_progress_start(&pr, a, "frf", "frequencies", j->npts);
  st = sweep_chunks(j, f, w, sp, H, &pr);
  if (st) {
    cli_progress_end(&pr);
    free(w);
    return cli_fail(cli_status_exit(st), "frf: %s", cli_msg(rcb_frf_errmsg(f), st));
  }
  for (p = 0; p < j->npts; p++)
    for (o = 0; o < nout; o++)
      for (i = 0; i < nin; i++) {
        j->re[p * j->nch + o * nin + i] = creal(H[p * j->nch + o + nout * i]);
        j->im[p * j->nch + o * nin + i] = cimag(H[p * j->nch + o + nout * i]);
      }
  if (j->solver == RCB_SOLVER_MODAL && j->npts)
    st = modal_report(a, j, f, w[j->npts - 1], sp[j->npts - 1]);
  free(w);
  if (st) {
    cli_progress_end(&pr);
    return cli_fail(cli_status_exit(st), "frf: modal check: %s", cli_msg(rcb_frf_errmsg(f), st));
  }
  cli_progress_end(&pr);
  {
    rcb_frf_condition c;
    if (!rcb_frf_get_condition(f, &c)) cli_warn_condition(a->cmd, &c, 0);
  }
  return 0;
}

/* --solver auto at one speed: the modal path where it pays
 * (rcb_frf_pick_solver), if its basis passes the check against one direct
 * solve at fmax within AUTO_MODAL_TOL (-): then the checked object (basis
 * computed) is returned and j->solver set; NULL for a direct solver. */
#define AUTO_MODAL_TOL 1e-8

static rcb_frf *pick_auto(const rcb_model *m, frf_job *j) {
  rcb_frf *f = NULL;
  double w = j->npts ? j->freq[j->npts - 1] * CLI_HZ_TO_RAD_S : 0.0,
         speed = j->rpm * CLI_RPM_TO_RAD_S, err = (double)NAN;
  if (j->solver != RCB_SOLVER_AUTO ||
      rcb_frf_pick_solver(m, j->npts, !j->sync) != RCB_SOLVER_MODAL)
    return NULL;
  if (!rcb_frf_create(&f, m, j->out.n, j->out.dofs, j->in.n, j->in.dofs, RCB_SOLVER_MODAL,
                      NULL) &&
      !rcb_frf_modal_error(f, w, speed, &err) && err <= AUTO_MODAL_TOL) {
    j->solver = RCB_SOLVER_MODAL;
    j->modal_err = err, j->modal_err_set = 1; /* the same check modal_report makes */
    return f;
  }
  rcb_frf_destroy(f);
  return NULL;
}

static int compute(const cli_args *a, const rcb_model *m, frf_job *j) {
  rcb_frf *f = pick_auto(m, j);
  rcb_complex *H;
  int rc;
  rcb_status st =
      f ? RCB_OK
        : rcb_frf_create(&f, m, j->out.n, j->out.dofs, j->in.n, j->in.dofs,
                         (rcb_solver_kind)j->solver, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "frf: %s",
                  cli_msg(f ? rcb_frf_errmsg(f) : rcb_model_errmsg(m), st));
    rcb_frf_destroy(f);
    return rc;
  }
  j->solver = (int)rcb_frf_solver(f);
  /* the default (all modes) needs no call, which would drop pick_auto's basis */
  if (j->solver == RCB_SOLVER_MODAL && (j->modes || j->modes_fmax > 0.0) &&
      (st = rcb_frf_set_modal(f, j->modes, j->modes_fmax * CLI_HZ_TO_RAD_S))) {
    rc = cli_fail(cli_status_exit(st), "frf: %s", cli_msg(rcb_frf_errmsg(f), st));
    rcb_frf_destroy(f);
    return rc;
  }
  H = malloc((j->npts ? j->npts : 1) * j->nch * sizeof *H);
  rc = H ? sweep(a, j, f, H) : cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  free(H);
  rcb_frf_destroy(f);
  return rc;
}

static void write_csv(FILE *fp, const frf_job *j) {
  size_t p, c, o, i;
  char u[32];
  /* the "# key = value" lines of a measurement CSV: rcbtool compare/fit read it back */
  fprintf(fp, "# kind = %s\n", kind_names[j->kind]);
  if (j->sync)
    fputs("# rpm = synchronous\n", fp);
  else
    fprintf(fp, "# rpm = %.17g\n", j->rpm);
  fputs("freq_hz", fp);
  for (o = 0; o < j->out.n; o++)
    for (i = 0; i < j->in.n; i++) {
      cli_channel_unit(j->out.names[o], j->in.names[i], j->kind, u, sizeof u);
      fprintf(fp, ",%s/%s re [%s],%s/%s im [%s]", j->out.names[o], j->in.names[i], u,
              j->out.names[o], j->in.names[i], u);
    }
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
  fprintf(fp, ", \"synchronous\": %s, \"kind\": \"%s\", \"solver\": \"%s\",\n",
          j->sync ? "true" : "false", kind_names[j->kind], solver_names[j->solver]);
  if (j->modal_ok) {
    fprintf(fp, "\"modal\": {\"roots\": %zu, \"roots_kept\": %zu, \"modes_kept\": %zu, ",
            j->modal.nroots, j->modal.nkept, j->modal.nmodes);
    fputs("\"max_kept_hz\": ", fp);
    cli_json_num(fp, j->modal.max_kept_wn / CLI_HZ_TO_RAD_S);
    fprintf(fp, ", \"residual_used\": %s, \"residual\": ",
            j->modal.residual_used ? "true" : "false");
    cli_json_num(fp, j->modal.residual);
    fputs(", \"check_hz\": ", fp);
    cli_json_num(fp, j->freq[j->npts - 1]);
    fputs(", \"truncation_error\": ", fp);
    cli_json_num(fp, j->modal_err);
    fputs("},\n", fp);
  }
  fputs("\"channels\": [", fp);
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
      (rc = cli_channels_parse(a, m, "--in", &j->in)) ||
      (rc = cli_check_size(a, (double)j->npts, 1.0 + 2.0 * (double)j->out.n * (double)j->in.n)) ||
      (rc = alloc_job(j)))
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
                    {"--solver", "SOLVER", NULL}, {"--modes", "N", NULL},
                    {"--modes-fmax", "HZ", NULL}, {"--threads", "N", NULL}};
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
