/* rcbtool sensitivity: which measurement channels are most sensitive to the
 * parameters to be fitted (the paper's Figs. 7 and 11). A noise-free
 * simulated measurement of every candidate channel goes through the fitter's
 * sensitivity (rcb_fit_channel_sensitivity); channels are ranked by a score
 * that rewards being sensitive to every parameter. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_sensitivity[] =
    "usage: rcbtool sensitivity MODEL.ini --params NAME,... --frf --in CH --fmax HZ\n"
    "                           [--fmin HZ] [--points N] [--rpm R] [--kind K]\n"
    "                           [--candidates all|CH,...] [--top N]\n"
    "                           [--scale linear|log10|db|complex] [--json] [-o FILE]\n"
    "       rcbtool sensitivity MODEL.ini --params NAME,... --unbalance --rpm-max B\n"
    "                           [--rpm-min A] [--points N] [options as above]\n"
    "\n"
    "Simulates, without noise, what every candidate channel would measure (an FRF\n"
    "with the force at --in, or the unbalance response), and ranks the channels by\n"
    "their sensitivity to the parameters: the paper's sensitivity analysis that\n"
    "picks the channels to measure before a fit (Figs. 7 and 11).\n"
    "  --params LIST  parameters by name, as for rcbtool fit (bounds are ignored)\n"
    "  --frf          FRFs at f_i = fmin + i (fmax - fmin)/(N - 1) Hz, rotor speed\n"
    "                 --rpm (default 0), force at --in CH (one channel)\n"
    "  --unbalance    unbalance responses at A + i (B - A)/(N - 1) rpm\n"
    "  --fmin, --fmax, --points (default 200), --rpm, --kind (default receptance),\n"
    "  --rpm-min (default 0), --rpm-max: as for rcbtool simulate\n"
    "  --candidates   all (default: x and y at every named station and at every\n"
    "                 node \"#N\"; each DOF once, under its first name) or a list\n"
    "                 STATION.DIR,...\n"
    "  --top N        print only the best N channels, and a ready-to-paste --out list\n"
    "  --scale S      scale of the sensitivities, as rcbtool fit --scale (default\n"
    "                 linear, on |H| as in the paper: large responses rank above\n"
    "                 small ones that a test's noise would swamp; log10 gives the\n"
    "                 relative change, which favours weak channels)\n"
    "\n"
    "Sensitivity of channel c to parameter k: RMS over the points of\n"
    "p_k d s(H_c)/d p_k, the change of s(H) on the scale for a 100 % change of p_k\n"
    "(analytic, eq. 9). Score: geometric mean over the parameters of the channel's\n"
    "sensitivity divided by the best channel's for that parameter (1 = the best\n"
    "channel for every parameter; a parameter no channel responds to is left out).\n"
    "JSON: {\"params\": [...], \"scale\", \"input\", \"channels\": [{\"rank\",\n"
    "\"channel\", \"node\", \"score\", \"sensitivity\": [per parameter]}], \"out\"}\n"
    "Exit codes: 2 usage, 3 bad model or parameter name, 4 numerical failure,\n"
    "5 output not written.\n";

static const char *const scale_names[] = {"linear", "log10", "db", "complex"};
static const char *const dir_names[] = {"x", "y"};

typedef struct sens_job {
  int frf, kind, scale;
  double lo, hi, rpm; /* grid in Hz or rpm; rotor speed of the FRF test, rpm */
  size_t npts, top;
  cli_params params;
  cli_channels in;
} sens_job;

/* Candidate channels: names owned here, each DOF once. */
typedef struct cand_list {
  char **names;
  rcb_dof *dofs;
  size_t *rows; /* matrix row, for telling duplicates apart */
  size_t n, cap;
} cand_list;

static void cand_free(cand_list *cl) {
  size_t i;
  for (i = 0; i < cl->n; i++) free(cl->names[i]);
  free(cl->names);
  free(cl->dofs);
  free(cl->rows);
  memset(cl, 0, sizeof *cl);
}

static int cand_grow(cand_list *cl) {
  size_t cap = cl->cap ? 2 * cl->cap : 64;
  char **nn = realloc(cl->names, cap * sizeof *nn);
  rcb_dof *nd;
  size_t *nr;
  if (!nn) return -1;
  cl->names = nn;
  if (!(nd = realloc(cl->dofs, cap * sizeof *nd))) return -1;
  cl->dofs = nd;
  if (!(nr = realloc(cl->rows, cap * sizeof *nr))) return -1;
  cl->rows = nr;
  cl->cap = cap;
  return 0;
}

/* Add channel @p name unless its DOF is already a candidate (dedup != 0). */
static int cand_add(cand_list *cl, const rcb_model *m, const char *name, int dedup) {
  rcb_dof d;
  size_t row, i;
  if (rcb_model_find_dof(m, name, &d) || rcb_model_dof_index(m, d, &row))
    return cli_fail(CLI_EXIT_INPUT, "sensitivity: channel '%s': %s", name,
                    cli_msg(rcb_model_errmsg(m), RCB_ERR_NOT_FOUND));
  if (dedup)
    for (i = 0; i < cl->n; i++)
      if (cl->rows[i] == row) return 0;
  if (cl->n == cl->cap && cand_grow(cl)) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  cl->names[cl->n] = malloc(strlen(name) + 1);
  if (!cl->names[cl->n]) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(cl->names[cl->n], name);
  cl->dofs[cl->n] = d;
  cl->rows[cl->n] = row;
  cl->n++;
  return 0;
}

/* "all": x and y of every named station, then of every node. */
static int cand_all(cand_list *cl, const rcb_model *m) {
  char name[256];
  size_t i, d;
  int rc;
  for (i = 0; i < rcb_model_station_count(m); i++) {
    rcb_station_info si;
    if (rcb_model_station_info(m, i, &si)) continue;
    for (d = 0; d < 2; d++) {
      snprintf(name, sizeof name, "%s.%s", si.name, dir_names[d]);
      if ((rc = cand_add(cl, m, name, 1))) return rc;
    }
  }
  for (i = 0; i < rcb_model_node_count(m); i++)
    for (d = 0; d < 2; d++) {
      snprintf(name, sizeof name, "#%zu.%s", i, dir_names[d]);
      if ((rc = cand_add(cl, m, name, 1))) return rc;
    }
  return 0;
}

static int cand_parse(const cli_args *a, const rcb_model *m, cand_list *cl) {
  const char *s = cli_opt_value(a, "--candidates");
  cli_channels ch;
  size_t i;
  int rc;
  memset(cl, 0, sizeof *cl);
  if (!s || strcmp(s, "all") == 0) return cand_all(cl, m);
  if ((rc = cli_channels_parse(a, (rcb_model *)m, "--candidates", &ch))) {
    cli_channels_free(&ch);
    return rc;
  }
  for (i = 0; i < ch.n && !rc; i++) rc = cand_add(cl, m, ch.names[i], 0);
  cli_channels_free(&ch);
  return rc;
}

/* ---- options ---- */

static int parse_frf(const cli_args *a, sens_job *j) {
  return cli_sweep_frf(a, "the force channel STATION.DIR of the FRFs", &j->lo, &j->hi, &j->rpm,
                       &j->kind);
}

static int parse_unbalance(const cli_args *a, sens_job *j) {
  j->kind = RCB_RECEPTANCE;
  return cli_sweep_unbalance(a,
                             "--in, --fmin, --fmax, --rpm and --kind belong to --frf; "
                             "--unbalance takes --rpm-min, --rpm-max, --points",
                             &j->lo, &j->hi);
}

static int parse_job(const cli_args *a, sens_job *j) {
  int rc, frf = cli_opt_value(a, "--frf") != NULL, unb = cli_opt_value(a, "--unbalance") != NULL;
  size_t top = 0;
  if (frf == unb)
    return cli_usage(a->cmd, "give exactly one of --frf (FRFs at a rotor speed) and "
                     "--unbalance (unbalance response over a speed range)");
  j->frf = frf;
  if ((rc = (frf ? parse_frf : parse_unbalance)(a, j)) ||
      (rc = cli_opt_count(a, "--points", 200, &j->npts)) ||
      (rc = cli_opt_count(a, "--top", 1, &top)) ||
      (rc = cli_opt_choice(a, "--scale", scale_names, 4, RCB_SCALE_LINEAR, &j->scale)))
    return rc;
  j->top = cli_opt_value(a, "--top") ? top : 0;
  if (j->lo > j->hi || (j->npts > 1 && j->lo == j->hi))
    return cli_usage(a->cmd, "%s %g is not below %s %g; expected an increasing range",
                     frf ? "--fmin" : "--rpm-min", j->lo, frf ? "--fmax" : "--rpm-max", j->hi);
  return cli_params_parse(a, "--params", &j->params);
}

/* ---- the noise-free measurement of every candidate ---- */

static int sweep(const cli_args *a, const sens_job *j, rcb_frf *fr, const double *x,
                 size_t nch, rcb_complex *H, rcb_complex *data) {
  cli_progress pr;
  size_t p, c;
  cli_progress_start(&pr, a, "sensitivity", j->frf ? "frequencies" : "speeds", j->npts);
  for (p = 0; p < j->npts; p++) {
    rcb_status st = j->frf ? rcb_frf_eval(fr, x[p], j->rpm * CLI_RPM_TO_RAD_S,
                                          (rcb_frf_kind)j->kind, H)
                           : rcb_frf_unbalance(fr, x[p], H);
    if (st) {
      cli_progress_end(&pr);
      return cli_fail(cli_status_exit(st), "sensitivity: simulating point %zu: %s", p + 1,
                      cli_msg(rcb_frf_errmsg(fr), st));
    }
    for (c = 0; c < nch; c++) data[c * j->npts + p] = H[c]; /* nch x 1 */
    cli_progress_step(&pr, p + 1);
  }
  cli_progress_end(&pr);
  return 0;
}

static int fill_meas(const sens_job *j, const cand_list *cl, const double *x,
                     const rcb_complex *data, rcb_meas *ms) {
  size_t c;
  rcb_status st = rcb_meas_set_grid(ms, j->frf ? RCB_MEAS_FRF : RCB_MEAS_UNBALANCE, j->npts,
                                    x, j->rpm * CLI_RPM_TO_RAD_S);
  for (c = 0; c < cl->n && !st; c++)
    st = rcb_meas_add_channel(ms, cl->names[c], j->frf ? j->in.names[0] : NULL,
                              (rcb_frf_kind)j->kind, data + c * j->npts);
  if (st)
    return cli_fail(cli_status_exit(st), "sensitivity: %s", cli_msg(rcb_meas_errmsg(ms), st));
  return 0;
}

static int simulate(const cli_args *a, const sens_job *j, const rcb_model *m,
                    const cand_list *cl, rcb_meas *ms) {
  rcb_frf *fr = NULL;
  /* at least one item each: malloc(0) may return NULL, read as out of memory */
  size_t nc = cl->n ? cl->n : 1, npts = j->npts ? j->npts : 1;
  double *x = malloc(npts * sizeof *x);
  rcb_complex *H = malloc(nc * sizeof *H), *data = malloc(nc * npts * sizeof *data);
  size_t p;
  int rc;
  rcb_status st;
  if (!x || !H || !data) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    goto done;
  }
  cli_linspace(j->lo, j->hi, j->npts, x);
  for (p = 0; p < j->npts; p++) x[p] *= j->frf ? CLI_HZ_TO_RAD_S : CLI_RPM_TO_RAD_S;
  st = rcb_frf_create(&fr, m, cl->n, cl->dofs, j->frf ? 1 : 0, j->frf ? j->in.dofs : NULL,
                      RCB_SOLVER_AUTO, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "sensitivity: %s",
                  cli_msg(fr ? rcb_frf_errmsg(fr) : rcb_model_errmsg(m), st));
    goto done;
  }
  if (!(rc = sweep(a, j, fr, x, cl->n, H, data))) rc = fill_meas(j, cl, x, data, ms);
done:
  rcb_frf_destroy(fr);
  free(x);
  free(H);
  free(data);
  return rc;
}

/* ---- ranking ---- */

typedef struct ranked {
  double score;
  size_t c;
} ranked;

static int by_score(const void *pa, const void *pb) {
  const ranked *ra = pa, *rb = pb;
  if (ra->score != rb->score) return ra->score < rb->score ? 1 : -1;
  return ra->c < rb->c ? -1 : ra->c > rb->c; /* stable: candidate order */
}

/* Geometric mean over the parameters of S[c, k] / max_c S[c, k]. */
static void rank_channels(const double *S, size_t nch, size_t np, ranked *rk) {
  size_t c, k;
  for (c = 0; c < nch; c++) {
    double sum = 0.0;
    size_t used = 0;
    int zero = 0;
    for (k = 0; k < np; k++) {
      double best = 0.0;
      size_t q;
      for (q = 0; q < nch; q++)
        if (S[q + nch * k] > best) best = S[q + nch * k];
      if (!(best > 0) || !isfinite(best)) continue; /* no channel responds to it */
      used++;
      if (!(S[c + nch * k] > 0)) zero = 1;
      else sum += log(S[c + nch * k] / best);
    }
    rk[c].c = c;
    rk[c].score = zero || used == 0 ? 0.0 : exp(sum / (double)used);
  }
  qsort(rk, nch, sizeof *rk, by_score);
}

/* ---- output ---- */

static void write_text(FILE *fp, const sens_job *j, const cand_list *cl, const double *S,
                       const ranked *rk, size_t nshow) {
  size_t r, k, nch = cl->n, np = j->params.n;
  fprintf(fp, "# sensitivity: RMS over %zu points of the change of %s|H| for a 100 %% change "
          "of each parameter; score: geometric mean of sensitivity / best channel's\n",
          j->npts, j->scale == RCB_SCALE_LOG10 ? "log10 " : j->scale == RCB_SCALE_DB ? "dB "
                   : j->scale == RCB_SCALE_COMPLEX ? "Re/Im " : "");
  fprintf(fp, "%-5s %-12s %-5s %-10s", "rank", "channel", "node", "score");
  for (k = 0; k < np; k++) fprintf(fp, " %-16s", j->params.items[k].name);
  fputc('\n', fp);
  for (r = 0; r < nshow; r++) {
    size_t c = rk[r].c;
    fprintf(fp, "%-5zu %-12s %-5zu %-10.4f", r + 1, cl->names[c], cl->dofs[c].node,
            rk[r].score);
    for (k = 0; k < np; k++) fprintf(fp, " %-16.4g", S[c + nch * k]);
    fputc('\n', fp);
  }
  if (j->top) {
    fputs("--out ", fp);
    for (r = 0; r < nshow; r++) fprintf(fp, "%s%s", r ? "," : "", cl->names[rk[r].c]);
    fputc('\n', fp);
  }
}

static void write_json(FILE *fp, const sens_job *j, const cand_list *cl, const double *S,
                       const ranked *rk, size_t nshow) {
  size_t r, k, nch = cl->n, np = j->params.n;
  fputs("{\"params\": [", fp);
  for (k = 0; k < np; k++) {
    fputs(k ? ", " : "", fp);
    cli_json_str(fp, j->params.items[k].name);
  }
  fprintf(fp, "], \"scale\": \"%s\", \"type\": \"%s\", \"input\": ", scale_names[j->scale],
          j->frf ? "frf" : "unbalance");
  if (j->frf)
    cli_json_str(fp, j->in.names[0]);
  else
    fputs("null", fp);
  fprintf(fp, ", \"points\": %zu,\n\"channels\": [", j->npts);
  for (r = 0; r < nshow; r++) {
    size_t c = rk[r].c;
    fprintf(fp, "%s{\"rank\": %zu, \"channel\": ", r ? ",\n  " : "\n  ", r + 1);
    cli_json_str(fp, cl->names[c]);
    fprintf(fp, ", \"node\": %zu, \"score\": ", cl->dofs[c].node);
    cli_json_num(fp, rk[r].score);
    fputs(", \"sensitivity\": ", fp);
    cli_json_nums(fp, S + c, np, nch);
    fputc('}', fp);
  }
  fputs("],\n\"out\": \"", fp);
  for (r = 0; r < nshow; r++) fprintf(fp, "%s%s", r ? "," : "", cl->names[rk[r].c]);
  fputs("\"}\n", fp);
}

static int output(const cli_args *a, const sens_job *j, const cand_list *cl, const double *S) {
  ranked *rk = malloc((cl->n ? cl->n : 1) * sizeof *rk);
  size_t nshow = j->top && j->top < cl->n ? j->top : cl->n;
  cli_out o;
  int rc;
  if (!rk) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  rank_channels(S, cl->n, j->params.n, rk);
  if (!(rc = cli_out_open(&o, a))) {
    (a->json ? write_json : write_text)(o.fp, j, cl, S, rk, nshow);
    rc = cli_out_close(&o);
  }
  free(rk);
  return rc;
}

/* ---- run ---- */

static int sensitivities(const cli_args *a, const sens_job *j, rcb_model *m,
                         const cand_list *cl, const rcb_meas *ms) {
  rcb_fit *f = NULL;
  /* calloc of at least one: the analyzer cannot see rcb_fit fill S */
  double *S = calloc(cl->n && j->params.n ? cl->n * j->params.n : 1, sizeof *S);
  int rc = 0;
  rcb_status st;
  size_t k;
  for (k = 0; k < j->params.n; k++) /* fit and diagnose take them; a placement does not */
    if (rcb_fit_sensor_param_defaults(j->params.items[k].name, NULL, NULL, NULL, NULL)) {
      free(S);
      return cli_usage(a->cmd, "parameter %s belongs to the measurement chain, not to the "
                       "model: it says nothing about where to measure; give model parameters",
                       j->params.items[k].name);
    }
  st = S ? rcb_fit_create(&f, m, ms, NULL) : RCB_ERR_NOMEM;
  if (st) {
    rc = cli_fail(cli_status_exit(st), "sensitivity: %s", cli_msg(f ? rcb_fit_errmsg(f) : NULL,
                                                                  st));
  } else if (!(rc = cli_params_add(a, f, m, &j->params, 0, 1))) {
    st = rcb_fit_set_scale(f, (rcb_fit_scale)j->scale);
    if (!st) st = rcb_fit_channel_sensitivity(f, S);
    if (st)
      rc = cli_fail(st == RCB_ERR_ARG ? CLI_EXIT_USAGE : cli_status_exit(st),
                    "sensitivity: %s", cli_msg(rcb_fit_errmsg(f), st));
    else
      rc = output(a, j, cl, S);
  }
  rcb_fit_destroy(f);
  free(S);
  return rc;
}

static int run(const cli_args *a, sens_job *j, rcb_model *m) {
  cand_list cl;
  rcb_meas *ms = NULL;
  int rc;
  if (j->frf) {
    if ((rc = cli_channels_parse(a, m, "--in", &j->in))) return rc;
    if (j->in.n != 1)
      return cli_usage(a->cmd, "option --in takes one force channel, got %zu", j->in.n);
  }
  if ((rc = cand_parse(a, m, &cl))) {
    cand_free(&cl);
    return rc;
  }
  if (rcb_meas_create(&ms, NULL))
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  else if (!(rc = simulate(a, j, m, &cl, ms)))
    rc = sensitivities(a, j, m, &cl, ms);
  rcb_meas_destroy(ms);
  cand_free(&cl);
  return rc;
}

int cmd_sensitivity(int argc, char **argv) {
  cli_opt opts[] = {{"--params", "NAME,...", NULL},   {"--frf", NULL, NULL},
                    {"--unbalance", NULL, NULL},      {"--in", "CH", NULL},
                    {"--fmin", "HZ", NULL},           {"--fmax", "HZ", NULL},
                    {"--points", "N", NULL},          {"--rpm", "R", NULL},
                    {"--kind", "KIND", NULL},         {"--rpm-min", "A", NULL},
                    {"--rpm-max", "B", NULL},         {"--candidates", "all|CH,...", NULL},
                    {"--top", "N", NULL},             {"--scale", "SCALE", NULL}};
  sens_job j;
  cli_args a;
  rcb_model *m = NULL;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_sensitivity);
  memset(&j, 0, sizeof j);
  if (!(rc = parse_job(&a, &j)) && !(rc = cli_load_model(&a, &m))) rc = run(&a, &j, m);
  cli_params_free(&j.params);
  cli_channels_free(&j.in);
  rcb_model_destroy(m);
  return rc;
}
