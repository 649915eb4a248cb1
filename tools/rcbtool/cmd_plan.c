/* rcbtool plan: which test would tell two rival effects apart (issue #23
 * item 6)? The separability of the present data (principal angle, the
 * chi-square by which the best rival B misses A's data) and the candidate
 * channels ranked by how much they would raise it (rcb_plan). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_plan[] =
    "usage: rcbtool plan MODEL.ini MEAS.uff|MEAS.csv --between A[,A...] B[,B...]\n"
    "                    --noise A,S [--size CHI2] [--rpm-list R,...] [--top N]\n"
    "                    [--map NODE=STATION,...] [--rpm R] [--json] [-o FILE]\n"
    "\n"
    "Which test would tell two rival effects apart? A and B (each one or more model\n"
    "parameters, comma-separated) fit the data about equally when their weighted\n"
    "sensitivities on the measured channels are nearly collinear. The measurement\n"
    "gives the layout (channels, references, frequency grid, speed; FRFs at a\n"
    "fixed speed); its values are not used: every figure is linear at the model's\n"
    "values, on the fit's objective (log10 scale, eq. 19 noise-model weights).\n"
    "  --between A B  the rivals: A's parameters make the data, B's are fitted to\n"
    "                 them (also written --between A --and B)\n"
    "  --noise A,S    the eq. 19 noise model (random A %, systematic S %), required:\n"
    "                 it makes the objective a chi-square\n"
    "  --size CHI2    how large A's effect is: the chi-square it moves the objective\n"
    "                 by on the present channels on its own (default 25)\n"
    "  --rpm-list R,. other rotor speeds for the candidates, rpm (the test speed is\n"
    "                 always one)\n"
    "  --top N        candidates printed (default 10)\n"
    "Prints (a) the smallest principal angle (deg) between the rivals' weighted\n"
    "sensitivity subspaces, A's data (its parameters moved along the direction\n"
    "closest to B's, by --size), the best B's fit to them, and the separating\n"
    "chi-square S sin^2(angle) by which that B misses them, with the verdict: below\n"
    "10 (the diagnosis' BIC threshold) \"these data cannot separate them\"; (b) the\n"
    "candidate channels: x and y of every station per an excitation at x or y of\n"
    "every station, at the test speed and each --rpm-list speed (same grid and\n"
    "noise model), ranked by the gain in that chi-square when the channel is added.\n"
    "Units: angle deg; chi-square and gain no unit; rpm; parameter values and\n"
    "changes in the parameter's SI unit (N/m, N s/m, N m/rad, kg, ...).\n"
    "JSON: {\"model\", \"measurement\", \"rpm\", \"params\": [{\"name\", \"side\", \"value\",\n"
    "\"change\"}], \"angle_deg\", \"size\", \"chi2_sep\", \"threshold\", \"separable\",\n"
    "\"verdict\", \"residuals\", \"candidates\": [{\"rank\", \"response\", \"reference\",\n"
    "\"rpm\", \"gain\", \"chi2_after\", \"level_db\"}]}\n"
    "Exit codes: 0 ok, 2 usage, 3 bad input (an unknown parameter, a parameter\n"
    "without effect on the present channels, not FRFs at a fixed speed), 4\n"
    "numerical failure, 5 output error.\n";

typedef struct plan_job {
  const char *meas_path;
  cli_params side[2];
  int have[2];
  double beta_a, beta_s, size;
  double *rpms;
  size_t nrpm, top;
} plan_job;

static int noise_pair(const cli_args *a, double *x, double *y) {
  const char *s = cli_opt_value(a, "--noise"), *t = s ? strchr(s, ',') : NULL;
  char *e1, *e2;
  if (!s) return cli_usage(a->cmd, "option --noise A,S is required (e.g. --noise 10,1)");
  if (t) {
    *x = strtod(s, &e1);
    *y = strtod(t + 1, &e2);
    if (e1 == t && !*e2 && *x >= 0 && *y >= 0 && *x + *y > 0 && isfinite(*x + *y)) return 0;
  }
  return cli_usage(a->cmd, "option --noise expects two numbers >= 0 separated by ',' "
                   "(random %%, systematic %%), e.g. 10,1");
}

static int rpm_list(const cli_args *a, plan_job *j) {
  const char *s = cli_opt_value(a, "--rpm-list");
  size_t n = 1;
  const char *q;
  if (!s) return 0;
  for (q = s; *q; q++) n += *q == ',';
  if (!(j->rpms = calloc(n, sizeof *j->rpms))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (q = s; j->nrpm < n; j->nrpm++) {
    char *e;
    double v = strtod(q, &e);
    if (e == q || (*e && *e != ',') || !(v >= 0) || !isfinite(v))
      return cli_usage(a->cmd, "option --rpm-list expects speeds >= 0 in rpm separated by "
                       "',', e.g. 3000,6000; got '%s'", s);
    j->rpms[j->nrpm] = v;
    q = *e ? e + 1 : e;
  }
  return 0;
}

static int parse_job(const cli_args *a, plan_job *j) {
  int rc, k;
  static const char *const opt[2] = {"--between", "--and"};
  for (k = 0; k < 2; k++) {
    if (!cli_opt_value(a, opt[k]))
      return cli_usage(a->cmd, "option --between A B is required: the rivals' parameters, "
                       "e.g. --between bearing.B4.kyy coupling.C.kr");
    j->have[k] = 1; /* freed even when the parse fails half-way */
    if ((rc = cli_params_parse(a, opt[k], &j->side[k]))) return rc;
  }
  if ((rc = noise_pair(a, &j->beta_a, &j->beta_s)) ||
      (rc = cli_opt_double(a, "--size", "chi-square", 25.0, &j->size)) ||
      (rc = cli_opt_count(a, "--top", 10, &j->top)) || (rc = rpm_list(a, j)))
    return rc;
  if (!(j->size > 0))
    return cli_usage(a->cmd, "option --size %g: expected a chi-square > 0 (e.g. 25)", j->size);
  return 0;
}

/* ---- reporting ---- */

static const char *verdict(const rcb_plan_result *r) {
  return r->separable ? "these data separate them"
                      : "these data cannot separate them";
}

/* Whether a rival's change exceeds 30 % of its (nonzero) value. */
static int large_change(const rcb_plan *p) {
  size_t k;
  for (k = 0; k < rcb_plan_param_count(p); k++) {
    rcb_plan_param q;
    rcb_plan_get_param(p, k, &q);
    if (q.value != 0 && fabs(q.change) > 0.3 * fabs(q.value)) return 1;
  }
  return 0;
}

static void print_params(FILE *fp, const rcb_plan *p, int side) {
  size_t k;
  for (k = 0; k < rcb_plan_param_count(p); k++) {
    rcb_plan_param q;
    rcb_plan_get_param(p, k, &q);
    if (q.side != side) continue;
    fprintf(fp, "  %-28s %12.5g -> %+12.5g", q.name, q.value, q.change);
    if (q.value != 0) fprintf(fp, " (%+.3g %%)", 100.0 * q.change / q.value);
    fputc('\n', fp);
  }
}

static void print_text(FILE *fp, const cli_args *a, const plan_job *j, const rcb_meas *ms,
                       const rcb_plan *p) {
  rcb_plan_result r;
  size_t i;
  rcb_plan_get_result(p, &r);
  fputs("# rcbtool plan: ", fp); /* file names escaped (cli_text.c) */
  cli_put_text(fp, a->model);
  fputs(" vs the layout of ", fp);
  cli_put_text(fp, j->meas_path);
  fprintf(fp, " (%zu channel%s x %zu points, %.6g to %.6g Hz, %.6g rpm)\n",
          rcb_meas_channel_count(ms),
          rcb_meas_channel_count(ms) == 1 ? "" : "s", rcb_meas_point_count(ms),
          rcb_meas_grid(ms)[0] / CLI_HZ_TO_RAD_S,
          rcb_meas_grid(ms)[rcb_meas_point_count(ms) - 1] / CLI_HZ_TO_RAD_S,
          rcb_meas_speed(ms) / CLI_RPM_TO_RAD_S);
  fprintf(fp, "present channels: principal angle %.4g deg between the rivals' weighted "
          "sensitivities (%zu residuals)\n", r.angle_deg, r.residuals);
  fprintf(fp, "A's data, the effect moving the objective by %g on its own (value -> change, "
          "SI units):\n", r.size);
  print_params(fp, p, 0);
  fprintf(fp, "the best B fitted to them:\n");
  print_params(fp, p, 1);
  fprintf(fp, "separating chi-square %.4g (threshold %g): %s\n", r.chi2_sep,
          RCB_PLAN_SEPARATE_CHI2, verdict(&r));
  if (large_change(p))
    fprintf(fp, "note: a change above 30 %% of its value: the figures are linear at the "
            "model's values and extrapolate that far (the ranking stands; a smaller --size "
            "keeps them local)\n");
  fprintf(fp, "\ncandidate channels (same grid and noise model) by gain in the separating "
          "chi-square:\n");
  fprintf(fp, "%-5s %-14s %-14s %9s %12s %12s %9s\n", "rank", "response", "excitation", "rpm",
          "gain", "chi2_after", "level_dB");
  for (i = 0; i < r.candidates && i < j->top; i++) {
    rcb_plan_candidate c;
    rcb_plan_get_candidate(p, i, &c);
    fprintf(fp, "%-5zu %-14s %-14s %9.6g %12.4g %12.4g %9.1f%s\n", i + 1, c.response,
            c.reference, c.speed / CLI_RPM_TO_RAD_S, c.gain, c.chi2_after, c.level_db,
            !r.separable && rcb_evidence_separable(c.chi2_after, 0.0) ? "  separates" : "");
  }
}

static void print_json(FILE *fp, const cli_args *a, const plan_job *j, const rcb_meas *ms,
                       const rcb_plan *p) {
  rcb_plan_result r;
  size_t i;
  rcb_plan_get_result(p, &r);
  fputs("{\"model\": ", fp);
  cli_json_str(fp, a->model);
  fputs(", \"measurement\": ", fp);
  cli_json_str(fp, j->meas_path);
  fputs(", \"rpm\": ", fp);
  cli_json_num(fp, rcb_meas_speed(ms) / CLI_RPM_TO_RAD_S);
  fputs(",\n\"params\": [", fp);
  for (i = 0; i < rcb_plan_param_count(p); i++) {
    rcb_plan_param q;
    rcb_plan_get_param(p, i, &q);
    fputs(i ? ", {\"name\": " : "{\"name\": ", fp);
    cli_json_str(fp, q.name);
    fprintf(fp, ", \"side\": \"%s\", \"value\": ", q.side ? "B" : "A");
    cli_json_num(fp, q.value);
    fputs(", \"change\": ", fp);
    cli_json_num(fp, q.change);
    fputc('}', fp);
  }
  fputs("],\n\"angle_deg\": ", fp);
  cli_json_num(fp, r.angle_deg);
  fputs(", \"size\": ", fp);
  cli_json_num(fp, r.size);
  fputs(", \"chi2_sep\": ", fp);
  cli_json_num(fp, r.chi2_sep);
  fputs(", \"threshold\": ", fp);
  cli_json_num(fp, RCB_PLAN_SEPARATE_CHI2);
  fprintf(fp, ", \"separable\": %s, \"verdict\": \"%s\", \"residuals\": %zu,\n",
          r.separable ? "true" : "false", verdict(&r), r.residuals);
  fputs("\"candidates\": [", fp);
  for (i = 0; i < r.candidates && i < j->top; i++) {
    rcb_plan_candidate c;
    rcb_plan_get_candidate(p, i, &c);
    fprintf(fp, "%s\n {\"rank\": %zu, \"response\": ", i ? "," : "", i + 1);
    cli_json_str(fp, c.response);
    fputs(", \"reference\": ", fp);
    cli_json_str(fp, c.reference);
    fputs(", \"rpm\": ", fp);
    cli_json_num(fp, c.speed / CLI_RPM_TO_RAD_S);
    fputs(", \"gain\": ", fp);
    cli_json_num(fp, c.gain);
    fputs(", \"chi2_after\": ", fp);
    cli_json_num(fp, c.chi2_after);
    fputs(", \"level_db\": ", fp);
    cli_json_num(fp, c.level_db);
    fputc('}', fp);
  }
  fputs("]}\n", fp);
}

/* ---- the job ---- */

static int plan_fail(const cli_args *a, const rcb_plan *p, rcb_status st) {
  int code = st == RCB_ERR_ARG || st == RCB_ERR_NOT_FOUND ? CLI_EXIT_INPUT : cli_status_exit(st);
  return cli_fail(code, "%s: %s", a->cmd, cli_msg(rcb_plan_errmsg(p), st));
}

static int setup(const cli_args *a, const plan_job *j, rcb_plan *p) {
  rcb_status st = RCB_OK;
  size_t k;
  int s;
  for (s = 0; s < 2 && !st; s++)
    for (k = 0; k < j->side[s].n && !st; k++) {
      if (j->side[s].items[k].has_bounds)
        return cli_usage(a->cmd, "--between takes parameter names without bounds, got "
                         "bounds on %s", j->side[s].items[k].name);
      st = rcb_plan_add_param(p, s, j->side[s].items[k].name);
    }
  if (!st) st = rcb_plan_set_noise_model(p, j->beta_a, j->beta_s);
  if (!st) st = rcb_plan_set_size(p, j->size);
  for (k = 0; k < j->nrpm && !st; k++) st = rcb_plan_add_speed(p, j->rpms[k] * CLI_RPM_TO_RAD_S);
  return st ? plan_fail(a, p, st) : 0;
}

static int run(const cli_args *a, plan_job *j) {
  rcb_model *m = NULL;
  rcb_meas *ms = NULL;
  rcb_plan *p = NULL;
  rcb_status st;
  cli_out o;
  int rc;
  if ((rc = cli_load_model(a, &m))) return rc;
  if ((rc = cli_meas_read(a, j->meas_path, m, &ms))) goto done;
  if ((st = rcb_plan_create(&p, m, ms, NULL))) {
    rc = p ? plan_fail(a, p, st) : cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    goto done;
  }
  if ((rc = setup(a, j, p))) goto done;
  if ((st = rcb_plan_run(p))) {
    rc = plan_fail(a, p, st);
    goto done;
  }
  if ((rc = cli_out_open(&o, a))) goto done;
  (a->json ? print_json : print_text)(o.fp, a, j, ms, p);
  rc = cli_out_close(&o);
done:
  rcb_plan_destroy(p);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  return rc;
}

/* "--between A B" -> "--between A --and B": the option parser takes one value
 * per option. NULL when out of memory. */
static char **split_between(int argc, char **argv, int *out_argc) {
  char **v = malloc(((size_t)argc + 2) * sizeof *v);
  int i, n = 0, done = 0;
  static char and_opt[] = "--and";
  if (!v) return NULL;
  for (i = 0; i < argc; i++) {
    v[n++] = argv[i];
    if (!done && strcmp(argv[i], "--") == 0) done = 1;
    if (!done && strcmp(argv[i], "--between") == 0 && i + 2 < argc && argv[i + 1][0] != '-' &&
        argv[i + 2][0] != '-') {
      v[n++] = argv[++i];
      v[n++] = and_opt;
      done = 1;
    }
  }
  v[n] = NULL;
  *out_argc = n;
  return v;
}

int cmd_plan(int argc, char **argv) {
  cli_opt opts[] = {{"--between", "A[,A...] B[,B...]", NULL},
                    {"--and", "B[,B...]", NULL},
                    {"--noise", "BETA_A,BETA_S", NULL},
                    {"--size", "CHI2", NULL},
                    {"--rpm-list", "R,...", NULL},
                    {"--top", "N", NULL},
                    {"--map", "NODE=STATION,...", NULL},
                    {"--rpm", "R", NULL}};
  size_t nopts = sizeof opts / sizeof opts[0];
  plan_job j;
  cli_args a;
  char **args = NULL, **v;
  int rc, n = 0, k;
  memset(&j, 0, sizeof j);
  if (!(v = split_between(argc, argv, &n))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  if (!(rc = cli_parse_meas_cmd(n, v, opts, nopts, cli_help_plan,
                                "'rcbtool plan MODEL.ini MEAS.uff|MEAS.csv'", &a, &j.meas_path,
                                &args)) &&
      !(rc = parse_job(&a, &j)))
    rc = run(&a, &j);
  for (k = 0; k < 2; k++)
    if (j.have[k]) cli_params_free(&j.side[k]);
  free(j.rpms);
  free(args);
  free(v);
  return rc < 0 ? CLI_EXIT_OK : rc;
}
