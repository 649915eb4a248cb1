/* rcbtool fit: fit model parameters to a measurement (FRFs or unbalance
 * responses) with the paper's algorithm or NLopt, print the fitted values with
 * their uncertainty, and write the fitted model. Also the --params list
 * helpers shared with rcbtool sensitivity. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

const char cli_help_fit[] =
    "usage: rcbtool fit MODEL.ini MEAS.uff|MEAS.unv|MEAS.csv --params NAME[:LO:HI][,...]\n"
    "                   [--log] [--method paper|nlopt:ALG]\n"
    "                   [--scale linear|log10|db|complex] [--band LO:HI]\n"
    "                   [--noise BETA_A,BETA_S] [--fd] [--max-iter N] [--starts N]\n"
    "                   [--sensor RESP:KEY=V,...] [--swap A,B,...]\n"
    "                   [--map NODE=STATION,...] [--rpm R] [-o FITTED.ini] [--json] [--progress]\n"
    "\n"
    "Fits model parameters so that the model reproduces the measurement (paper\n"
    "eq. 12: least squares over every channel and point), starting from the values\n"
    "in MODEL.ini. MODEL.ini itself is never changed.\n"
    "  --params LIST  parameters to fit, by name (coupling.C.kt, bearing.B2.kxx,\n"
    "                 disk.DA.mass, shaft.A.damping_stiffness, unbalance.UA.phase,\n"
    "                 ...; SI units of the INI keys), each with optional bounds\n"
    "                 NAME:LO:HI; without bounds [start/1000, start*1000] (a start\n"
    "                 <= 0 needs explicit bounds). Also the measurement chain's:\n"
    "                 sensor.RESP.gain (dimensionless, start 1, default bounds\n"
    "                 [0.1, 10], fitted on log g) and sensor.RESP.phase (rad,\n"
    "                 start 0, default [-pi/2, pi/2]; seen on --scale complex\n"
    "                 only) of a measured response RESP (DB.y): every channel\n"
    "                 measured at RESP is predicted as g e^(i phase) x the model.\n"
    "                 They are not written to -o (not part of the model)\n"
    "  --sensor LIST  known corrections of the measurement chain, not fitted:\n"
    "                 RESP:KEY=V[,KEY=V][,RESP2:KEY=V...] with KEY gain\n"
    "                 (dimensionless, nonzero), phase (rad, positive when the\n"
    "                 sensor leads) or sign (-1: wired the wrong way), e.g.\n"
    "                 DB.y:gain=0.8,phase=0 or DB.y:sign=-1; a fitted\n"
    "                 sensor.RESP.gain multiplies them\n"
    "  --swap LIST    probes known to be swapped, in pairs: A,B[,C,D...] (e.g.\n"
    "                 DB.x,DB.y: the channels of DB.x read the model at DB.y and\n"
    "                 vice versa; the two measured with the same references)\n"
    "  --log          optimise log(p) for every parameter (needs LO > 0)\n"
    "  --method M     paper (default: Gauss-Newton by pseudo-inverse, Coggins line\n"
    "                 search, lambda-Q damping, exterior penalty; eqs. 14-18) or\n"
    "                 nlopt:ALG with an NLopt algorithm name (LN_BOBYQA, LN_SBPLX,\n"
    "                 LD_LBFGS, LD_MMA, GN_DIRECT_L, GN_CRS2_LM, G_MLSL_LDS, ...)\n"
    "  --scale S      residuals on |H| (linear), log10 |H| (log10, default: FRF\n"
    "                 magnitudes span decades), 20 log10 |H| (db) or Re/Im (complex);\n"
    "                 a CSV of magnitudes only ('mag' or 'dB' columns, no phase) fits\n"
    "                 on the first three, and complex is refused\n"
    "  --band LO:HI   fit only points with LO <= abscissa <= HI: Hz for FRFs, rpm\n"
    "                 for unbalance responses\n"
    "  --noise A,S    noise-aware weights from the paper's eq. 19 noise model (random\n"
    "                 factor A %, systematic factor S %); points at the noise floor\n"
    "                 are left out; A,S,P adds a phase noise uniform in +-P degrees\n"
    "                 (its variance on the complex scale)\n"
    "  --sd FILE      weight each point by 1 / its variance from the --stats file\n"
    "                 of rcbtool estimate or rcbtool order written with the\n"
    "                 measurement, instead of --noise; the noise floor reported\n"
    "                 is the error % these standard deviations alone explain\n"
    "  --fd           sensitivities by finite differences (eq. 11) instead of the\n"
    "                 analytic ones (eq. 9)\n"
    "  --max-iter N   iteration limit (default 100)\n"
    "  --history FILE record this fit as a step (rcbtool history FILE shows them);\n"
    "                 one run at a time: another run on FILE waits up to\n"
    "                 RCB_LOCK_WAIT s (default 10), then exits 6\n"
    "  --starts N     when the fit ends unsure (above 1.5 x the noise floor that\n"
    "                 --noise or --sd predicts, or not converged: a local minimum or a\n"
    "                 missing effect), retry from up to N - 1 random starts within\n"
    "                 the bounds and keep the best (default 8; 1: no restart)\n"
    "  --map LIST     UFF node number <-> model station, e.g. 10=DA,20=C.A, added to\n"
    "                 the model's [uff] map (nodes without one: model node \"#N\", warned;\n"
    "                 a CSV's numeric stations, 2.x/11.x_re, map through it too);\n"
    "                 NODE.DIR=STATION.DIR maps one channel in any direction\n"
    "                 (1.z=DA.x: an accelerometer's own z; 3.s=DB.y: a scalar)\n"
    "  --rpm R        rotor speed of an FRF test, rpm (default: the file's, else the\n"
    "                 model's [test] rpm, else 0 with a warning)\n"
    "  -o FILE        write the fitted model as INI to FILE (atomically; never over\n"
    "                 MODEL.ini)\n"
    "\n"
    "Prints per parameter: start, fitted value, standard error, 95 % confidence\n"
    "interval and whether the data determine it (SVD test); then the paper's error\n"
    "in % at the start (E0) and the end (E1) (linear |H|, unweighted: the figure of\n"
    "rcbtool compare), the objective F the fit minimises (on --scale, --noise\n"
    "weights: E can rise while F falls), iterations, model evaluations, starting\n"
    "points, residuals used, convergence, the adequacy test (with --noise or --sd: is\n"
    "the fitted model's chi-square within the 1 % limit of what the noise alone\n"
    "leaves? the one rule of rcbtool diagnose) and the parameter correlation matrix.\n"
    "Progress per\n"
    "iteration goes to stderr (on a terminal, or with --progress).\n"
    "JSON: {\"params\": [{\"name\", \"start\", \"fitted\", \"stderr\", \"ci95\": [lo, hi],\n"
    "\"lo\", \"hi\", \"log\", \"identifiable\"}], \"error0_pct\", \"error_pct\",\n"
    "\"floor_pct\", \"adequacy\": {\"chi2\", \"limit\", \"adequate\" (null: noise unknown)},\n"
    "\"iterations\", \"evaluations\", \"starts\", \"starts_max\", \"residuals\", \"converged\",\n"
    "\"objective0\", "
    "\"objective\", \"sigma\", \"correlation\": [[...]], \"notes\": [...], \"output\"}\n"
    "Exit codes: 2 usage, 3 bad model, measurement or parameter name, 4 numerical\n"
    "failure, 5 output not written, 6 the --history FILE is being updated by\n"
    "another run.\n";

static const char *const scale_names[] = {"linear", "log10", "db", "complex"};

#define NOT_IDENTIFIABLE "not identifiable from these data: its value is arbitrary"

/* ---- --params NAME[:LO:HI],... (shared with rcbtool sensitivity) ---- */

void cli_params_free(cli_params *ps) {
  free(ps->buf);
  free(ps->items);
  memset(ps, 0, sizeof *ps);
}

static int parse_bound(const cli_args *a, const char *item, const char *s, double *out) {
  char *end;
  errno = 0;
  *out = strtod(s, &end);
  if (end == s || *end != '\0' || errno == ERANGE || !isfinite(*out))
    return cli_usage(a->cmd, "option --params: item '%s': bound '%s' is not a finite number; "
                     "expected NAME or NAME:LO:HI",
                     item, s);
  return 0;
}

/* One "NAME" or "NAME:LO:HI" item, split in place. */
static int param_item(const cli_args *a, char *item, cli_param_spec *p) {
  char *c1 = strchr(item, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
  int rc;
  memset(p, 0, sizeof *p);
  p->name = item;
  if (*item == '\0' || item[0] == ':')
    return cli_usage(a->cmd, "option --params has an empty parameter name; expected "
                     "NAME[:LO:HI][,...] (e.g. coupling.C.kt:1e3:1e6,coupling.C.kr)");
  if (!c1) return 0;
  if (!c2 || strchr(c2 + 1, ':'))
    return cli_usage(a->cmd, "option --params: item '%s': expected NAME or NAME:LO:HI (two "
                     "bounds)", item);
  *c1 = *c2 = '\0';
  if ((rc = parse_bound(a, item, c1 + 1, &p->lo)) || (rc = parse_bound(a, item, c2 + 1, &p->hi)))
    return rc;
  if (!(p->lo < p->hi))
    return cli_usage(a->cmd, "option --params: parameter '%s': bounds %g:%g, expected LO < HI",
                     item, p->lo, p->hi);
  p->has_bounds = 1;
  return 0;
}

int cli_params_parse(const cli_args *a, const char *opt, cli_params *ps) {
  const char *list = cli_opt_value(a, opt);
  size_t n = 1, i;
  char *p;
  int rc;
  memset(ps, 0, sizeof *ps);
  if (!list)
    return cli_usage(a->cmd, "option %s is required: the parameters, e.g. "
                     "coupling.C.kt,coupling.C.kr:1:1e5",
                     opt);
  ps->buf = malloc(strlen(list) + 1);
  if (!ps->buf) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(ps->buf, list);
  for (p = ps->buf; *p; p++) n += (*p == ',');
  ps->items = malloc(n * sizeof *ps->items);
  if (!ps->items) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  p = ps->buf;
  for (i = 0; i < n; i++) {
    char *comma = strchr(p, ',');
    if (comma) *comma = '\0';
    if ((rc = param_item(a, p, &ps->items[i]))) return rc;
    ps->n++;
    if (comma) p = comma + 1;
  }
  return 0;
}

/* Bounds of one parameter: given, or [start/1000, start*1000]; @p any makes up
 * bounds around any start (for sensitivities, where they do not matter). */
int cli_param_bounds(const cli_args *a, const cli_param_spec *p, double start, int any,
                     double *lo, double *hi) {
  if (p->has_bounds) {
    *lo = p->lo;
    *hi = p->hi;
  } else if (start > 0) {
    *lo = start / 1000;
    *hi = start * 1000;
  } else if (any) {
    *lo = start - 1000 * fabs(start) - 1;
    *hi = start + 1000 * fabs(start) + 1;
  } else {
    return cli_usage(a->cmd, "parameter '%s' starts at %g: default bounds [start/1000, "
                     "start*1000] need a start > 0; give bounds as %s:LO:HI",
                     p->name, start, p->name);
  }
  return 0;
}

int cli_param_setup(const cli_args *a, const rcb_model *m, const cli_param_spec *p, int log_all,
                    int any_bounds, double *lo, double *hi, int *logp) {
  double start;
  rcb_status st;
  if (rcb_fit_sensor_param_defaults(p->name, &start, lo, hi, logp)) {
    /* a sensor's (the measurement chain, in no model): its own bounds and scale */
    if (p->has_bounds) *lo = p->lo, *hi = p->hi;
    *logp = *logp && *lo > 0;
    return 0;
  }
  if ((st = rcb_model_get_param(m, p->name, &start)))
    return cli_fail(st == RCB_ERR_NOT_FOUND ? CLI_EXIT_INPUT : CLI_EXIT_NUMERIC, "%s: %s",
                    a->cmd, cli_msg(rcb_model_errmsg(m), st));
  *logp = log_all;
  return cli_param_bounds(a, p, start, any_bounds, lo, hi);
}

int cli_params_add(const cli_args *a, rcb_fit *f, const rcb_model *m, const cli_params *ps,
                   int log_all, int any_bounds) {
  size_t k;
  for (k = 0; k < ps->n; k++) {
    const cli_param_spec *p = &ps->items[k];
    double lo = 0.0, hi = 0.0;
    int rc, logp = 0;
    rcb_status st;
    if ((rc = cli_param_setup(a, m, p, log_all, any_bounds, &lo, &hi, &logp))) return rc;
    st = rcb_fit_add_param(f, p->name, lo, hi, logp);
    /* a sensor no channel measures is a bad name, as a model parameter's */
    if (st == RCB_ERR_ARG && rcb_fit_sensor_param_defaults(p->name, NULL, NULL, NULL, NULL))
      return cli_fail(CLI_EXIT_INPUT, "%s: %s", a->cmd, cli_msg(rcb_fit_errmsg(f), st));
    if (st)
      return st == RCB_ERR_ARG ? cli_usage(a->cmd, "%s", cli_msg(rcb_fit_errmsg(f), st))
                               : cli_fail(cli_status_exit(st), "%s: %s", a->cmd,
                                          cli_msg(rcb_fit_errmsg(f), st));
  }
  return 0;
}

/* ---- the fit job ---- */

typedef struct fit_job {
  const char *meas_path;
  cli_params params;
  int log_all, scale, method_nlopt;
  const char *algorithm; /* after "nlopt:" */
  int have_band, have_noise;
  double band_lo, band_hi; /* Hz (FRF) or rpm (unbalance) */
  double beta_a, beta_s;   /* % */
  double phase_deg;        /* the noise model's phase term, degrees */
  size_t max_iter, starts;
  int is_uff; /* the measurement is a UFF file (set by read_meas) */
  int have_sd;          /* --sd: weights and the noise floor from the standard deviations */
  cli_chain chain;      /* --sensor, --swap: the measurement chain's known corrections */
} fit_job;

/* "A<sep>B": two finite numbers. */
static int parse_pair(const cli_args *a, const char *opt, char sep, const char *what,
                      double *x, double *y) {
  const char *s = cli_opt_value(a, opt), *t;
  char *end;
  errno = 0;
  *x = strtod(s, &end);
  if (end != s && *end == sep) {
    t = end + 1;
    *y = strtod(t, &end);
    if (end != t && *end == '\0' && !errno && isfinite(*x) && isfinite(*y)) return 0;
  }
  return cli_usage(a->cmd, "option %s expects %s, got '%s'", opt, what, s);
}

static int parse_method(const cli_args *a, fit_job *j) {
  const char *s = cli_opt_value(a, "--method");
  if (!s || strcmp(s, "paper") == 0) return 0;
  if (strncmp(s, "nlopt:", 6) == 0 && s[6] != '\0') {
    j->method_nlopt = 1;
    j->algorithm = s + 6;
    return 0;
  }
  return cli_usage(a->cmd, "option --method expects paper or nlopt:ALG (e.g. nlopt:LN_BOBYQA), "
                   "got '%s'", s);
}

static int parse_job(const cli_args *a, fit_job *j) {
  int rc;
  j->log_all = cli_opt_value(a, "--log") != NULL;
  if ((rc = cli_opt_choice(a, "--scale", scale_names, 4, RCB_SCALE_LOG10, &j->scale)) ||
      (rc = parse_method(a, j)) || (rc = cli_opt_count(a, "--max-iter", 100, &j->max_iter)) ||
      (rc = cli_opt_count(a, "--starts", 8, &j->starts)))
    return rc;
  if (cli_opt_value(a, "--band")) {
    if ((rc = parse_pair(a, "--band", ':', "LO:HI (Hz for FRFs, rpm for unbalance data)",
                         &j->band_lo, &j->band_hi)))
      return rc;
    if (!(j->band_lo >= 0 && j->band_lo < j->band_hi))
      return cli_usage(a->cmd, "option --band %g:%g: expected 0 <= LO < HI", j->band_lo,
                       j->band_hi);
    j->have_band = 1;
  }
  if ((rc = cli_noise_opt(a, "--noise", &j->beta_a, &j->beta_s, &j->phase_deg))) return rc;
  j->have_noise = cli_opt_value(a, "--noise") != NULL;
  if (a->output && strcmp(a->output, "-") == 0)
    return cli_usage(a->cmd, "-o - is not supported: the report goes to standard output; give "
                     "a file for the fitted model");
  if ((rc = cli_chain_parse(a, &j->chain))) return rc;
  return cli_params_parse(a, "--params", &j->params);
}

static int read_meas(const cli_args *a, fit_job *j, const rcb_model *m, rcb_meas **out) {
  int rc = strcmp(j->meas_path, "-") == 0 ? 0 : cli_meas_format(a->cmd, j->meas_path, &j->is_uff);
  if (!rc) rc = cli_meas_read(a, j->meas_path, m, out);
  if (!rc && j->scale == RCB_SCALE_COMPLEX &&
      (rc = cli_meas_need_phase(a, *out, j->meas_path, "--scale complex (Re and Im)"))) {
    rcb_meas_destroy(*out);
    *out = NULL;
  }
  return rc;
}

/* Progress per iteration on stderr. */
typedef struct fit_progress {
  int on, tty, shown;
} fit_progress;

static int progress_cb(void *user, size_t iter, size_t evals, double objective) {
  fit_progress *p = user;
  if (!p->on) return 0;
  fprintf(stderr, "%sfit: iteration %zu, %zu model evaluations, objective %.6g%s",
          p->tty ? "\r" : "", iter, evals, objective, p->tty ? "   " : "\n");
  fflush(stderr);
  p->shown = 1;
  return 0;
}

/* The fit's message without the library's own "fit: " prefix (we add the
 * command name). */
static const char *fit_msg(const rcb_fit *f, rcb_status st) {
  const char *msg = cli_msg(rcb_fit_errmsg(f), st);
  return strncmp(msg, "fit: ", 5) == 0 ? msg + 5 : msg;
}

/* The library's status for a setting or the run, as an exit code: settings the
 * data cannot satisfy (empty band, unknown algorithm, NLopt missing) are usage. */
static int fit_exit(rcb_status st) {
  if (st == RCB_ERR_ARG || st == RCB_ERR_UNSUPPORTED) return CLI_EXIT_USAGE;
  return cli_status_exit(st);
}

static int settings(const cli_args *a, const fit_job *j, rcb_fit *f, const rcb_meas *ms) {
  double unit = rcb_meas_get_type(ms) == RCB_MEAS_FRF ? CLI_HZ_TO_RAD_S : CLI_RPM_TO_RAD_S;
  rcb_status st = rcb_fit_set_scale(f, (rcb_fit_scale)j->scale);
  if (!st && j->have_band) st = rcb_fit_set_band(f, j->band_lo * unit, j->band_hi * unit);
  if (!st && j->have_noise) st = rcb_fit_set_noise_model(f, j->beta_a, j->beta_s);
  if (!st && j->have_noise) st = rcb_fit_set_noise_phase(f, j->phase_deg * CLI_PI / 180.0);
  if (!st)
    st = rcb_fit_set_method(f, j->method_nlopt ? RCB_FIT_NLOPT : RCB_FIT_PAPER, j->algorithm);
  if (!st) st = rcb_fit_set_analytic(f, cli_opt_value(a, "--fd") == NULL);
  /* the library's default tolerances (rcb_fit_create), only the limit changes */
  if (!st) st = rcb_fit_set_limits(f, j->max_iter, 1e-10, 1e-8);
  if (!st) st = rcb_fit_set_starts(f, j->starts, 1);
  if (st)
    return cli_fail(fit_exit(st), "%s: %s", a->cmd, fit_msg(f, st));
  return 0;
}

static int make_fit(const cli_args *a, const fit_job *j, rcb_model *m, const rcb_meas *ms,
                    rcb_fit **out) {
  rcb_status st = rcb_fit_create(out, m, ms, NULL);
  int rc;
  if (st) {
    int code = st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT;
    cli_fail(code, "%s: measurement '%s' against model '%s': %s", a->cmd, j->meas_path,
             a->model, *out ? fit_msg(*out, st) : rcb_status_str(st));
    if (st == RCB_ERR_NOT_FOUND && j->is_uff && !cli_opt_value(a, "--map"))
      fputs("rcbtool: (UFF node numbers name model nodes \"#N\" unless mapped to stations "
            "with --map NODE=STATION,...)\n",
            stderr);
    return code;
  }
  if ((rc = cli_chain_fit(a, &j->chain, *out)) ||
      (rc = cli_params_add(a, *out, m, &j->params, j->log_all, 0)))
    return rc;
  return settings(a, j, *out, ms);
}

static int run_fit(const cli_args *a, rcb_fit *f) {
  fit_progress pr;
  rcb_status st;
  pr.tty = isatty(fileno(stderr));
  pr.on = a->progress || pr.tty;
  pr.shown = 0;
  rcb_fit_set_progress(f, progress_cb, &pr);
  st = rcb_fit_run(f);
  if (pr.shown && pr.tty) fputc('\n', stderr);
  if (st) return cli_fail(fit_exit(st), "%s: %s", a->cmd, fit_msg(f, st));
  return 0;
}

/* ---- report ---- */

typedef struct fit_result {
  rcb_fit_report rep;
  rcb_fit_param *par;
  double *corr; /* np x np column-major */
  size_t np;
  rcb_fit_stop stop;      /* why the run stopped */
  size_t stop_param;      /* the parameter at its bound (RCB_FIT_STOP_AT_BOUND) */
  rcb_frf_condition cond; /* condition of the final evaluation's solves */
  rcb_fit_adequacy adeq;  /* the adequacy test of the fitted model (issue #23) */
} fit_result;

static int collect(rcb_fit *f, fit_result *r) {
  size_t k;
  r->np = rcb_fit_param_count(f);
  r->par = calloc(r->np, sizeof *r->par);
  r->corr = calloc(r->np * r->np, sizeof *r->corr);
  if (!r->par || !r->corr) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  rcb_fit_get_report(f, &r->rep);
  r->stop = rcb_fit_stop_reason(f, &r->stop_param);
  if (rcb_fit_get_condition(f, &r->cond)) r->cond.ill = 0;
  if (rcb_fit_get_adequacy(f, &r->adeq, NULL, NULL, NULL)) r->adeq.known = 0;
  for (k = 0; k < r->np; k++) rcb_fit_get_param(f, k, &r->par[k]);
  if (rcb_fit_correlation(f, r->corr))
    for (k = 0; k < r->np * r->np; k++) r->corr[k] = NAN;
  return 0;
}

static void text_num(FILE *fp, int width, double x) {
  if (isfinite(x))
    fprintf(fp, "%-*.10g", width, x);
  else
    fprintf(fp, "%-*s", width, "-");
}

static void write_text_params(FILE *fp, const fit_result *r) {
  size_t k;
  int w = 9;
  for (k = 0; k < r->np; k++)
    if ((int)strlen(r->par[k].name) > w) w = (int)strlen(r->par[k].name);
  fprintf(fp, "%-*s  %-17s %-17s %-17s %-37s %s\n", w, "parameter", "start", "fitted",
          "std error", "95 % CI", "identifiable");
  for (k = 0; k < r->np; k++) {
    const rcb_fit_param *p = &r->par[k];
    char ci[80];
    if (isfinite(p->ci_lo) && isfinite(p->ci_hi))
      snprintf(ci, sizeof ci, "[%.10g, %.10g]", p->ci_lo, p->ci_hi);
    else
      snprintf(ci, sizeof ci, "-");
    fprintf(fp, "%-*s  ", w, p->name);
    text_num(fp, 18, p->start);
    text_num(fp, 18, p->value);
    text_num(fp, 18, p->stderr_);
    fprintf(fp, "%-37s %s\n", ci, p->identifiable ? "yes" : "NO");
  }
  for (k = 0; k < r->np; k++)
    if (!r->par[k].identifiable)
      fprintf(fp, "note: %s is " NOT_IDENTIFIABLE "\n", r->par[k].name);
  for (k = 0; k < r->np; k++) {
    const char *nm = r->par[k].name;
    int which = rcb_fit_sensor_param_defaults(nm, NULL, NULL, NULL, NULL);
    size_t len = strlen(nm) - (sizeof "sensor." - 1) - (which == 1 ? 5 : 6);
    if (which)
      fprintf(fp, "note: %s belongs to the measurement chain, not to the model: a model "
              "written with -o does not hold it; carry it into the next run with --sensor "
              "%.*s:%s=%.6g (on top of any --sensor correction of this run), or fit it again\n",
              nm, (int)len, nm + sizeof "sensor." - 1, which == 1 ? "gain" : "phase",
              r->par[k].value);
  }
}

/* E0/E1 are the paper's error (linear magnitudes, every point alike: the figure
 * rcbtool compare prints); the fit minimises its objective F, on the --scale
 * with the --noise weights. The two can move apart (E rising while F falls),
 * so F is printed beside E with what it measures (issue #17). */
static void write_text_objective(FILE *fp, const fit_result *r, const fit_job *j) {
  double f0 = r->rep.objective0, f1 = r->rep.objective;
  fprintf(fp, "  (E: the paper's error on linear |H|, every point weighted alike, as rcbtool "
          "compare reports it)\n");
  fprintf(fp, "objective F:         %.6g -> %.6g (%+.3g %%; what the fit minimises: squared "
          "residuals on %s%s)\n",
          f0, f1, f0 > 0 ? 100.0 * (f1 - f0) / f0 : 0.0,
          j->scale == RCB_SCALE_COMPLEX ? "Re/Im of H" : j->scale == RCB_SCALE_LINEAR ? "|H|"
          : j->scale == RCB_SCALE_DB ? "20 log10 |H|" : "log10 |H|",
          j->have_noise ? ", weighted by the --noise model"
          : j->have_sd  ? ", weighted by the --sd deviations"
                        : ", unweighted");
  if (r->rep.error_pct > r->rep.error0_pct && f1 <= f0)
    fprintf(fp, "note: E rose (%.4g %% -> %.4g %%) while F fell: the fit lowers F, not E%s\n",
            r->rep.error0_pct, r->rep.error_pct,
            r->rep.unsure ? "; here it also ends unsure (see below)"
            : j->scale == RCB_SCALE_LINEAR && !j->have_noise && !j->have_sd
                ? ""
                : " (--scale linear without --noise minimises E itself)");
}

/* Starting points tried, of the most --starts allows, and why it stopped there. */
static void write_text_starts(FILE *fp, const fit_result *r, const fit_job *j) {
  fprintf(fp, "starting points: %zu of at most %zu", r->rep.starts, j->starts);
  if (r->rep.starts < j->starts && (j->have_noise || j->have_sd))
    fputs(" (restarts run only while the result is unsure: not converged, or above 1.5 x "
          "the noise floor)",
          fp);
  else if (r->rep.starts < j->starts)
    fputs(" (without --noise a restart runs only when the fit does not converge: a local "
          "minimum cannot be told from measurement noise; give --noise A,S)",
          fp);
  else if (j->starts > 1 && r->rep.unsure)
    fputs(" (every one ended unsure: the best is kept)", fp);
  fputc('\n', fp);
}

static void write_text(FILE *fp, const fit_result *r, const fit_job *j) {
  size_t k, l;
  write_text_params(fp, r);
  fprintf(fp, "\nerror at start (E0): %.6g %%\nerror at end (E1):   %.6g %%\n",
          r->rep.error0_pct, r->rep.error_pct);
  write_text_objective(fp, r, j);
  if (isfinite(r->rep.floor_pct))
    fprintf(fp, "noise floor (predicted by the --noise model or the --sd deviations; the "
            "error reached can be lower): %.6g %%\n", r->rep.floor_pct);
  if (r->adeq.known)
    fprintf(fp, "adequacy test: chi-square %.6g %s the 1 %% limit %.6g (the noise alone: "
            "%.6g +- %.3g): the fitted model is %s\n",
            r->adeq.chi2, r->adeq.adequate ? "within" : "ABOVE", r->adeq.limit,
            r->adeq.expected, r->adeq.sd,
            r->adeq.adequate ? "consistent with the data"
                             : "not consistent with the data (an effect is missing, a local "
                               "minimum, or a faulty sensor: rcbtool diagnose)");
  else
    fputs("adequacy test: none (the noise is unknown: give --noise or --sd)\n", fp);
  fprintf(fp, "iterations: %zu\nmodel evaluations: %zu\n", r->rep.iterations,
          r->rep.evaluations);
  write_text_starts(fp, r, j);
  fprintf(fp, "residuals: %zu\nconverged: %s\n", r->rep.residuals,
          !r->rep.converged ? "no"
          : r->rep.unsure   ? "yes, to a minimum of the objective that may not be the best "
                              "(see UNSURE below)"
                            : "yes");
  fprintf(fp, "stopped: %s\n", rcb_fit_stop_str(r->stop));
  if (r->stop == RCB_FIT_STOP_AT_BOUND && r->stop_param < r->np) {
    const rcb_fit_param *p = &r->par[r->stop_param];
    fprintf(fp, "UNSURE: %s ended at its bound (%.10g): the best fit may lie outside the "
            "bounds (widen them with --params NAME:LO:HI) or the model lacks an effect\n",
            p->name, p->value);
  } else if (r->stop == RCB_FIT_STOP_STALLED || r->stop == RCB_FIT_STOP_MAX_ITER)
    fprintf(fp, "UNSURE: the fit %s (%s)\n",
            r->stop == RCB_FIT_STOP_STALLED ? "stalled: no step reduced the objective"
                                            : "used its iterations before converging",
            r->stop == RCB_FIT_STOP_STALLED ? "try --fd or another --method"
                                            : "raise --max-iter, or try --starts 8");
  else if (r->rep.unsure)
    fprintf(fp, "UNSURE: the fit did not converge or ends well above the noise floor after "
            "%zu starting point%s: a local minimum (try --starts %zu or --method "
            "nlopt:direct-l+bobyqa) or a physical effect the model lacks (rcbtool diagnose)\n",
            r->rep.starts, r->rep.starts == 1 ? "" : "s", r->rep.starts < 8 ? 8 : 4 * r->rep.starts);
  fputs("\ncorrelation matrix:\n    ", fp);
  for (l = 0; l < r->np; l++) fprintf(fp, " %7s(%zu)", "", l + 1);
  fputc('\n', fp);
  for (k = 0; k < r->np; k++) {
    fprintf(fp, "(%zu) ", k + 1);
    for (l = 0; l < r->np; l++) {
      double c = r->corr[k + r->np * l];
      if (isfinite(c))
        fprintf(fp, " %+9.5f ", c);
      else
        fprintf(fp, " %9s ", "-");
    }
    fprintf(fp, " %s\n", r->par[k].name);
  }
}

static void json_param(FILE *fp, const rcb_fit_param *p, const cli_param_spec *s,
                       int log_all) {
  fputs("{\"name\": ", fp);
  cli_json_str(fp, p->name);
  fputs(", \"start\": ", fp);
  cli_json_num(fp, p->start);
  fputs(", \"fitted\": ", fp);
  cli_json_num(fp, p->value);
  fputs(", \"stderr\": ", fp);
  cli_json_num(fp, p->stderr_);
  fputs(", \"ci95\": [", fp);
  cli_json_num(fp, p->ci_lo);
  fputs(", ", fp);
  cli_json_num(fp, p->ci_hi);
  fputs("], ", fp);
  if (s->has_bounds) {
    fputs("\"lo\": ", fp);
    cli_json_num(fp, s->lo);
    fputs(", \"hi\": ", fp);
    cli_json_num(fp, s->hi);
  } else {
    fputs("\"lo\": ", fp);
    cli_json_num(fp, p->start / 1000);
    fputs(", \"hi\": ", fp);
    cli_json_num(fp, p->start * 1000);
  }
  fprintf(fp, ", \"log\": %s, \"identifiable\": %s}", log_all ? "true" : "false",
          p->identifiable ? "true" : "false");
}

static void write_json(FILE *fp, const fit_result *r, const fit_job *j, const cli_args *a) {
  size_t k, n = 0;
  fputs("{\"model\": ", fp);
  cli_json_str(fp, a->model);
  fputs(", \"measurement\": ", fp);
  cli_json_str(fp, j->meas_path);
  fprintf(fp, ", \"method\": \"%s%s\", \"scale\": \"%s\",\n\"params\": [",
          j->method_nlopt ? "nlopt:" : "paper", j->method_nlopt ? j->algorithm : "",
          scale_names[j->scale]);
  for (k = 0; k < r->np; k++) {
    fputs(k ? ",\n  " : "\n  ", fp);
    json_param(fp, &r->par[k], &j->params.items[k], j->log_all);
  }
  fputs("],\n\"error0_pct\": ", fp);
  cli_json_num(fp, r->rep.error0_pct);
  fputs(", \"error_pct\": ", fp);
  cli_json_num(fp, r->rep.error_pct);
  fputs(", \"floor_pct\": ", fp);
  cli_json_num(fp, r->rep.floor_pct);
  fputs(", \"adequacy\": {\"chi2\": ", fp);
  cli_json_num(fp, r->adeq.chi2);
  fputs(", \"limit\": ", fp);
  cli_json_num(fp, r->adeq.limit);
  fprintf(fp, ", \"adequate\": %s}",
          !r->adeq.known ? "null" : r->adeq.adequate ? "true" : "false");
  fprintf(fp, ", \"iterations\": %zu, \"evaluations\": %zu, \"starts\": %zu, "
          "\"starts_max\": %zu, "
          "\"residuals\": %zu, \"converged\": %s, \"unsure\": %s, \"stop\": \"%s\",\n"
          "\"objective0\": ",
          r->rep.iterations, r->rep.evaluations, r->rep.starts, j->starts, r->rep.residuals,
          r->rep.converged ? "true" : "false", r->rep.unsure ? "true" : "false",
          rcb_fit_stop_str(r->stop));
  cli_json_num(fp, r->rep.objective0);
  fputs(", \"objective\": ", fp);
  cli_json_num(fp, r->rep.objective);
  fputs(", \"sigma\": ", fp);
  cli_json_num(fp, r->rep.sigma);
  fputs(",\n\"correlation\": [", fp);
  for (k = 0; k < r->np; k++) {
    fputs(k ? ", " : "", fp);
    cli_json_nums(fp, r->corr + k, r->np, r->np); /* row k of a symmetric matrix */
  }
  fputs("],\n\"notes\": [", fp);
  for (k = 0; k < r->np; k++)
    if (!r->par[k].identifiable) {
      fprintf(fp, "%s\"%s is " NOT_IDENTIFIABLE "\"", n++ ? ", " : "", r->par[k].name);
    }
  fputs("], \"output\": ", fp);
  if (a->output)
    cli_json_str(fp, a->output);
  else
    fputs("null", fp);
  fputs("}\n", fp);
}

/* The fitted model as INI, written atomically to -o FILE. */
static int write_model(const cli_args *a, const rcb_model *m) {
  size_t need = 0;
  char *buf;
  cli_out o;
  int rc;
  rcb_status st = rcb_model_write_ini(m, NULL, 0, &need);
  if (st != RCB_OK && st != RCB_ERR_WORKSPACE)
    return cli_fail(cli_status_exit(st), "%s: writing the fitted model: %s", a->cmd,
                    cli_msg(rcb_model_errmsg(m), st));
  buf = malloc(need);
  if (!buf) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  st = rcb_model_write_ini(m, buf, need, &need);
  if (st) {
    free(buf);
    return cli_fail(cli_status_exit(st), "%s: writing the fitted model: %s", a->cmd,
                    cli_msg(rcb_model_errmsg(m), st));
  }
  if ((rc = cli_out_open(&o, a))) {
    free(buf);
    return rc;
  }
  fputs(buf, o.fp);
  free(buf);
  return cli_out_close(&o);
}

static int report(const cli_args *a, const fit_job *j, rcb_fit *f, const rcb_model *m) {
  fit_result r;
  int rc;
  memset(&r, 0, sizeof r);
  if (!(rc = collect(f, &r))) {
    cli_warn_condition(a->cmd, &r.cond, 0);
    if (a->json)
      write_json(stdout, &r, j, a);
    else
      write_text(stdout, &r, j);
    errno = 0;
    if (fflush(stdout) != 0 || ferror(stdout))
      rc = cli_fail(CLI_EXIT_IO, "cannot write to standard output: %s",
                    strerror(errno ? errno : EIO));
  }
  if (!rc && cli_opt_value(a, "--history")) {
    char note[160];
    /* E is the paper's error (compare's figure); the objective's change beside it
     * says why E may rise in a fit that lowered what it minimises */
    snprintf(note, sizeof note, "fit: error %.4g %% -> %.4g %% (objective %+.3g %%)%s",
             r.rep.error0_pct, r.rep.error_pct,
             r.rep.objective0 > 0
                 ? 100.0 * (r.rep.objective - r.rep.objective0) / r.rep.objective0
                 : 0.0,
             r.rep.unsure ? " (unsure)" : "");
    rc = cli_history_append(cli_opt_value(a, "--history"), "fit", a->model, r.rep.error_pct,
                            r.rep.floor_pct, r.np, note);
  }
  free(r.par);
  free(r.corr);
  if (!rc && a->output) rc = write_model(a, m);
  return rc;
}

/* --sd FILE: weights (and the noise floor) from the estimated standard
 * deviations. */
static int sd_weights(const cli_args *a, fit_job *j, rcb_fit *f, const rcb_meas *ms) {
  const char *path = cli_opt_value(a, "--sd");
  double *sd = NULL;
  rcb_status st;
  int rc;
  if (!path) return 0;
  if (j->have_noise) return cli_usage(a->cmd, "give --noise or --sd, not both");
  if ((rc = cli_sd_read(path, ms, &sd))) return rc;
  j->have_sd = 1;
  st = rcb_fit_set_sd(f, sd);
  free(sd);
  if (st) return cli_fail(fit_exit(st), "%s: %s", a->cmd, fit_msg(f, st));
  return 0;
}

static int run(const cli_args *a, fit_job *j) {
  rcb_model *m = NULL;
  rcb_meas *ms = NULL;
  rcb_fit *f = NULL;
  int rc;
  if ((rc = cli_load_model(a, &m))) return rc;
  if (!(rc = read_meas(a, j, m, &ms)) && !(rc = make_fit(a, j, m, ms, &f)) &&
      !(rc = sd_weights(a, j, f, ms)) && !(rc = run_fit(a, f)))
    rc = report(a, j, f, m);
  rcb_fit_destroy(f);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  return rc;
}

int cmd_fit(int argc, char **argv) {
  cli_opt opts[] = {{"--params", "NAME[:LO:HI],...", NULL},
                    {"--log", NULL, NULL},
                    {"--method", "paper|nlopt:ALG", NULL},
                    {"--scale", "SCALE", NULL},
                    {"--band", "LO:HI", NULL},
                    {"--noise", "BETA_A,BETA_S[,PHASE_DEG]", NULL},
                    {"--sd", "FILE", NULL},
                    {"--fd", NULL, NULL},
                    {"--max-iter", "N", NULL},
                    {"--starts", "N", NULL},
                    {"--history", "FILE", NULL},
                    {"--map", "NODE=STATION,...", NULL},
                    {"--rpm", "R", NULL},
                    {"--sensor", "RESP:KEY=V,...", NULL},
                    {"--swap", "A,B,...", NULL}};
  size_t nopts = sizeof opts / sizeof opts[0];
  fit_job j;
  cli_args a;
  char **args = NULL;
  int rc;
  static const cli_file_opt files[] = {{"--sd", CLI_IO_IN}, {"--history", CLI_IO_INOUT}};
  memset(&j, 0, sizeof j);
  cli_plan_options(files, sizeof files / sizeof files[0]);
  if (!(rc = cli_parse_meas_cmd(argc, argv, opts, nopts, cli_help_fit,
                                "'rcbtool fit MODEL.ini MEAS.uff|MEAS.csv --params ...'",
                                &a, &j.meas_path, &args)) &&
      !(rc = parse_job(&a, &j)))
    rc = run(&a, &j);
  cli_params_free(&j.params);
  cli_chain_free(&j.chain);
  free(args);
  return rc < 0 ? CLI_EXIT_OK : rc;
}
