/* rcbtool unbalance: steady unbalance response over a rotor speed range. */
#include <complex.h>
#include <math.h>
#include <stdlib.h>

#include "cli.h"

const char cli_help_unbalance[] =
    "usage: rcbtool unbalance MODEL.ini --out CH[,CH...] --rpm-max B [--rpm-min A]\n"
    "                         [--points N] [--solver auto|dense|banded]\n"
    "                         [--json] [-o FILE] [--progress]\n"
    "\n"
    "Steady response to the model's [unbalance] sections (paper eqs. 3-4) at rotor\n"
    "speeds Omega_i = A + i (B - A)/(N - 1), i = 0..N-1; speed-dependent bearings\n"
    "are evaluated at each speed. q(t) = Re(Q e^{i Omega t}).\n"
    "  --out CH,...   output channels STATION.DIR (DIR x, y, rx, ry), e.g. DA.x,DA.y\n"
    "  --rpm-min A    first speed, rpm (default 0)\n"
    "  --rpm-max B    last speed, rpm (required, >= rpm-min)\n"
    "  --points N     number of speeds (default 200, >= 1)\n"
    "  --solver S     linear solver: auto (default), dense, banded\n"
    "\n"
    "amp = |Q| (m, or rad for rotations); phase_deg = arg(Q) in degrees, from +x\n"
    "towards +y, in (-180, 180].\n"
    "CSV: rpm,<out> amp,<out> phase_deg,...\n"
    "JSON: {\"rpm\": [...], \"channels\": [{\"output\", \"re\", \"im\", \"amp\",\n"
    "\"phase_deg\"}]}\n";

static const char *const solver_names[] = {"auto", "dense", "banded"};

typedef struct unb_job {
  cli_channels out;
  size_t npts;
  double *rpm;     /* rpm */
  double *re, *im; /* [point * nout + o], m or rad */
  int solver;
} unb_job;

static int parse_job(const cli_args *a, unb_job *j, double *lo, double *hi) {
  int rc;
  if ((rc = cli_opt_require(a, "--out", "output channels STATION.DIR[,...]")) ||
      (rc = cli_opt_require(a, "--rpm-max", "the highest rotor speed in rpm")) ||
      (rc = cli_opt_nonneg(a, "--rpm-min", "rpm", 0.0, lo)) ||
      (rc = cli_opt_nonneg(a, "--rpm-max", "rpm", 0.0, hi)) ||
      (rc = cli_opt_count(a, "--points", 200, &j->npts)) ||
      (rc = cli_opt_choice(a, "--solver", solver_names, 3, RCB_SOLVER_AUTO, &j->solver)))
    return rc;
  if (*lo > *hi)
    return cli_usage(a->cmd, "--rpm-min %g is above --rpm-max %g; expected rpm-min <= rpm-max",
                     *lo, *hi);
  return 0;
}

static void free_job(unb_job *j) {
  cli_channels_free(&j->out);
  free(j->rpm);
  free(j->re);
  free(j->im);
}

static int sweep(const cli_args *a, unb_job *j, rcb_frf *f, rcb_complex *Q) {
  size_t p, o, n = j->out.n;
  cli_progress pr;
  cli_progress_start(&pr, a, "unbalance", "speeds", j->npts);
  for (p = 0; p < j->npts; p++) {
    rcb_status st = rcb_frf_unbalance(f, j->rpm[p] * CLI_RPM_TO_RAD_S, Q);
    if (st) {
      cli_progress_end(&pr);
      return cli_fail(cli_status_exit(st), "unbalance at %.17g rpm: %s", j->rpm[p],
                      cli_msg(rcb_frf_errmsg(f), st));
    }
    for (o = 0; o < n; o++) {
      j->re[p * n + o] = creal(Q[o]);
      j->im[p * n + o] = cimag(Q[o]);
    }
    cli_progress_step(&pr, p + 1);
  }
  cli_progress_end(&pr);
  {
    rcb_frf_condition c;
    if (!rcb_frf_get_condition(f, &c)) cli_warn_condition(a->cmd, &c, 1);
  }
  return 0;
}

static int compute(const cli_args *a, const rcb_model *m, unb_job *j) {
  rcb_frf *f = NULL;
  rcb_complex *Q;
  int rc;
  rcb_status st =
      rcb_frf_create(&f, m, j->out.n, j->out.dofs, 0, NULL, (rcb_solver_kind)j->solver, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "unbalance: %s",
                  cli_msg(f ? rcb_frf_errmsg(f) : rcb_model_errmsg(m), st));
    rcb_frf_destroy(f);
    return rc;
  }
  Q = malloc(j->out.n * sizeof *Q);
  rc = Q ? sweep(a, j, f, Q) : cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  free(Q);
  rcb_frf_destroy(f);
  return rc;
}

static double phase_deg(double re, double im) { return atan2(im, re) * 180.0 / CLI_PI; }

static void write_csv(FILE *fp, const unb_job *j) {
  size_t p, o, n = j->out.n;
  char u[32];
  fputs("# unbalance response: amplitude (m, or rad for rotations) and phase in degrees "
        "from +x towards +y\nrpm", fp);
  for (o = 0; o < n; o++)
    fprintf(fp, ",%s amp [%s],%s phase_deg", j->out.names[o],
            cli_channel_unit(j->out.names[o], NULL, 0, u, sizeof u), j->out.names[o]);
  fputc('\n', fp);
  for (p = 0; p < j->npts; p++) {
    cli_csv_num(fp, j->rpm[p]);
    for (o = 0; o < n; o++) {
      double re = j->re[p * n + o], im = j->im[p * n + o];
      fputc(',', fp);
      cli_csv_num(fp, hypot(re, im));
      fputc(',', fp);
      cli_csv_num(fp, phase_deg(re, im));
    }
    fputc('\n', fp);
  }
}

/* amp and phase of channel o as JSON arrays (derived from re, im). */
static void json_polar(FILE *fp, const unb_job *j, size_t o) {
  size_t p, n = j->out.n;
  fputs(",\n   \"amp\": [", fp);
  for (p = 0; p < j->npts; p++) {
    fputs(p ? ", " : "", fp);
    cli_json_num(fp, hypot(j->re[p * n + o], j->im[p * n + o]));
  }
  fputs("],\n   \"phase_deg\": [", fp);
  for (p = 0; p < j->npts; p++) {
    fputs(p ? ", " : "", fp);
    cli_json_num(fp, phase_deg(j->re[p * n + o], j->im[p * n + o]));
  }
  fputs("]", fp);
}

static void write_json(FILE *fp, const unb_job *j) {
  size_t o, n = j->out.n;
  fputs("{\"rpm\": ", fp);
  cli_json_nums(fp, j->rpm, j->npts, 1);
  fputs(",\n\"channels\": [", fp);
  for (o = 0; o < n; o++) {
    fputs(o ? ",\n  {\"output\": " : "\n  {\"output\": ", fp);
    cli_json_str(fp, j->out.names[o]);
    fputs(",\n   \"re\": ", fp);
    cli_json_nums(fp, j->re + o, j->npts, n);
    fputs(",\n   \"im\": ", fp);
    cli_json_nums(fp, j->im + o, j->npts, n);
    json_polar(fp, j, o);
    fputs("}", fp);
  }
  fputs("]}\n", fp);
}

static int run(const cli_args *a, rcb_model *m, unb_job *j, double lo, double hi) {
  cli_out o;
  int rc;
  if ((rc = cli_channels_parse(a, m, "--out", &j->out)) ||
      (rc = cli_check_size(a, (double)j->npts, 1.0 + 2.0 * (double)j->out.n)))
    return rc;
  j->rpm = malloc(j->npts * sizeof *j->rpm);
  /* calloc: the static analyzer cannot see compute fill them */
  j->re = calloc(j->npts * j->out.n, sizeof *j->re);
  j->im = calloc(j->npts * j->out.n, sizeof *j->im);
  if (!j->rpm || !j->re || !j->im) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  cli_linspace(lo, hi, j->npts, j->rpm);
  if ((rc = compute(a, m, j)) || (rc = cli_out_open(&o, a))) return rc;
  (a->json ? write_json : write_csv)(o.fp, j);
  return cli_out_close(&o);
}

int cmd_unbalance(int argc, char **argv) {
  cli_opt opts[] = {{"--out", "CH,...", NULL},
                    {"--rpm-min", "A", NULL},
                    {"--rpm-max", "B", NULL},
                    {"--points", "N", NULL},
                    {"--solver", "SOLVER", NULL}};
  unb_job j = {0};
  cli_args a;
  rcb_model *m = NULL;
  double lo = 0.0, hi = 0.0;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_unbalance);
  if ((rc = parse_job(&a, &j, &lo, &hi))) return rc;
  if ((rc = cli_load_model(&a, &m))) return rc;
  rc = run(&a, m, &j, lo, hi);
  free_job(&j);
  rcb_model_destroy(m);
  return rc;
}
