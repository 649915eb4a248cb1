/* rcbtool diagnose: which physical effect is the model missing, and where?
 * With --apply K, write the model with candidate K added and fitted. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

const char cli_help_diagnose[] =
    "usage: rcbtool diagnose MODEL.ini MEAS.uff|MEAS.csv [--params NAME[:LO:HI],...]\n"
    "                        [--log] [--scale linear|log10|db|complex] [--noise A,S|--sd FILE]\n"
    "                        [--band LO:HI] [--map NODE=STATION,...] [--rpm R] [--refits N]\n"
    "                        [--top N] [--apply K [--force] -o MODEL2.ini]\n"
    "                        [--sensor RESP:KEY=V,...] [--swap A,B,...] [--history FILE]\n"
    "                        [--threads N] [--json] [--progress]\n"
    "\n"
    "Fits the model as it is (the --params, e.g. the coupling's kt and kr), then\n"
    "scores every effect of the catalogue at every place it can occur: coupling\n"
    "damping and rotational stiffness, another coupling model, coupling hub mass\n"
    "and inertia, bearing stiffness in each direction (anisotropy), bearing\n"
    "cross-coupled stiffness kxy = -kyx, bearing damping, a flexible support (a\n"
    "pedestal mass on a spring and damper) under each bearing, shaft material\n"
    "damping, an added mass or inertia at each node, a local change of stiffness\n"
    "(a crack, wear, a loose fit) or of mass of each shaft element\n"
    "(shaft.S.e<k>.stiffness | mass; 'rcbtool check' lists the elements), and\n"
    "(FRF data) an operating speed other than the stated one; a change along a\n"
    "span of a shaft (shaft.S.e<a>-<b>.stiffness | mass) is searched for when a\n"
    "shaft's stiffness or mass leads and nothing explains. A CSV of magnitudes\n"
    "only ('mag' or 'dB' columns, no phase) is diagnosed on the magnitude scales:\n"
    "--scale complex is refused, and the placement along the shaft (fitted on the\n"
    "complex scale) is skipped, as the explanation says. The score is the\n"
    "error reduction the effect can explain (score test on the weighted\n"
    "objective, orthogonal to the fitted parameters); the best N (--refits,\n"
    "default 8) and the other coupling models are refitted. What may be said of\n"
    "a candidate follows one rule (rcb_evidence_claim): it is significant when\n"
    "BIC falls by more than 10 (and, without --noise or --sd, the error by at\n"
    "least 2 % of itself); it \"explains\" the data only when it is\n"
    "significant and the model with it passes the adequacy test (its chi-square\n"
    "within the 1 % limit of what the noise alone leaves: --noise or --sd needed),\n"
    "or fails it with a residual white along frequency at most 2 x the declared\n"
    "noise level (noise of another level, RCB_WHITE_LEVEL_MAX); a significant one\n"
    "that fails both \"improves\": another effect is still missing, or (white but\n"
    "further above the declared noise) the data cannot tell a missing effect from\n"
    "a noise declared too low. Candidates are ranked by that claim (explains, improves, none), then\n"
    "by the change of BIC. When nothing explains the data, the report says where\n"
    "the misfit concentrates (per response sensor), and a sensor whose misfit\n"
    "stands out is named to be checked first. The catalogue also holds faults of\n"
    "the measurement chain (a sensor's gain, sign, two swapped probes): they\n"
    "never change the model, and --apply refuses them. A sensor finding names the\n"
    "options that read the data through its correction in the next round (round\n"
    "2 then neither needs nor names it again): its gain fitted with the model's\n"
    "parameters (--params ...,sensor.DB.y.gain), a sign (--sensor DB.y:sign=-1)\n"
    "or a swap (--swap DB.x,DB.y); the same options work for rcbtool fit.\n"
    "On large sets (where a subset of the frequencies keeps at most half of\n"
    "them) the refits are screened on that subset and evaluated on all points\n"
    "where their screen ended; only those within 10 % of the best objective are\n"
    "polished on all points. The others are marked \"screened\" (\"screened_only\"\n"
    "in JSON): their dBIC is an upper bound, their error the screened point's.\n"
    "  --noise A,S    the eq. 19 noise model (random A %, systematic S %): weights\n"
    "                 and the noise floor (strongly recommended); A,S,P adds a\n"
    "                 phase noise uniform in +-P degrees (complex scale)\n"
    "  --sd FILE      instead of --noise: weights and the noise floor from the\n"
    "                 standard deviations of the --stats file of rcbtool estimate\n"
    "                 or order written with the measurement; the objective is\n"
    "                 then a chi-square, and dBIC = F - F0 + k ln N\n"
    "  --band LO:HI   use only this band: Hz for FRF data, rpm for unbalance data\n"
    "  --params LIST  the model's parameters to fit first, as for rcbtool fit, and\n"
    "                 sensor gains and phases (sensor.DB.y.gain: dimensionless,\n"
    "                 [0.1, 10]; sensor.DB.y.phase: rad, [-pi/2, pi/2])\n"
    "  --sensor LIST  known sensor corrections, RESP:KEY=V[,KEY=V][,RESP2:...] with\n"
    "                 KEY gain (dimensionless), phase (rad) or sign (-1 or 1),\n"
    "                 carried into every fit (as for rcbtool fit)\n"
    "  --swap LIST    probes known to be swapped, in pairs A,B[,C,D...]\n"
    "  --refits N     candidates refitted (default 8)\n"
    "  --top N        candidates to print (default 10)\n"
    "  --threads N    fit the candidates on N threads (default 1); the same\n"
    "                 numbers bit for bit\n"
    "  --apply K      with -o FILE: write the model with candidate K (1 = best)\n"
    "                 added and fitted, atomically; the input model is untouched.\n"
    "                 A candidate that is not significant is refused (exit 3)\n"
    "  --force        with --apply: write a candidate that is not significant\n"
    "                 all the same (a warning says so)\n"
    "  --history FILE record this step (rcbtool history FILE shows the steps); one\n"
    "                 run at a time, as for fit\n"
    "  --json         the ranking as JSON: per candidate \"claim\" (explains,\n"
    "                 improves, none), \"significant\", \"adequate\" (null when\n"
    "                 unknown), \"chi2\", \"chi2_limit\", \"chain\", \"carry\" (a sensor\n"
    "                 finding's options for the next round); \"adequacy\" of\n"
    "                 the model as it is (chi2, dof, expected, sd, limit,\n"
    "                 adequate); \"misfit\": per sensor chi2, expected, excess_pct,\n"
    "                 concentrated; and \"evaluations\" (model sweeps, a\n"
    "                 Jacobian counting one), \"scored\", \"refits\" and \"restarts\"\n"
    "                 (refits that tried random starts after their screen)\n"
    "Units of the report: error % and the noise floor %: the relative error of\n"
    "the model against the data, in percent (the floor is predicted from --noise\n"
    "or --sd, not measured); score %: the part of that error the effect can\n"
    "explain, in percent; dBIC: change of the Bayesian information criterion (no unit;\n"
    "below -10 with a falling error is significant); chi-square: the weighted\n"
    "objective (no unit); fitted: values in SI units\n"
    "(N/m, N s/m, N m/rad, N m s/rad, kg, kg m^2).\n"
    "Other options as for rcbtool fit. Exit codes: 0 ok, 2 usage, 3 bad input,\n"
    "4 numerical failure, 5 output error, 6 the --history FILE is being updated\n"
    "by another run.\n";

static const char *const scale_names[] = {"linear", "log10", "db", "complex"};

typedef struct diag_job {
  const char *meas_path;
  cli_params params;
  int have_params, log_all, scale, have_noise, have_band, have_sd;
  double beta_a, beta_s, band_lo, band_hi;
  double phase_deg; /* the noise model's phase term, degrees */
  size_t refits, top, apply, threads;
  int force;
  const char *history;
  cli_chain chain; /* --sensor, --swap: the measurement chain's known corrections */
} diag_job;

static int pair(const cli_args *a, const char *opt, char sep, double *x, double *y) {
  const char *s = cli_opt_value(a, opt), *t = s ? strchr(s, sep) : NULL;
  char *e1, *e2;
  if (!t) return cli_usage(a->cmd, "option %s expects two numbers separated by '%c'", opt, sep);
  *x = strtod(s, &e1);
  *y = strtod(t + 1, &e2);
  if (e1 != t || *e2 || !isfinite(*x) || !isfinite(*y))
    return cli_usage(a->cmd, "option %s expects two numbers separated by '%c', got '%s'", opt,
                     sep, s);
  return 0;
}

static int parse_job(const cli_args *a, diag_job *j) {
  int rc;
  j->log_all = cli_opt_value(a, "--log") != NULL;
  j->history = cli_opt_value(a, "--history");
  j->have_sd = cli_opt_value(a, "--sd") != NULL;
  j->force = cli_opt_value(a, "--force") != NULL;
  if ((rc = cli_opt_choice(a, "--scale", scale_names, 4, RCB_SCALE_LOG10, &j->scale)) ||
      (rc = cli_opt_count(a, "--refits", 8, &j->refits)) ||
      (rc = cli_opt_count(a, "--top", 10, &j->top)) ||
      (rc = cli_opt_count(a, "--threads", 1, &j->threads)) ||
      (rc = cli_opt_count(a, "--apply", 0, &j->apply)))
    return rc;
  j->have_noise = cli_opt_value(a, "--noise") != NULL;
  if ((rc = cli_noise_opt(a, "--noise", &j->beta_a, &j->beta_s, &j->phase_deg))) return rc;
  if ((j->have_band = cli_opt_value(a, "--band") != NULL) &&
      (rc = pair(a, "--band", ':', &j->band_lo, &j->band_hi)))
    return rc;
  if (j->apply && !a->output)
    return cli_usage(a->cmd, "--apply K writes a model: give -o MODEL2.ini");
  if (j->force && !j->apply) return cli_usage(a->cmd, "--force goes with --apply K");
  if ((rc = cli_chain_parse(a, &j->chain))) return rc;
  if ((j->have_params = cli_opt_value(a, "--params") != NULL) &&
      (rc = cli_params_parse(a, "--params", &j->params)))
    return rc;
  return 0;
}

static int setup(const cli_args *a, const diag_job *j, const rcb_model *m, const rcb_meas *ms,
                 rcb_diag *d) {
  double unit = rcb_meas_get_type(ms) == RCB_MEAS_FRF ? CLI_HZ_TO_RAD_S : CLI_RPM_TO_RAD_S;
  rcb_status st = rcb_diag_set_scale(d, (rcb_fit_scale)j->scale);
  size_t k;
  if (!st && j->have_noise) st = rcb_diag_set_noise_model(d, j->beta_a, j->beta_s);
  if (!st && j->have_noise) st = rcb_diag_set_noise_phase(d, j->phase_deg * CLI_PI / 180.0);
  if (!st && cli_opt_value(a, "--sd")) {
    double *sd = NULL;
    int rc;
    if (j->have_noise) return cli_usage(a->cmd, "give --noise or --sd, not both");
    if ((rc = cli_sd_read(cli_opt_value(a, "--sd"), ms, &sd))) return rc;
    st = rcb_diag_set_sd(d, sd, rcb_meas_channel_count(ms) * rcb_meas_point_count(ms));
    free(sd);
    if (st) return cli_fail(CLI_EXIT_INPUT, "%s: --sd: %s", a->cmd, rcb_diag_errmsg(d));
  }
  if (!st && j->have_band) st = rcb_diag_set_band(d, j->band_lo * unit, j->band_hi * unit);
  if (!st) st = rcb_diag_set_refits(d, j->refits);
  if (st) return cli_usage(a->cmd, "invalid --noise, --band or --refits value");
  if (rcb_diag_set_threads(d, j->threads))
    return cli_usage(a->cmd, "--threads %zu: from 1 to %d", j->threads, RCB_DIAG_MAX_THREADS);
  for (k = 0; j->have_params && k < j->params.n; k++) {
    const cli_param_spec *p = &j->params.items[k];
    double lo = 0, hi = 0;
    int rc, logp = 0;
    if ((rc = cli_param_setup(a, m, p, j->log_all, 0, &lo, &hi, &logp))) return rc;
    if ((st = rcb_diag_add_fitted_param(d, p->name, lo, hi, logp)))
      return cli_fail(st == RCB_ERR_ARG ? CLI_EXIT_INPUT : CLI_EXIT_NUMERIC, "%s: %s", a->cmd,
                      rcb_diag_errmsg(d));
  }
  return cli_chain_diag(a, &j->chain, d);
}

typedef struct prog_ctx {
  cli_progress p;
  const cli_args *a;
  int started;
} prog_ctx;

static int progress_cb(void *user, size_t done, size_t total) {
  prog_ctx *c = user;
  if (!c->started) {
    cli_progress_start(&c->p, c->a, "diagnose", "steps", total);
    c->started = 1;
  }
  cli_progress_step(&c->p, done);
  return 0;
}

/* The adequacy test of the model as it is, and the sensors by misfit. */
static void print_adequacy(FILE *fp, const rcb_diag *d) {
  rcb_fit_adequacy t;
  size_t k, n = rcb_diag_misfit_count(d);
  if (rcb_diag_adequacy(d, &t) || !t.known) {
    fputs("adequacy test: none (the noise is unknown: give --noise or --sd)\n\n", fp);
    return;
  }
  fprintf(fp, "adequacy test of the model as it is: chi-square %.6g, %s the 1 %% limit %.6g "
          "(the noise alone: %.6g +- %.3g; %.0f degrees of freedom)\n",
          t.chi2, t.adequate ? "within" : "ABOVE", t.limit, t.expected, t.sd, t.dof);
  fprintf(fp, "the residual along frequency: %s (lag-1 statistic %.3g, 1 %% limit %.3g); "
          "chi-square / expected %.4g\n",
          t.white ? "white" : "STRUCTURED", t.white_z, RCB_ADEQUACY_Z, t.dispersion);
  if (!t.adequate && n) {
    fprintf(fp, "%-14s %12s %12s %9s  %s\n", "sensor", "chi-square", "noise alone",
            "excess %", "");
    for (k = 0; k < n && k < 8; k++) {
      rcb_diag_misfit s;
      char name[256];
      rcb_diag_misfit_get(d, k, &s);
      fprintf(fp, "%-14s %12.6g %12.6g %9.1f  %s\n", cli_text(s.sensor, name, sizeof name),
              s.chi2, s.expected,
              s.excess_pct, s.concentrated ? "<- the misfit concentrates here" : "");
    }
  }
  fputc('\n', fp);
}

static void print_text(FILE *fp, const diag_job *j, const rcb_diag *d, const char *explain) {
  double e0, floor_pct;
  size_t k, n = rcb_diag_candidate_count(d);
  rcb_diag_baseline(d, &e0, NULL, &floor_pct);
  fprintf(fp, "the model as it is: error %.4g %%", e0);
  if (isfinite(floor_pct))
    fprintf(fp, " (noise floor %.4g %%, predicted by the %s; the error reached can be lower)",
            floor_pct, j->have_sd ? "--sd deviations" : "--noise model");
  fprintf(fp, "; %zu candidates scored\n\n", n);
  print_adequacy(fp, d);
  fprintf(fp, "%-4s %-8s %-58s %9s %9s %10s  %s\n", "rank", "claim", "candidate", "score %",
          "error %", "dBIC", "fitted");
  for (k = 0; k < n && k < j->top; k++) {
    rcb_diag_candidate c;
    char desc[1024];
    rcb_diag_candidate_get(d, k, &c);
    /* names from the model file: escaped by the one rule (cli_text) */
    fprintf(fp, "%-4zu %-8s %-58.58s %9.3g ", k + 1, rcb_claim_str(c.claim),
            cli_text(c.description, desc, sizeof desc), c.predicted_pct);
    if (c.refitted) {
      fprintf(fp, "%9.4g %+10.1f  ", c.error_pct, c.delta_bic);
      cli_put_text(fp, c.fitted);
      fprintf(fp, "%s\n", c.screened_only ? " (screened: dBIC an upper bound)" : "");
    } else {
      fprintf(fp, "%9s %10s  ", "-", "-");
      cli_put_text(fp, c.fitted[0] ? c.fitted : "(not refitted)");
      fputc('\n', fp);
    }
  }
  fputc('\n', fp);
  cli_put_text(fp, explain);
  fputc('\n', fp);
}

/* "adequacy" and "misfit" (per sensor) of the model as it is. */
static void json_adequacy(FILE *fp, const rcb_diag *d) {
  rcb_fit_adequacy t;
  size_t k, n = rcb_diag_misfit_count(d);
  if (rcb_diag_adequacy(d, &t)) return;
  fprintf(fp, ",\n\"adequacy\": {\"known\": %s, \"chi2\": ", t.known ? "true" : "false");
  cli_json_num(fp, t.chi2);
  fputs(", \"dof\": ", fp);
  cli_json_num(fp, t.dof);
  fputs(", \"expected\": ", fp);
  cli_json_num(fp, t.known ? t.expected : (double)NAN);
  fputs(", \"sd\": ", fp);
  cli_json_num(fp, t.known ? t.sd : (double)NAN);
  fputs(", \"limit\": ", fp);
  cli_json_num(fp, t.limit);
  fprintf(fp, ", \"adequate\": %s, \"white_z\": ",
          !t.known ? "null" : t.adequate ? "true" : "false");
  cli_json_num(fp, t.known ? t.white_z : (double)NAN);
  fprintf(fp, ", \"white\": %s, \"dispersion\": ", !t.known ? "null" : t.white ? "true" : "false");
  cli_json_num(fp, t.dispersion);
  fputs("}", fp);
  fputs(",\n\"misfit\": {\"sensors\": [", fp);
  for (k = 0; k < n; k++) {
    rcb_diag_misfit s;
    rcb_diag_misfit_get(d, k, &s);
    fprintf(fp, "%s{\"response\": ", k ? ", " : "");
    cli_json_str(fp, s.sensor);
    fputs(", \"chi2\": ", fp);
    cli_json_num(fp, s.chi2);
    fputs(", \"expected\": ", fp);
    cli_json_num(fp, s.expected);
    fputs(", \"ratio\": ", fp);
    cli_json_num(fp, s.expected > 0 ? s.chi2 / s.expected : (double)NAN);
    fputs(", \"excess_pct\": ", fp);
    cli_json_num(fp, s.excess_pct);
    fprintf(fp, ", \"concentrated\": %s, \"z_even\": ", s.concentrated ? "true" : "false");
    cli_json_num(fp, s.z_even);
    fprintf(fp, ", \"uneven\": %s}", s.uneven ? "true" : "false");
  }
  fputs("]}", fp);
  /* where equivalent loads place it (rcb_diag_place_get), the largest share first */
  n = rcb_diag_place_count(d);
  fputs(",\n\"places\": [", fp);
  for (k = 0; k < n; k++) {
    rcb_diag_place p;
    rcb_diag_place_get(d, k, &p);
    fprintf(fp, "%s{\"node\": %zu, \"shaft\": ", k ? ", " : "", p.node);
    cli_json_str(fp, p.shaft);
    fputs(", \"z\": ", fp);
    cli_json_num(fp, p.z);
    fputs(", \"share_pct\": ", fp);
    cli_json_num(fp, p.share_pct);
    fputs(", \"chi2\": ", fp);
    cli_json_num(fp, p.chi2);
    fputs(", \"dof\": ", fp);
    cli_json_num(fp, p.dof);
    fprintf(fp, ", \"adequate\": %s, \"in_span\": %s, \"at_drive\": %s}",
            p.adequate ? "true" : "false", p.in_span ? "true" : "false",
            p.at_drive ? "true" : "false");
  }
  fputs("]", fp);
}

static void print_json(FILE *fp, const diag_job *j, const rcb_diag *d, const char *explain) {
  double e0, floor_pct;
  rcb_diag_stats stats;
  size_t k, n = rcb_diag_candidate_count(d);
  rcb_diag_baseline(d, &e0, NULL, &floor_pct);
  fputs("{\"error0_pct\": ", fp);
  cli_json_num(fp, e0);
  fputs(", \"floor_pct\": ", fp);
  cli_json_num(fp, floor_pct);
  if (rcb_diag_get_stats(d, &stats) == RCB_OK) /* the work done: model sweeps, candidates */
    fprintf(fp, ", \"evaluations\": %zu, \"scored\": %zu, \"refits\": %zu, \"restarts\": %zu",
            stats.evaluations, stats.scored, stats.refits, stats.restarts);
  fputs(", \"explanation\": ", fp);
  cli_json_str(fp, explain);
  json_adequacy(fp, d);
  fputs(",\n\"candidates\": [", fp);
  for (k = 0; k < n && k < j->top; k++) {
    rcb_diag_candidate c;
    rcb_diag_candidate_get(d, k, &c);
    fprintf(fp, "%s\n  {\"rank\": %zu, \"effect\": ", k ? "," : "", k + 1);
    cli_json_str(fp, rcb_effect_name(c.effect));
    fputs(", \"place\": ", fp);
    cli_json_str(fp, c.place);
    fputs(", \"description\": ", fp);
    cli_json_str(fp, c.description);
    fputs(", \"params\": ", fp);
    cli_json_str(fp, c.params);
    fputs(", \"score_pct\": ", fp);
    cli_json_num(fp, c.predicted_pct);
    fprintf(fp, ", \"refitted\": %s, \"error_pct\": ", c.refitted ? "true" : "false");
    cli_json_num(fp, c.error_pct);
    fputs(", \"delta_bic\": ", fp);
    cli_json_num(fp, c.delta_bic);
    fprintf(fp, ", \"claim\": \"%s\", \"significant\": %s, \"adequate\": %s, \"chi2\": ",
            rcb_claim_str(c.claim), c.significant ? "true" : "false",
            c.adequate < 0 ? "null" : c.adequate ? "true" : "false");
    cli_json_num(fp, c.chi2);
    fputs(", \"chi2_limit\": ", fp);
    cli_json_num(fp, c.chi2_limit);
    fputs(", \"dispersion\": ", fp);
    cli_json_num(fp, c.dispersion);
    fputs(", \"white_z\": ", fp);
    cli_json_num(fp, c.white_z);
    fprintf(fp, ", \"white\": %s, \"beyond\": %s", c.white < 0 ? "null" : c.white ? "true" : "false",
            c.beyond ? "true" : "false");
    fprintf(fp, ", \"chain\": %s, \"screened_only\": %s, \"fitted\": ",
            c.chain ? "true" : "false", c.screened_only ? "true" : "false");
    cli_json_str(fp, c.fitted);
    fputs(", \"carry\": ", fp);
    cli_json_str(fp, c.carry);
    fputs("}", fp);
  }
  fputs("]}\n", fp);
}

/* --apply K: the candidate's fitted model, written as INI, to -o; the
 * report to stdout. */
static int apply(const cli_args *a, const diag_job *j, const rcb_diag *d) {
  size_t need = 0;
  char *buf;
  rcb_model *m = NULL;
  cli_out o;
  int rc;
  if (j->apply > rcb_diag_candidate_count(d))
    return cli_usage(a->cmd, "--apply %zu: there are %zu candidates", j->apply,
                     rcb_diag_candidate_count(d));
  {
    rcb_diag_candidate c;
    if (rcb_diag_candidate_get(d, j->apply - 1, &c) == RCB_OK && c.chain)
      return cli_fail(CLI_EXIT_INPUT,
                      "%s: --apply %zu: candidate %zu (%s) is a fault of the measurement "
                      "chain, not of the model: nothing written; check or recalibrate the "
                      "sensor, or read the data through the correction in the next round "
                      "(rcbtool fit or diagnose with %s)",
                      a->cmd, j->apply, j->apply, c.description, c.carry);
    if (rcb_diag_candidate_get(d, j->apply - 1, &c) == RCB_OK && c.claim == RCB_CLAIM_NONE) {
      if (!j->force)
        return cli_fail(CLI_EXIT_INPUT,
                        "%s: --apply %zu: candidate %zu (%s) is not significant (dBIC %+.1f; "
                        "significant needs BIC to fall by more than 10, and without --noise "
                        "or --sd the error by 2 %% of itself): the model would be fitting "
                        "noise; nothing written. Apply "
                        "a significant candidate, bring more data, or add --force",
                        a->cmd, j->apply, j->apply, c.description, c.delta_bic);
      cli_warn("%s: --apply %zu --force: candidate %zu (%s) is not significant (dBIC %+.1f): "
               "the model written may be fitting noise",
               a->cmd, j->apply, j->apply, c.description, c.delta_bic);
    }
  }
  if (rcb_diag_apply_model(d, j->apply - 1, NULL, &m))
    return cli_fail(CLI_EXIT_INPUT, "%s: %s", a->cmd, rcb_diag_errmsg(d));
  if (rcb_model_write_ini(m, NULL, 0, &need) != RCB_ERR_WORKSPACE) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "%s: %s", a->cmd, rcb_model_errmsg(m));
    rcb_model_destroy(m);
    return rc;
  }
  if (!(buf = malloc(need))) {
    rcb_model_destroy(m);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  rcb_model_write_ini(m, buf, need, &need);
  rcb_model_destroy(m);
  if ((rc = cli_out_open(&o, a))) {
    free(buf);
    return rc;
  }
  fputs(buf, o.fp);
  free(buf);
  return cli_out_close(&o);
}

static int record(const cli_args *a, const diag_job *j, const rcb_diag *d, const char *text) {
  double e0, floor_pct;
  rcb_diag_candidate c;
  char note[800];
  rcb_diag_baseline(d, &e0, NULL, &floor_pct);
  if (j->apply && !rcb_diag_candidate_get(d, j->apply - 1, &c)) {
    snprintf(note, sizeof note, "applied: %s (%s); claim: %s", c.description, c.fitted,
             rcb_claim_str(c.claim));
    return cli_history_append(j->history, "apply", a->output, c.error_pct, floor_pct,
                              (j->have_params ? j->params.n : 0) +
                                  (size_t)(strchr(c.params, ',') ? 2 : 1),
                              note);
  }
  return cli_history_append(j->history, "diagnose", a->model, e0, floor_pct,
                            j->have_params ? j->params.n : 0, text);
}

static int run(const cli_args *a, diag_job *j) {
  rcb_model *m = NULL;
  rcb_meas *ms = NULL;
  rcb_diag *d = NULL;
  char *text = NULL;
  size_t need = 0;
  rcb_status st;
  prog_ctx pc;
  int rc;
  memset(&pc, 0, sizeof pc);
  pc.a = a;
  if ((rc = cli_load_model(a, &m))) return rc;
  if ((rc = cli_meas_read(a, j->meas_path, m, &ms))) goto done;
  if (j->scale == RCB_SCALE_COMPLEX &&
      (rc = cli_meas_need_phase(a, ms, j->meas_path, "--scale complex (Re and Im)")))
    goto done;
  if ((st = rcb_diag_create(&d, m, ms, NULL))) {
    rc = cli_fail(cli_status_exit(st), "%s: %s", a->cmd, cli_msg(rcb_diag_errmsg(d), st));
    goto done;
  }
  if ((rc = setup(a, j, m, ms, d))) goto done;
  rcb_diag_set_progress(d, progress_cb, &pc);
  /* the first step (fitting the model's own parameters) reports nothing: say so */
  if (a->progress || isatty(fileno(stderr)))
    fputs("diagnose: fitting the model as it is, then scoring the candidates\n", stderr);
  if ((st = rcb_diag_run(d))) {
    if (pc.started) cli_progress_end(&pc.p);
    rc = cli_fail(cli_status_exit(st), "%s: %s", a->cmd, cli_msg(rcb_diag_errmsg(d), st));
    goto done;
  }
  if (pc.started) cli_progress_end(&pc.p);
  rcb_diag_explain(d, NULL, 0, &need); /* two-call sizing */
  if (!(text = malloc(need ? need : 1)) || rcb_diag_explain(d, text, need, &need)) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "%s: out of memory", a->cmd);
    goto done;
  }
  (a->json ? print_json : print_text)(stdout, j, d, text);
  if (j->apply && (rc = apply(a, j, d))) goto done;
  if (j->history) rc = record(a, j, d, text);
done:
  free(text);
  rcb_diag_destroy(d);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  return rc;
}

int cmd_diagnose(int argc, char **argv) {
  cli_opt opts[] = {{"--params", "NAME[:LO:HI],...", NULL},
                    {"--log", NULL, NULL},
                    {"--scale", "SCALE", NULL},
                    {"--noise", "BETA_A,BETA_S[,PHASE_DEG]", NULL},
                    {"--sd", "FILE", NULL},
                    {"--band", "LO:HI", NULL},
                    {"--map", "NODE=STATION,...", NULL},
                    {"--rpm", "R", NULL},
                    {"--refits", "N", NULL},
                    {"--top", "N", NULL},
                    {"--threads", "N", NULL},
                    {"--apply", "K", NULL},
                    {"--force", NULL, NULL},
                    {"--history", "FILE", NULL},
                    {"--sensor", "RESP:KEY=V,...", NULL},
                    {"--swap", "A,B,...", NULL}};
  size_t nopts = sizeof opts / sizeof opts[0];
  diag_job j;
  cli_args a;
  char **args = NULL;
  int rc;
  static const cli_file_opt files[] = {{"--sd", CLI_IO_IN}, {"--history", CLI_IO_INOUT}};
  memset(&j, 0, sizeof j);
  cli_plan_options(files, sizeof files / sizeof files[0]);
  if (!(rc = cli_parse_meas_cmd(argc, argv, opts, nopts, cli_help_diagnose,
                                "'rcbtool diagnose MODEL.ini MEAS.uff|MEAS.csv'",
                                &a, &j.meas_path, &args)) &&
      !(rc = parse_job(&a, &j)))
    rc = run(&a, &j);
  if (j.have_params) cli_params_free(&j.params);
  cli_chain_free(&j.chain);
  free(args);
  return rc < 0 ? CLI_EXIT_OK : rc;
}
