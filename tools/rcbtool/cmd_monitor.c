/* rcbtool monitor: model-based condition monitoring of a time-ordered series
 * of measurement files (issue #16) through rcb_monitor: the first file(s)
 * commission the reference, then one line per update (error, noise floor,
 * test statistic against its threshold, alarms, the effect named, the tracked
 * parameters with their intervals); --log writes JSON or CSV, --plot the
 * trend through tools/python/rcb_plots.py. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "cmd_monitor.h"

const char cli_help_monitor[] =
    "usage: rcbtool monitor BASELINE.ini DIR|MEAS... --params NAME[:LO:HI],...\n"
    "                       [--noise A,S[,P] | --sd STATS.csv|DIR] [--commission N]\n"
    "                       [--alpha A] [--cusum-h H] [--cusum-k K] [--relinearise N]\n"
    "                       [--reweight] [--no-sensors] [--baseline-sd SD,...]\n"
    "                       [--noise-scale auto|S]\n"
    "                       [--map NODE=STATION,...] [--rpm R]\n"
    "                       [--log OUT.json|OUT.csv] [--plot TREND.png] [--json]\n"
    "                       [-o FILE] [--progress]\n"
    "       rcbtool monitor BASELINE.ini --state S.rcbmon [options] [NEW...]\n"
    "\n"
    "Condition monitoring against a fitted baseline model. The measurements are\n"
    "taken in time order: the files of DIR sorted by name (.uff, .unv, .uf, .csv;\n"
    "other files are skipped), or the MEAS files in the order given. The first\n"
    "file (the first N with --commission N, averaged) commissions the reference:\n"
    "later changes are measured against it, so the model's own misfit at\n"
    "commissioning is never an alarm. Every later file is one update, printed on\n"
    "one line: the error of the baseline model against it and the noise floor\n"
    "(%), the instant test statistic T over its threshold (T/thr > 1 is an alarm:\n"
    "a chi-square test, at false-alarm rate --alpha per update, that nothing but\n"
    "the tracked parameters changed), the alarm flags (TEST: the instant test;\n"
    "CUSUM-/CUSUM+: a tracked parameter's two-sided CUSUM passed --cusum-h,\n"
    "falling or rising), each tracked parameter's value with its 95 % interval\n"
    "(the baseline's uncertainty included, --baseline-sd) and its change since the\n"
    "baseline with its own 95 % interval (the noise of the change only), and on\n"
    "a TEST alarm the effect and place of the catalogue (as rcbtool diagnose)\n"
    "that explain the change best, with its size. A CUSUM alarm says whose change\n"
    "it is: the parameter's, or \"kr falling, or <effect> falling: not separable\n"
    "on these channels\", then, when rcbtool plan finds one among the model's\n"
    "stations at the series' speed, \"; RESP per REF at R rpm would separate\n"
    "them\" (JSON: the tracked entry's \"separate_by\"). See docs/monitoring.md.\n"
    "  --params LIST   parameters to track (fitted at commissioning, e.g.\n"
    "                  coupling.C.kt,coupling.C.ct); LO:HI their plausible range\n"
    "                  (default [v/1000, 1000 v])\n"
    "  --noise A,S[,P] eq. 19 noise of one measurement (random A %, systematic S %)\n"
    "                  and phase noise, uniform in +-P degrees per point (0)\n"
    "  --sd PATH       per-point standard deviations instead (rcbtool estimate\n"
    "                  --stats or order --stats): one file for every update, or a\n"
    "                  directory holding STEM_stats.csv for each measurement STEM.*\n"
    "  --commission N  files averaged into the reference (default 1); with N >= 2\n"
    "                  their scatter measures the noise's level (--noise-scale)\n"
    "  --noise-scale S the noise's level against --noise or --sd: every declared\n"
    "                  standard deviation times S (1: as declared). auto (the\n"
    "                  default): with --commission N >= 2, the scatter of the N\n"
    "                  files about their average, whitened by the declared noise\n"
    "                  (sqrt of chi-square over 2 x channels x points x (N - 1)\n"
    "                  degrees of freedom; printed in the header), unless under\n"
    "                  0.1 (repeated or noise-free files: then 1); else 1. Kept\n"
    "                  in --state\n"
    "  --alpha A       false-alarm probability of the instant test per update\n"
    "                  (default: the library's, 1e-3)\n"
    "  --cusum-h H     CUSUM decision threshold, standard deviations (default: the\n"
    "                  library's); --cusum-k K its reference value\n"
    "  --relinearise N at most N iterations re-evaluating the model per update,\n"
    "                  until converged (0: linear; 8 recommended after a drift of\n"
    "                  several %; joint with the named effect while TEST fires)\n"
    "  --reweight      each update's noise from its own values (eq. 19 on them, or\n"
    "                  its --sd file), statistics by generalised least squares: T\n"
    "                  stays chi-square after a large change of the tracked\n"
    "                  parameters (a moved resonance); slower per update\n"
    "  --no-sensors    leave the measurement chain out of the candidate effects\n"
    "                  (by default each measured probe's gain and phase is one,\n"
    "                  and each station's x and y probes swapped: a drifting,\n"
    "                  lagging or miscalibrated probe, one wired the wrong way,\n"
    "                  gain -1, or two exchanged are named as the sensors, not\n"
    "                  read as the machine; --sensors, the default, is accepted).\n"
    "                  A --state series keeps its choice; one saved without\n"
    "                  either was made without them\n"
    "  --baseline-sd L standard errors of the baseline's values of the --params, in\n"
    "                  their order and units (the 'stderr' of the rcbtool fit that\n"
    "                  made the baseline): they widen the values' intervals (the\n"
    "                  changes' stay) and raise each CUSUM's allowance by the\n"
    "                  error the baseline's makes in its input while the other\n"
    "                  parameters change (rcb_monitor.h); default 0, the\n"
    "                  baseline taken as exact\n"
    "  --log FILE      every update as JSON (.json) or CSV (.csv), atomically\n"
    "  --plot FILE     the trend (.png, .pdf or .svg): tracked parameters with\n"
    "                  their 95 % bands, T/thr with the alarm line, alarms marked;\n"
    "                  Python 3 with matplotlib (RCB_PYTHON, RCB_PLOTS as compare)\n"
    "  --json          the log's JSON on standard output instead of the lines\n"
    "  --state FILE    keep the series' state in FILE between runs. A new FILE: the\n"
    "                  run as above, then FILE holds its settings, commissioning and\n"
    "                  updates. An existing FILE: the settings and the commissioning\n"
    "                  come from it (give no setting option), each NEW file is one\n"
    "                  more update (a file whose content is already in the state is\n"
    "                  refused), and FILE is replaced atomically (write, fsync,\n"
    "                  rename; a crash leaves the previous state). --log and --plot\n"
    "                  then cover the whole series, so with no NEW file they rebuild\n"
    "                  them from the state. One run at a time: another run on FILE\n"
    "                  waits up to RCB_LOCK_WAIT s (default 10), then exits 6.\n"
    "                  FILE.image beside it keeps what commissioning computed\n"
    "                  (megabytes), so a run per file skips it (the same\n"
    "                  results); missing or not this series' (a changed model),\n"
    "                  the run commissions in full and writes it again\n"
    "Units: error, floor %; T and its threshold have no unit; parameters in SI\n"
    "(N/m, N s/m, N m/rad, N m s/rad, kg). Exit codes: 0 ok (alarms or not), 2\n"
    "usage, 3 bad input (a missing or empty DIR, a file whose channels, points or\n"
    "speed differ from the commissioning file's), 4 numerical failure, 5 output\n"
    "not written (no partial log or plot is ever left), 6 the --state FILE is\n"
    "being updated by another run (nothing read or written).\n";

/* --noise A,S[,P]: eq. 19's two numbers, then the phase noise in degrees. */
/* --baseline-sd SD,...: one standard error >= 0 per tracked parameter. */
static int baseline_sd_opt(const cli_args *a, mon_job *j) {
  const char *s = cli_opt_value(a, "--baseline-sd"), *p = s;
  size_t k;
  if (!s) return 0;
  for (k = 0; k < j->params.n; k++) {
    char *end;
    j->baseline_sd[k] = strtod(p, &end);
    if (end == p || !(j->baseline_sd[k] >= 0) || !isfinite(j->baseline_sd[k]) ||
        (k + 1 < j->params.n ? *end != ',' : *end != '\0'))
      return cli_usage(a->cmd, "option --baseline-sd expects %zu standard errors >= 0 "
                       "separated by ',' (one per --params entry, in its units), got '%s'",
                       j->params.n, s);
    p = end + 1;
  }
  j->have_baseline_sd = 1;
  return 0;
}

/* --noise-scale auto|S|scatter:CHI2:DOF: 0 (auto), S > 0, or the scatter
 * measured before (what a state keeps, so a resumed run reports it as the
 * first did). */
static int noise_scale_opt(const cli_args *a, mon_job *j) {
  const char *v = cli_opt_value(a, "--noise-scale");
  int rc;
  j->noise_scale = 0.0;
  if (!v || strcmp(v, "auto") == 0) return 0;
  if (strncmp(v, "scatter:", 8) == 0) {
    char *e1 = NULL, *e2 = NULL;
    j->scatter[0] = strtod(v + 8, &e1);
    if (e1 != v + 8 && *e1 == ':') j->scatter[1] = strtod(e1 + 1, &e2);
    if (!e2 || e2 == e1 + 1 || *e2 || !(j->scatter[0] >= 0) || !(j->scatter[1] >= 1) ||
        !isfinite(j->scatter[0] + j->scatter[1]))
      return cli_usage(a->cmd, "option --noise-scale scatter:CHI2:DOF expects a chi-square >= 0 "
                       "and its degrees of freedom >= 1, got '%s'", v);
    return 0;
  }
  if ((rc = cli_opt_nonneg(a, "--noise-scale", "-", 0.0, &j->noise_scale))) return rc;
  if (!(j->noise_scale > 0.0) || !isfinite(j->noise_scale))
    return cli_usage(a->cmd, "option --noise-scale expects 'auto' or a factor > 0 on the "
                     "declared noise (1: as declared), got '%s'", v);
  if (j->noise_scale > 1e6)
    return cli_usage(a->cmd, "option --noise-scale %s: a noise over 1e6 x the declared one; give "
                     "--noise the level you mean", v);
  return 0;
}

static int parse_job(const cli_args *a, mon_job *j) {
  int rc;
  double relin = 0.0;
  j->log = cli_opt_value(a, "--log");
  j->plot = cli_opt_value(a, "--plot");
  j->sd_path = cli_opt_value(a, "--sd");
  if ((rc = cli_opt_require(a, "--params", "the parameters to track, e.g. coupling.C.kt")) ||
      (rc = cli_params_parse(a, "--params", &j->params)))
    return rc;
  j->have_params = 1;
  if (j->params.n > RCB_MONITOR_MAX_TRACKED)
    return cli_usage(a->cmd, "--params: %zu parameters, at most %d can be tracked",
                     j->params.n, RCB_MONITOR_MAX_TRACKED);
  if ((rc = cli_opt_count(a, "--commission", 1, &j->commission)) ||
      (rc = cli_opt_nonneg(a, "--alpha", "-", 0.0, &j->alpha)) ||
      (rc = cli_opt_nonneg(a, "--cusum-h", "-", 0.0, &j->cusum_h)) ||
      (rc = cli_opt_nonneg(a, "--cusum-k", "-", 0.0, &j->cusum_k)))
    return rc;
  if ((rc = cli_opt_nonneg(a, "--relinearise", "iterations", 0.0, &relin))) return rc;
  if (relin != floor(relin) || relin > 100)
    return cli_usage(a->cmd, "option --relinearise expects a whole number 0..100, got '%s'",
                     cli_opt_value(a, "--relinearise"));
  j->relinearise = (size_t)relin;
  j->reweight = cli_opt_value(a, "--reweight") != NULL;
  if (cli_opt_value(a, "--sensors") && cli_opt_value(a, "--no-sensors"))
    return cli_usage(a->cmd, "options --sensors and --no-sensors: give one of them");
  j->sensors = cli_opt_value(a, "--no-sensors") == NULL; /* the probes' gains by default */
  if (cli_opt_value(a, "--alpha") && !(j->alpha > 0.0 && j->alpha < 1.0))
    return cli_usage(a->cmd, "option --alpha expects a probability 0 < A < 1, got '%s'",
                     cli_opt_value(a, "--alpha"));
  if ((cli_opt_value(a, "--cusum-h") && !(j->cusum_h > 0.0)) ||
      (cli_opt_value(a, "--cusum-k") && !(j->cusum_k > 0.0)))
    return cli_usage(a->cmd, "options --cusum-h and --cusum-k expect values > 0");
  if ((rc = baseline_sd_opt(a, j))) return rc;
  if ((rc = noise_scale_opt(a, j))) return rc;
  if (cli_opt_value(a, "--noise") && j->sd_path)
    return cli_usage(a->cmd, "--noise and --sd exclude each other: give the eq. 19 model or "
                     "the per-point standard deviations");
  if (cli_opt_value(a, "--noise") && (rc = cli_noise_opt(a, "--noise", &j->beta_a, &j->beta_s, &j->phase_deg)))
    return rc;
  if (!cli_opt_value(a, "--noise") && !j->sd_path)
    return cli_usage(a->cmd, "the monitor needs the measurement noise: give --noise A,S (eq. "
                     "19, e.g. --noise 10,1) or --sd STATS.csv|DIR");
  if (j->log && !mon_log_is_csv(j->log) && !mon_has_ext(j->log, ".json"))
    return cli_usage(a->cmd, "--log %s: expected a .json or .csv file name", j->log);
  if (j->plot && !mon_plot_format(j->plot))
    return cli_usage(a->cmd, "--plot %s: expected a .png, .pdf or .svg file name", j->plot);
  return 0;
}

/* ---- the series: DIR sorted by name, or the files as given ---- */

int mon_has_ext(const char *path, const char *ext) {
  size_t n = strlen(path), k = strlen(ext), i;
  if (n < k) return 0;
  for (i = 0; i < k; i++) {
    char c = path[n - k + i];
    if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
    if (c != ext[i]) return 0;
  }
  return 1;
}

static int is_meas_name(const char *name) {
  return name[0] != '.' && (mon_has_ext(name, ".uff") || mon_has_ext(name, ".unv") ||
                            mon_has_ext(name, ".uf") || mon_has_ext(name, ".csv"));
}

static int add_file(mon_series *s, const char *dir, const char *name) {
  char *p;
  if (s->n == s->cap) {
    size_t cap = s->cap ? 2 * s->cap : 64;
    char **f = realloc(s->files, cap * sizeof *f);
    if (!f) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    s->files = f;
    s->cap = cap;
  }
  p = malloc((dir ? strlen(dir) + 1 : 0) + strlen(name) + 1);
  if (!p) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  if (dir) {
    strcpy(p, dir);
    if (p[0] && p[strlen(p) - 1] != '/') strcat(p, "/");
    strcat(p, name);
  } else {
    strcpy(p, name);
  }
  s->files[s->n++] = p;
  return 0;
}

static int by_name(const void *x, const void *y) {
  return strcmp(*(char *const *)x, *(char *const *)y);
}

static int add_dir(const char *cmd, mon_series *s, const char *dir) {
  DIR *d = opendir(dir);
  struct dirent *e;
  size_t first = s->n;
  int rc = 0;
  if (!d)
    return cli_fail(CLI_EXIT_INPUT, "%s: cannot read the directory '%s': %s", cmd, dir,
                    strerror(errno));
  while (!rc && (e = readdir(d)) != NULL)
    if (is_meas_name(e->d_name)) rc = add_file(s, dir, e->d_name);
  closedir(d);
  if (rc) return rc;
  if (s->n == first)
    return cli_fail(CLI_EXIT_INPUT, "%s: the directory '%s' holds no measurement file (.uff, "
                    ".unv, .uf or .csv); give the directory of the series or its files", cmd,
                    dir);
  qsort(s->files + first, s->n - first, sizeof *s->files, by_name);
  return 0;
}

int mon_series_add(const char *cmd, mon_series *s, const char *path) {
  struct stat st;
  if (stat(path, &st) != 0)
    return cli_fail(CLI_EXIT_INPUT, "%s: cannot read '%s': %s", cmd, path, strerror(errno));
  if (S_ISDIR(st.st_mode)) return add_dir(cmd, s, path);
  return add_file(s, NULL, path);
}

void mon_series_free(mon_series *s) {
  size_t i;
  for (i = 0; i < s->n; i++) free(s->files[i]);
  free(s->files);
  memset(s, 0, sizeof *s);
}

/* cli_parse knows one positional (the model): the others are the series. */
static int takes_value(const char *arg, const cli_opt *opts, size_t nopts) {
  size_t i;
  if (strchr(arg, '=')) return 0;
  if (strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0 ||
      strcmp(arg, "--max-output") == 0)
    return 1;
  for (i = 0; i < nopts; i++)
    if (opts[i].metavar && strcmp(arg, opts[i].name) == 0) return 1;
  return 0;
}

static void split_series(int argc, char **argv, const cli_opt *opts, size_t nopts, char **args,
                         int *nargs, const char **series, size_t *nseries) {
  int k, npos = 0, only_pos = 0, n = 0;
  *nseries = 0;
  for (k = 0; k < argc; k++) {
    const char *arg = argv[k];
    int pos = k > 0 && (only_pos || arg[0] != '-' || arg[1] == '\0');
    if (k > 0 && !only_pos && strcmp(arg, "--") == 0) only_pos = 1;
    if (pos && ++npos >= 2) {
      series[(*nseries)++] = arg;
      continue;
    }
    args[n++] = argv[k];
    if (k > 0 && !pos && !only_pos && takes_value(arg, opts, nopts) && k + 1 < argc)
      args[n++] = argv[++k];
  }
  *nargs = n;
}

/* The series files join the run's plan (-o, --log, --plot and --sd came from the
 * option table), checked again before any work. */
static int guard_outputs(const mon_job *j) {
  size_t i;
  for (i = 0; i < j->series.n; i++) cli_plan_input(j->series.files[i], "measurement");
  return cli_plan_check();
}

/* An existing --state is read before the command line is parsed (its
 * settings join it): the run's plan is checked on what the line names
 * first, so a --state onto an input is refused as every output onto an
 * input is (exit 5), before it is read as a state. The check locks the
 * state (CLI_IO_INOUT, cli_plan_lock.c) before the caller looks whether it
 * exists: two runs on one new state cannot both start a series. */
static int state_plan(int argc, char **argv, const cli_opt *opts, size_t nopts,
                      const char *state) {
  char **args = malloc(((size_t)argc + 1) * sizeof *args);
  const char **series = malloc(((size_t)argc + 1) * sizeof *series);
  size_t nseries = 0, k;
  int nargs = 0, i, model = 0;
  if (!args || !series) {
    free(args), free((void *)series);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  split_series(argc, argv, opts, nopts, args, &nargs, series, &nseries);
  for (k = 0; k < nseries; k++) cli_plan_input(series[k], "measurement");
  for (i = 1; i < nargs; i++) {
    if (args[i][0] == '-' && args[i][1]) {
      if (strcmp(args[i], "--sd") == 0 && i + 1 < nargs) cli_plan_input(args[i + 1], "--sd");
      if (takes_value(args[i], opts, nopts)) i++;
    } else if (!model++) {
      cli_plan_input(args[i], "model");
    }
  }
  cli_plan_output(state, "--state", CLI_IO_IN);
  free(args), free((void *)series);
  return cli_plan_check();
}

/* ---- --state: the settings' options kept in the state ---- */

static const char *const SETTING_OPTS[] = {"--params", "--noise",  "--sd",     "--commission",
                                           "--alpha",  "--cusum-h", "--cusum-k", "--relinearise",
                                           "--reweight", "--map",  "--rpm", "--baseline-sd",
                                           "--sensors", "--noise-scale", "--no-sensors"};

/* 1 + the number of strings @p argv[k] (with its value) takes when it is a
 * setting option, else 0. */
static int setting_at(int argc, char **argv, int k) {
  size_t i, n;
  for (i = 0; i < sizeof SETTING_OPTS / sizeof SETTING_OPTS[0]; i++) {
    n = strlen(SETTING_OPTS[i]);
    if (strncmp(argv[k], SETTING_OPTS[i], n) != 0) continue;
    if (argv[k][n] == '=') return 2;
    if (argv[k][n] != '\0') continue;
    if (strcmp(SETTING_OPTS[i], "--reweight") == 0 || strcmp(SETTING_OPTS[i], "--sensors") == 0 ||
        strcmp(SETTING_OPTS[i], "--no-sensors") == 0)
      return 2;
    return k + 1 < argc ? 3 : 2;
  }
  return 0;
}

/* Whether the settings opts[0 .. n) choose the probes' gains either way. */
static int sensors_set(char *const *opts, size_t n) {
  size_t k;
  for (k = 0; k < n; k++)
    if (strcmp(opts[k], "--sensors") == 0 || strcmp(opts[k], "--no-sensors") == 0) return 1;
  return 0;
}

/* The value of --state on the command line (NULL without). */
static const char *state_arg(int argc, char **argv) {
  int k;
  for (k = 1; k < argc; k++) {
    if (strcmp(argv[k], "--") == 0) break;
    if (strcmp(argv[k], "--state") == 0 && k + 1 < argc) return argv[k + 1];
    if (strncmp(argv[k], "--state=", 8) == 0) return argv[k] + 8;
  }
  return NULL;
}

/* The setting options of argv into *out (pointers into argv), n of them. */
static size_t settings_of(int argc, char **argv, char **out) {
  int k, t;
  size_t n = 0;
  for (k = 1; k < argc; k++) {
    if (strcmp(argv[k], "--") == 0) break;
    if (!(t = setting_at(argc, argv, k))) continue;
    out[n++] = argv[k];
    if (t == 3) out[n++] = argv[++k];
  }
  return n;
}

/* With an existing state: its settings appended to the command line, which
 * may give none of its own. *nargv the new count; 0 or an exit code. */
static int with_saved(int argc, char **argv, const char *state, mon_saved *sv, char ***nargv,
                      int *nargc) {
  char **own = malloc(((size_t)argc + 1) * sizeof *own);
  size_t n, k;
  int rc;
  if (!own) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  n = settings_of(argc, argv, own);
  if (n) {
    rc = cli_usage(argv[0], "--state '%s' exists and holds the series' settings: %s cannot be "
                   "given again (give the new files, --log, --plot, --json or -o; a new "
                   "state file starts a new series)", state, own[0]);
    free(own);
    return rc;
  }
  free(own);
  if ((rc = mon_saved_read(argv[0], state, sv))) return rc;
  if (!(*nargv = malloc(((size_t)argc + sv->nopts + 2) * sizeof **nargv)))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  /* right after the command, before any "--" */
  (*nargv)[0] = argv[0];
  *nargc = 1;
  for (k = 0; k < sv->nopts; k++) (*nargv)[(*nargc)++] = sv->opts[k];
  /* saved before the probes' gains were the default and chosen in every
   * new state: a series made without them */
  if (!sensors_set(sv->opts, sv->nopts)) (*nargv)[(*nargc)++] = "--no-sensors";
  for (k = 1; k < (size_t)argc; k++) (*nargv)[(*nargc)++] = argv[k];
  (*nargv)[*nargc] = NULL;
  return 0;
}

int cmd_monitor(int argc, char **argv) {
  cli_opt opts[] = {{"--params", "NAME[:LO:HI],...", NULL},
                    {"--noise", "BETA_A,BETA_S[,PHASE_DEG]", NULL},
                    {"--sd", "STATS.csv|DIR", NULL},
                    {"--commission", "N", NULL},
                    {"--alpha", "A", NULL},
                    {"--cusum-h", "H", NULL},
                    {"--cusum-k", "K", NULL},
                    {"--relinearise", "N", NULL},
                    {"--reweight", NULL, NULL},
                    {"--sensors", NULL, NULL},
                    {"--no-sensors", NULL, NULL},
                    {"--baseline-sd", "SD,...", NULL},
                    {"--noise-scale", "auto|S", NULL},
                    {"--map", "NODE=STATION,...", NULL},
                    {"--rpm", "R", NULL},
                    {"--log", "FILE", NULL},
                    {"--plot", "FILE", NULL},
                    {"--state", "FILE", NULL}};
  size_t nopts = sizeof opts / sizeof opts[0], nseries = 0, k;
  const char **series = NULL;
  char **args = NULL, **sargv = NULL;
  static const cli_file_opt files[] = {{"--sd", CLI_IO_IN},
                                       {"--log", CLI_IO_OUT},
                                       {"--plot", CLI_IO_OUT | CLI_IO_MKDIR},
                                       {"--state", CLI_IO_INOUT}};
  int nargs = 0, rc = 0;
  mon_job j;
  mon_saved saved;
  cli_args a;
  struct stat sst;
  const char *state = state_arg(argc, argv);
  memset(&j, 0, sizeof j);
  memset(&saved, 0, sizeof saved);
  cli_plan_options(files, sizeof files / sizeof files[0]);
  if (state && (rc = state_plan(argc, argv, opts, nopts, state))) goto done;
  if (state && stat(state, &sst) == 0) {
    if ((rc = with_saved(argc, argv, state, &saved, &sargv, &argc))) goto done;
    argv = sargv;
    j.saved = &saved;
  }
  args = malloc(((size_t)argc + 1) * sizeof *args);
  series = malloc(((size_t)argc + 1) * sizeof *series);
  j.setopts = malloc(((size_t)argc + 1) * sizeof *j.setopts);
  if (!args || !series || !j.setopts) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    goto done;
  }
  j.nsetopts = settings_of(argc, argv, j.setopts);
  if (!j.saved && !sensors_set(j.setopts, j.nsetopts)) /* the default, stored as chosen */
    j.setopts[j.nsetopts++] = "--sensors";
  j.state = state;
  split_series(argc, argv, opts, nopts, args, &nargs, series, &nseries);
  for (k = 0; k < nseries; k++) cli_plan_input(series[k], "measurement"); /* a DIR too */
  if ((rc = cli_parse(nargs, args, opts, nopts, &a))) goto done;
  if (a.help) {
    rc = cli_print_help(cli_help_monitor);
    goto done;
  }
  if (!nseries && !j.saved) {
    rc = cli_usage(a.cmd, "missing the measurements: expected 'rcbtool monitor BASELINE.ini "
                   "DIR|MEAS...'");
    goto done;
  }
  if ((rc = parse_job(&a, &j))) goto done;
  if (j.saved) { /* the series so far by name (the files need not be here any more) */
    if (saved.ncomm != j.commission) {
      rc = cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': %zu commissioning files for "
                    "--commission %zu: damaged", a.cmd, state, saved.ncomm, j.commission);
      goto done;
    }
    for (k = 0; k < saved.ncomm && !rc; k++) rc = add_file(&j.series, NULL, saved.comm[k]);
    for (k = 0; k < saved.nrec && !rc; k++) rc = add_file(&j.series, NULL, saved.recfile[k]);
    j.resume = j.series.n;
  }
  for (k = 0; k < nseries && !rc; k++) rc = mon_series_add(a.cmd, &j.series, series[k]);
  if (rc) goto done;
  if (!j.saved && j.series.n <= j.commission) {
    rc = cli_usage(a.cmd, "%zu measurement file%s: the first %zu commission%s the reference "
                   "and none is left to monitor (--commission N takes the first N)",
                   j.series.n, j.series.n == 1 ? "" : "s", j.commission,
                   j.commission == 1 ? "s" : "");
    goto done;
  }
  if (state) { /* the commissioning image beside it, read and rewritten */
    if (!(j.image = mon_image_path(state))) {
      rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
      goto done;
    }
    cli_plan_output(j.image, "--state image", CLI_IO_INOUT);
  }
  if ((rc = guard_outputs(&j))) goto done;
  rc = mon_run(&a, &j);
done:
  if (j.have_params) cli_params_free(&j.params);
  mon_series_free(&j.series);
  mon_saved_free(&saved);
  free(sargv);
  free(j.image);
  free(j.setopts);
  free(args);
  free((void *)series);
  return rc;
}
