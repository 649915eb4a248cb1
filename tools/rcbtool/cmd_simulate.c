/* rcbtool simulate: synthetic measurements from a model (FRFs at a rotor
 * speed, or the unbalance response over a speed range), with the paper's
 * eq. 19 noise, written as UFF dataset 58 or CSV. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_simulate[] =
    "usage: rcbtool simulate MODEL.ini --frf --out CH,... --in CH,... --fmax HZ\n"
    "                        [--fmin HZ] [--points N] [--rpm R | --synchronous]\n"
    "                        [--kind receptance|mobility|inertance]\n"
    "                        [--noise A,S[,P]] [--seed S] [--map NODE=STATION,...]\n"
    "                        -o FILE.uff|FILE.csv [--binary] [--solver S] [--progress]\n"
    "       rcbtool simulate MODEL.ini --unbalance --out CH,... --rpm-max B\n"
    "                        [--rpm-min A] [--points N] [noise, map, output as above]\n"
    "\n"
    "Computes what a test would measure and writes it as a measurement file.\n"
    "  --frf          FRFs H(w) between --out responses and --in forces at\n"
    "                 f_i = fmin + i (fmax - fmin)/(N - 1) Hz (as rcbtool frf)\n"
    "  --unbalance    response to the model's unbalances at rotor speeds\n"
    "                 A + i (B - A)/(N - 1) rpm (as rcbtool unbalance)\n"
    "  --fmin, --fmax, --points, --rpm, --synchronous, --kind, --rpm-min,\n"
    "  --rpm-max, --solver: as for rcbtool frf / rcbtool unbalance\n"
    "  --noise A,S    the paper's eq. 19 noise, in %: per channel\n"
    "                 f_e = f_s (1 + A/100 r1) + (||f_s||_2/n) (S/100) r2 e^{i phi},\n"
    "                 r1, r2 uniform in [-1, 1], phi uniform in [0, 2 pi)\n"
    "                 (default: no noise); A,S,P also turns each value by a\n"
    "                 phase uniform in +-P degrees (a phase noise)\n"
    "  --seed S       noise seed, a whole number >= 0 (default 1): the same seed\n"
    "                 gives the same data on every platform\n"
    "  --map LIST     UFF node numbers of the stations, e.g. 10=DA,20=C.A; stations\n"
    "                 without one get the next free number (printed on stderr);\n"
    "                 NODE.DIR=STATION.DIR writes that channel as NODE, DIR\n"
    "  -o FILE        required; .uff/.unv/.uf: UFF dataset 58, .csv: CSV\n"
    "  --binary       binary 58b instead of ASCII 58 (UFF only)\n"
    "\n"
    "UFF records: function type 4 (FRF) or 1 (unbalance, reference node 0), double\n"
    "complex data, abscissa in Hz, rotor speed of an FRF test as the z-axis value\n"
    "(rpm). CSV: '# kind' and '# rpm' lines, then as rcbtool frf writes it (re/im).\n";

static const char *const solver_names[] = {"auto", "dense", "banded"};

typedef struct sim_job {
  int frf, kind, solver, sync, binary;
  double lo, hi, rpm;    /* Hz or rpm (grid), rpm (FRF test speed) */
  size_t npts;
  double noise_a, noise_s; /* % */
  double noise_p;          /* phase noise, degrees (uniform in +-noise_p) */
  int noise;
  unsigned long long seed;
  cli_channels out, in;
} sim_job;

static int parse_noise(const cli_args *a, sim_job *j) {
  const char *s = cli_opt_value(a, "--noise"), *seed = cli_opt_value(a, "--seed");
  char *end;
  j->seed = 1;
  if (seed) {
    errno = 0;
    j->seed = strtoull(seed, &end, 10);
    if (*end || errno || seed[0] == '-')
      return cli_usage(a->cmd, "option --seed expects a whole number >= 0, got '%s'", seed);
  }
  if (!s) return 0;
  j->noise = 1;
  return cli_noise_opt(a, "--noise", &j->noise_a, &j->noise_s, &j->noise_p);
}

static int parse_frf(const cli_args *a, sim_job *j) {
  j->sync = cli_opt_value(a, "--synchronous") != NULL;
  if (j->sync && cli_opt_value(a, "--rpm"))
    return cli_usage(a->cmd, "--rpm and --synchronous exclude each other; give one");
  return cli_sweep_frf(a, "input (force) channels STATION.DIR[,...]", &j->lo, &j->hi, &j->rpm,
                       &j->kind);
}

static int parse_unbalance(const cli_args *a, sim_job *j) {
  j->kind = RCB_RECEPTANCE;
  return cli_sweep_unbalance(a,
                             "--in, --fmin, --fmax, --rpm, --synchronous and --kind belong to --frf; "
                             "--unbalance takes --out, --rpm-min, --rpm-max, --points",
                             &j->lo, &j->hi);
}

static int parse_job(const cli_args *a, sim_job *j) {
  int rc, is_uff;
  int frf = cli_opt_value(a, "--frf") != NULL, unb = cli_opt_value(a, "--unbalance") != NULL;
  if (frf == unb)
    return cli_usage(a->cmd, "give exactly one of --frf (FRFs at a rotor speed) and "
                     "--unbalance (unbalance response over a speed range)");
  j->frf = frf;
  if ((rc = cli_opt_require(a, "--out", "output channels STATION.DIR[,...]")) ||
      (rc = (frf ? parse_frf : parse_unbalance)(a, j)) ||
      (rc = cli_opt_count(a, "--points", 200, &j->npts)) ||
      (rc = cli_opt_choice(a, "--solver", solver_names, 3, RCB_SOLVER_AUTO, &j->solver)) ||
      (rc = parse_noise(a, j)))
    return rc;
  if (j->lo > j->hi || (j->npts > 1 && j->lo == j->hi))
    return cli_usage(a->cmd, "%s %g is not below %s %g; expected an increasing range",
                     frf ? "--fmin" : "--rpm-min", j->lo, frf ? "--fmax" : "--rpm-max", j->hi);
  if (!a->output || strcmp(a->output, "-") == 0)
    return cli_usage(a->cmd, "option -o FILE is required (FILE.uff, FILE.unv or FILE.csv)");
  if ((rc = cli_meas_format(a->cmd, a->output, &is_uff))) return rc;
  j->binary = cli_opt_value(a, "--binary") != NULL;
  if (j->binary && !is_uff)
    return cli_usage(a->cmd, "--binary applies to UFF output only ('%s' is CSV)", a->output);
  if (a->json) return cli_usage(a->cmd, "--json does not apply: the output is a measurement "
                                        "file (-o FILE.uff or FILE.csv)");
  return 0;
}

/* Values of all channels at point p into data[c * npts + p]. */
static int sweep(const cli_args *a, sim_job *j, rcb_frf *f, const double *x,
                 rcb_complex *H, rcb_complex *data) {
  size_t p, c, nout = j->out.n, nin = j->frf ? j->in.n : 1, nch = nout * nin;
  cli_progress pr;
  cli_progress_start(&pr, a, "simulate", j->frf ? "frequencies" : "speeds", j->npts);
  for (p = 0; p < j->npts; p++) {
    double speed = j->sync ? x[p] : j->rpm * CLI_RPM_TO_RAD_S;
    rcb_status st = j->frf ? rcb_frf_eval(f, x[p], speed, (rcb_frf_kind)j->kind, H)
                           : rcb_frf_unbalance(f, x[p], H);
    if (st) {
      cli_progress_end(&pr);
      return cli_fail(cli_status_exit(st), "simulate at point %zu: %s", p + 1,
                      cli_msg(rcb_frf_errmsg(f), st));
    }
    /* channel order o outer, i inner (as rcbtool frf); H is nout x nin */
    for (c = 0; c < nch; c++) data[c * j->npts + p] = H[c / nin + nout * (c % nin)];
    cli_progress_step(&pr, p + 1);
  }
  cli_progress_end(&pr);
  return 0;
}

static int fill(const cli_args *a, sim_job *j, const rcb_model *m, rcb_meas *ms, double *x,
                rcb_complex *data) {
  rcb_frf *f = NULL;
  rcb_complex *H;
  size_t nch = j->frf ? j->out.n * j->in.n : j->out.n, c;
  rcb_status st;
  int rc;
  st = rcb_frf_create(&f, m, j->out.n, j->out.dofs, j->frf ? j->in.n : 0,
                      j->frf ? j->in.dofs : NULL, (rcb_solver_kind)j->solver, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "simulate: %s",
                  cli_msg(f ? rcb_frf_errmsg(f) : rcb_model_errmsg(m), st));
    rcb_frf_destroy(f);
    return rc;
  }
  H = malloc(nch * sizeof *H);
  rc = H ? sweep(a, j, f, x, H, data) : cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  free(H);
  rcb_frf_destroy(f);
  if (rc) return rc;
  st = rcb_meas_set_grid(ms, j->frf ? RCB_MEAS_FRF : RCB_MEAS_UNBALANCE, j->npts, x,
                         j->sync ? -1.0 : j->rpm * CLI_RPM_TO_RAD_S);
  for (c = 0; c < nch && !st; c++) {
    size_t o = j->frf ? c / j->in.n : c;
    st = rcb_meas_add_channel(ms, j->out.names[o], j->frf ? j->in.names[c % j->in.n] : NULL,
                              (rcb_frf_kind)j->kind, data + c * j->npts);
  }
  if (!st && j->noise)
    st = rcb_meas_add_noise_phase(ms, j->noise_a, j->noise_s, j->noise_p * CLI_PI / 180.0,
                                  j->seed);
  if (st) return cli_fail(cli_status_exit(st), "simulate: %s", cli_msg(rcb_meas_errmsg(ms), st));
  return 0;
}

static int run(const cli_args *a, sim_job *j, rcb_model *m) {
  rcb_meas *ms = NULL;
  cli_uff_map mp;
  double *x = NULL;
  rcb_complex *data = NULL;
  size_t nch, p;
  int rc;
  if ((rc = cli_uff_map_parse(a, "--map", m, &mp)) ||
      (rc = cli_channels_parse(a, m, "--out", &j->out)) ||
      (j->frf && (rc = cli_channels_parse(a, m, "--in", &j->in))) ||
      (rc = cli_check_size(a, (double)j->npts,
                           1.0 + 2.0 * (double)j->out.n * (double)(j->frf ? j->in.n : 1)))) {
    cli_uff_map_free(&mp);
    return rc;
  }
  nch = j->frf ? j->out.n * j->in.n : j->out.n;
  x = malloc(j->npts * sizeof *x);
  data = malloc(j->npts * nch * sizeof *data);
  if (!x || !data || rcb_meas_create(&ms, NULL)) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  } else {
    cli_linspace(j->lo, j->hi, j->npts, x);
    for (p = 0; p < j->npts; p++) x[p] *= j->frf ? CLI_HZ_TO_RAD_S : CLI_RPM_TO_RAD_S;
    rc = fill(a, j, m, ms, x, data);
    if (!rc) rc = cli_meas_write(a->cmd, ms, a->output, j->binary, &mp);
  }
  rcb_meas_destroy(ms);
  free(x);
  free(data);
  cli_uff_map_free(&mp);
  return rc;
}

int cmd_simulate(int argc, char **argv) {
  cli_opt opts[] = {{"--frf", NULL, NULL},          {"--unbalance", NULL, NULL},
                    {"--out", "CH,...", NULL},      {"--in", "CH,...", NULL},
                    {"--fmin", "HZ", NULL},         {"--fmax", "HZ", NULL},
                    {"--points", "N", NULL},        {"--rpm", "R", NULL},
                    {"--synchronous", NULL, NULL},  {"--kind", "KIND", NULL},
                    {"--rpm-min", "A", NULL},       {"--rpm-max", "B", NULL},
                    {"--noise", "BETA_A,BETA_S[,PHASE_DEG]", NULL}, {"--seed", "S", NULL},
                    {"--map", "NODE=STATION,...", NULL}, {"--binary", NULL, NULL},
                    {"--solver", "SOLVER", NULL}};
  sim_job j;
  cli_args a;
  rcb_model *m = NULL;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_simulate);
  memset(&j, 0, sizeof j);
  if ((rc = parse_job(&a, &j))) return rc;
  if ((rc = cli_load_model(&a, &m))) return rc;
  rc = run(&a, &j, m);
  cli_channels_free(&j.out);
  cli_channels_free(&j.in);
  rcb_model_destroy(m);
  return rc;
}
