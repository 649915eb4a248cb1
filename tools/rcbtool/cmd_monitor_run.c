/* rcbtool monitor: commissioning, the updates and the lines printed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cmd_monitor.h"

/* The file name without its directories (for the lines). */
static const char *base_name(const char *path) {
  const char *s = strrchr(path, '/');
  return s ? s + 1 : path;
}

static int same_x(double x, double y) { return fabs(x - y) <= 1e-6 * fabs(y) + 1e-12; }

/* The set-up's layout in @p ms (file @p path): the same type, points, speed
 * and channels (in any order: perm[c] is the channel of ms holding the
 * set-up's channel c). 0 or exit 3 naming the file. */
static int match_layout(const char *cmd, const rcb_meas *ref, const char *ref_path,
                        const rcb_meas *ms, const char *path, size_t *perm) {
  size_t n = rcb_meas_point_count(ref), nc = rcb_meas_channel_count(ref), c, q, i;
  int frf = rcb_meas_get_type(ref) == RCB_MEAS_FRF;
  const double *x = rcb_meas_grid(ref), *y = rcb_meas_grid(ms);
  double unit = frf ? CLI_HZ_TO_RAD_S : CLI_RPM_TO_RAD_S;
  static const char fix[] = "every file of a series must have the commissioning file's "
                            "channels, points and speed";
  if (rcb_meas_get_type(ms) != rcb_meas_get_type(ref))
    return cli_fail(CLI_EXIT_INPUT, "%s: '%s' holds %s, the commissioning file '%s' %s; %s",
                    cmd, path, frf ? "unbalance responses" : "FRFs", ref_path,
                    frf ? "FRFs" : "unbalance responses", fix);
  if (rcb_meas_point_count(ms) != n || rcb_meas_channel_count(ms) != nc)
    return cli_fail(CLI_EXIT_INPUT, "%s: '%s' has %zu channels x %zu points, the "
                    "commissioning file '%s' %zu x %zu; %s", cmd, path,
                    rcb_meas_channel_count(ms), rcb_meas_point_count(ms), ref_path, nc, n, fix);
  for (i = 0; i < n; i++)
    if (!same_x(y[i], x[i]))
      return cli_fail(CLI_EXIT_INPUT, "%s: '%s': point %zu is at %.9g %s, in the commissioning "
                      "file '%s' at %.9g; %s", cmd, path, i + 1, y[i] / unit, frf ? "Hz" : "rpm",
                      ref_path, x[i] / unit, fix);
  if (frf && !same_x(rcb_meas_speed(ms), rcb_meas_speed(ref)))
    return cli_fail(CLI_EXIT_INPUT, "%s: '%s' was measured at %.6g rpm, the commissioning "
                    "file '%s' at %.6g rpm; %s", cmd, path, rcb_meas_speed(ms) / CLI_RPM_TO_RAD_S,
                    ref_path, rcb_meas_speed(ref) / CLI_RPM_TO_RAD_S, fix);
  for (c = 0; c < nc; c++) {
    rcb_meas_channel_info ri, mi;
    rcb_meas_channel(ref, c, &ri);
    for (q = 0; q < nc; q++) {
      rcb_meas_channel(ms, q, &mi);
      if (strcmp(mi.response, ri.response) == 0 &&
          (ri.reference ? mi.reference && strcmp(mi.reference, ri.reference) == 0
                        : !mi.reference))
        break;
    }
    if (q == nc || mi.kind != ri.kind)
      return cli_fail(CLI_EXIT_INPUT, "%s: '%s' has no channel %s%s%s%s (of the commissioning "
                      "file '%s'); %s", cmd, path, ri.response, ri.reference ? "/" : "",
                      ri.reference ? ri.reference : "", q == nc ? "" : " of the same kind",
                      ref_path, fix);
    perm[c] = q;
  }
  return 0;
}

/* values[c * n + i] (the set-up's order) from ms. */
static void gather(const rcb_meas *ms, const size_t *perm, size_t nc, size_t n,
                   rcb_complex *values) {
  size_t c;
  for (c = 0; c < nc; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(ms, perm[c], &ci);
    memcpy(values + c * n, ci.data, n * sizeof *values);
  }
}

/* --sd DIR: DIR/STEM_stats.csv of measurement DIR2/STEM.ext. */
static char *sd_file_for(const char *dir, const char *meas) {
  const char *b = base_name(meas), *dot = strrchr(b, '.');
  size_t stem = dot ? (size_t)(dot - b) : strlen(b);
  char *p = malloc(strlen(dir) + stem + sizeof "/_stats.csv");
  if (!p) return NULL;
  sprintf(p, "%s/%.*s_stats.csv", dir, (int)stem, b);
  return p;
}

static int sd_is_dir(const char *path) {
  struct stat st;
  return path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

typedef struct mon_ctx {
  const cli_args *a;
  const mon_job *j;
  rcb_model *m;
  rcb_meas *setup; /* the first commissioning file, its values the average */
  rcb_meas *avg;   /* with --commission N > 1: the set-up holding the average */
  uint64_t *hash;  /* --state: the new files' content hashes */
  void *image;     /* --state: the commissioning image read */
  int new_image;   /* --state: write the image (none, or not this monitor's) */
  size_t n, nc, *perm;
  rcb_complex *values;
  rcb_complex *reps; /* with the scale measured: the N commissioning files'
                        values, N x nc x n (rcb_monitor_noise_scale) */
  double *sd;
  int have_sd;
  double noise_scale; /* the scale passed to the monitor (-) */
  rcb_monitor_noise scatter;
  int scale_from;    /* MON_SCALE_* */
  char scale_opt[80]; /* "--noise-scale=scatter:CHI2:DOF" kept in a new state ("": none) */
} mon_ctx;

/* --sd DIR: the sds of file @p path (read as @p ms, the set-up's layout) into
 * x->sd in the set-up's order; *have 0 without --sd DIR. 0 or an exit code. */
static int file_sd(mon_ctx *x, const rcb_meas *ms, const char *path, int *have) {
  size_t c;
  double *sd = NULL;
  char *f;
  int rc;
  *have = 0;
  if (!sd_is_dir(x->j->sd_path)) return 0;
  if (!(f = sd_file_for(x->j->sd_path, path)))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  rc = cli_sd_read(f, ms, &sd); /* ms has x->nc channels of x->n points (matched) */
  free(f);
  if (rc) return rc;
  for (c = 0; c < x->nc; c++)
    memcpy(x->sd + c * x->n, sd + x->perm[c] * x->n, x->n * sizeof *x->sd);
  free(sd);
  *have = 1;
  return 0;
}

static int read_file(mon_ctx *x, size_t k, rcb_meas **out) {
  const char *path = x->j->series.files[k];
  int rc = cli_meas_read(x->a, path, x->m, out);
  if (rc) return rc;
  if ((rc = cli_meas_need_phase(x->a, *out, path, "the monitor (it fits on the complex "
                                "scale)"))) {
    rcb_meas_destroy(*out);
    *out = NULL;
    return rc;
  }
  if (k > 0 &&
      (rc = match_layout(x->a->cmd, x->setup, x->j->series.files[0], *out, path, x->perm))) {
    rcb_meas_destroy(*out);
    *out = NULL;
  }
  return rc;
}

/* --state: the set-up the monitor was created from, kept in the state (the
 * commissioning files need not be here any more). */
static int restored_setup(mon_ctx *x) {
  mon_saved *sv = x->j->saved;
  x->setup = sv->setup;
  sv->setup = NULL;
  return 0;
}

/* The first --commission files: their average into the set-up's values. */
static int commission(mon_ctx *x) {
  size_t k, i, nv;
  rcb_meas *ms = NULL;
  int rc, saved = x->j->saved != NULL;
  if ((rc = saved ? restored_setup(x) : read_file(x, 0, &x->setup))) return rc;
  x->n = rcb_meas_point_count(x->setup);
  x->nc = rcb_meas_channel_count(x->setup);
  nv = x->n * x->nc;
  x->perm = calloc(x->nc ? x->nc : 1, sizeof *x->perm);
  x->values = calloc(nv ? nv : 1, sizeof *x->values);
  x->sd = calloc(nv ? nv : 1, sizeof *x->sd);
  if (!x->perm || !x->values || !x->sd) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (k = 0; k < x->nc; k++) x->perm[k] = k;
  if (x->j->sd_path && !sd_is_dir(x->j->sd_path)) { /* one file for every update */
    double *sd;
    if ((rc = cli_sd_read(x->j->sd_path, x->setup, &sd))) return rc;
    memcpy(x->sd, sd, nv * sizeof *sd);
    free(sd);
    x->have_sd = 1;
  } else if ((rc = file_sd(x, x->setup, x->j->series.files[0], &x->have_sd))) {
    return rc;
  }
  if (x->j->commission == 1) return 0;
  gather(x->setup, x->perm, x->nc, x->n, x->values);
  if (saved) return 0; /* the average itself */
  if (!x->j->noise_scale && !(x->j->scatter[1] > 0) && !sd_is_dir(x->j->sd_path)) { /* measured */
    if (!nv || nv > (size_t)-1 / sizeof *x->reps / x->j->commission ||
        !(x->reps = malloc(x->j->commission * nv * sizeof *x->reps)))
      return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    memcpy(x->reps, x->values, nv * sizeof *x->reps);
  }
  for (k = 1; k < x->j->commission; k++) {
    rcb_complex *v = x->values;
    if ((rc = read_file(x, k, &ms))) return rc;
    for (i = 0; i < x->nc; i++) {
      rcb_meas_channel_info ci;
      size_t p;
      rcb_meas_channel(ms, x->perm[i], &ci);
      for (p = 0; p < x->n; p++) v[i * x->n + p] += ci.data[p];
      if (x->reps) memcpy(x->reps + (k * x->nc + i) * x->n, ci.data, x->n * sizeof *x->reps);
    }
    rcb_meas_destroy(ms);
  }
  for (i = 0; i < nv; i++) x->values[i] /= (double)x->j->commission;
  return 0;
}

/* A set-up holding the averaged values: the first file's grid and channels. */
static int averaged_setup(mon_ctx *x, rcb_meas **out) {
  rcb_meas *ms = NULL;
  size_t c;
  rcb_status st = rcb_meas_create(&ms, NULL);
  if (!st)
    st = rcb_meas_set_grid(ms, rcb_meas_get_type(x->setup), x->n, rcb_meas_grid(x->setup),
                           rcb_meas_speed(x->setup));
  for (c = 0; c < x->nc && !st; c++) {
    rcb_meas_channel_info ci;
    rcb_meas_channel(x->setup, c, &ci);
    st = rcb_meas_add_channel(ms, ci.response, ci.reference, ci.kind, x->values + c * x->n);
  }
  if (st) {
    int rc = cli_fail(CLI_EXIT_NUMERIC, "%s: averaging the commissioning files: %s", x->a->cmd,
                      cli_msg(ms ? rcb_meas_errmsg(ms) : NULL, st));
    rcb_meas_destroy(ms);
    return rc;
  }
  *out = ms;
  return 0;
}

/* The noise's scale (--noise-scale): given, measured on the commissioning
 * files' scatter, or that measurement kept in the state; into x and o. 0 or
 * an exit code. */
static int noise_scale(mon_ctx *x, rcb_monitor_opts *o) {
  rcb_status st;
  x->noise_scale = 1.0;
  if (x->j->noise_scale > 0) {
    x->noise_scale = x->j->noise_scale, x->scale_from = MON_SCALE_GIVEN;
  } else if (sd_is_dir(x->j->sd_path)) {
    x->scale_from = MON_SCALE_SD_DIR;
  } else if (x->j->scatter[1] > 0 || x->reps) {
    if (x->j->scatter[1] > 0) { /* kept in the state: the same figures again */
      x->scatter.chi2 = x->j->scatter[0], x->scatter.dof = x->j->scatter[1];
      x->scatter.scale = sqrt(x->scatter.chi2 / x->scatter.dof);
    } else if ((st = rcb_monitor_noise_scale(x->avg, x->reps, x->j->commission, o,
                                             &x->scatter))) {
      return cli_fail(CLI_EXIT_INPUT, "%s: --noise-scale auto: the scatter of the %zu "
                      "commissioning files could not be measured against the declared noise "
                      "(%s): give --noise-scale 1 or a noise model that is not zero anywhere",
                      x->a->cmd, x->j->commission, cli_msg(NULL, st));
    }
    if (x->scatter.scale < MON_SCALE_MIN) {
      x->scale_from = MON_SCALE_TOO_LOW;
      cli_warn("%s: the %zu commissioning files scatter %.3g x the declared noise: repeated or "
               "noise-free files say nothing of the updates' noise, so the noise is taken as "
               "declared (--noise-scale S sets it)", x->a->cmd, x->j->commission,
               x->scatter.scale);
    } else {
      x->noise_scale = x->scatter.scale, x->scale_from = MON_SCALE_MEASURED;
    }
    /* a new state keeps the measurement as a setting: a resumed run applies
     * and reports it as this one */
    snprintf(x->scale_opt, sizeof x->scale_opt, "--noise-scale=scatter:%.17g:%.17g",
             x->scatter.chi2, x->scatter.dof);
  } else {
    x->scale_from = MON_SCALE_ONE_FILE;
  }
  o->noise_scale = x->noise_scale;
  return 0;
}

static int create_monitor(mon_ctx *x, rcb_monitor **mon) {
  rcb_monitor_param tp[RCB_MONITOR_MAX_TRACKED];
  double cov[RCB_MONITOR_MAX_TRACKED * RCB_MONITOR_MAX_TRACKED];
  rcb_monitor_opts o;
  rcb_meas *avg = NULL;
  rcb_status st = RCB_OK;
  size_t k;
  int rc;
  memset(&o, 0, sizeof o);
  for (k = 0; k < x->j->params.n; k++) {
    const cli_param_spec *p = &x->j->params.items[k];
    double v;
    if (rcb_model_get_param(x->m, p->name, &v))
      return cli_fail(CLI_EXIT_INPUT, "%s: %s", x->a->cmd, rcb_model_errmsg(x->m));
    tp[k].name = p->name;
    if ((rc = cli_param_bounds(x->a, p, v, 0, &tp[k].lo, &tp[k].hi))) return rc;
  }
  o.ntracked = x->j->params.n;
  o.tracked = tp;
  o.alpha = x->j->alpha;
  o.cusum_h = x->j->cusum_h;
  o.cusum_k = x->j->cusum_k;
  o.beta_a = x->j->beta_a;
  o.beta_s = x->j->beta_s;
  o.phase_deg = x->j->phase_deg;
  o.sd = x->have_sd ? x->sd : NULL;
  o.setup_averages = (double)x->j->commission;
  o.relinearise = x->j->relinearise;
  o.reweight = x->j->reweight;
  /* the default catalogue (rcb_monitor_opts.effects 0: the effects before the
   * shaft elements) and, unless --no-sensors, the measurement chain */
  if (x->j->sensors)
    o.effects = RCB_MONITOR_EFFECTS_SENSORS;
  if (x->j->have_baseline_sd) { /* the fit's standard errors: the diagonal */
    memset(cov, 0, sizeof cov);
    for (k = 0; k < x->j->params.n; k++)
      cov[k * x->j->params.n + k] = x->j->baseline_sd[k] * x->j->baseline_sd[k];
    o.baseline_cov = cov;
  }
  if (x->j->commission > 1 && (rc = averaged_setup(x, &avg))) return rc;
  x->avg = avg;
  if ((rc = noise_scale(x, &o))) return rc;
  /* --state: from the commissioning image when there is a good one (then
   * not rewritten), else in full (rcb_monitor_opts.image) */
  x->new_image = x->j->image != NULL;
  if (x->j->image && x->j->saved && mon_image_read(x->j->image, &x->image, &o.image_size)) {
    o.image = x->image;
    st = rcb_monitor_create(mon, x->m, avg ? avg : x->setup, &o, NULL);
    if (st == RCB_ERR_OTHER_SETUP || st == RCB_ERR_CORRUPT || st == RCB_ERR_VERSION)
      rcb_monitor_destroy(*mon), *mon = NULL, o.image = NULL, o.image_size = 0;
    else
      x->new_image = 0;
  }
  if (!o.image) st = rcb_monitor_create(mon, x->m, avg ? avg : x->setup, &o, NULL);
  if (st)
    return cli_fail(st == RCB_ERR_ARG || st == RCB_ERR_NOT_FOUND ? CLI_EXIT_INPUT
                                                                  : cli_status_exit(st),
                    "%s: commissioning on '%s': %s", x->a->cmd, x->j->series.files[0],
                    cli_msg(*mon ? rcb_monitor_errmsg(*mon) : NULL, st));
  return 0;
}

/* ---- the lines ---- */

void mon_print_scale(FILE *fp, const mon_state *s) {
  const rcb_monitor_noise *sc = &s->scatter;
  switch (s->scale_from) {
  case MON_SCALE_MEASURED:
    fprintf(fp, "# noise: the declared x %.3f, measured on the %zu commissioning files' "
            "scatter (chi-square %.4g on %.4g degrees of freedom)\n", s->noise_scale,
            s->j->commission, sc->chi2, sc->dof);
    break;
  case MON_SCALE_TOO_LOW:
    fprintf(fp, "# noise: as declared; the %zu commissioning files scatter only %.3g x it "
            "(repeated or noise-free files)\n", s->j->commission, sc->scale);
    break;
  case MON_SCALE_GIVEN:
    fprintf(fp, "# noise: the declared x %.6g (--noise-scale%s)\n", s->noise_scale,
            s->j->saved ? ", kept in the state" : "");
    break;
  case MON_SCALE_SD_DIR:
    fputs("# noise: each file's own --sd, as declared\n", fp);
    break;
  default:
    fputs(s->j->commission > 1 ? "# noise: as declared\n"
                               : "# noise: as declared (one commissioning file: --commission "
                                 "N >= 2 measures its level)\n", fp);
  }
}

static void print_header(FILE *fp, const mon_state *s) {
  size_t k;
  fputs("# commissioned on ", fp);
  cli_put_text(fp, s->j->series.files[0]); /* the one escaping rule (cli_text.c) */
  if (s->j->commission > 1) fprintf(fp, " and the next %zu files (averaged)", s->j->commission - 1);
  fprintf(fp, "; %zu channels x %zu points; %zu candidate effects; monitor memory %zu bytes\n",
          s->channels, s->points, s->candidates, s->memory);
  mon_print_scale(fp, s);
  if (s->j->saved)
    fprintf(fp, "# resumed from the state '%s' after %zu updates\n", s->j->state,
            s->j->saved->nrec);
  fprintf(fp, "%6s  %-24s %8s %8s %8s  %-12s", "update", "file", "error %", "floor %", "T/thr",
          "alarms");
  for (k = 0; k < s->j->params.n; k++)
    fprintf(fp, "  %s value [95 %% CI] change [95 %% CI]", s->j->params.items[k].name);
  fputc('\n', fp);
}

void mon_flags(const rcb_monitor_result *r, char *buf, size_t size) {
  size_t k;
  int down = 0, up = 0;
  for (k = 0; k < r->ntracked; k++) {
    if (r->tracked[k].cusum_alarm < 0) down = 1;
    if (r->tracked[k].cusum_alarm > 0) up = 1;
  }
  snprintf(buf, size, "%s%s%s%s", r->alarm ? "TEST" : "", r->alarm && (down || up) ? "," : "",
           down ? (up ? "CUSUM-+" : "CUSUM-") : (up ? "CUSUM+" : ""),
           !r->alarm && !down && !up ? "-" : "");
}

/* "<effect> at <place>[: <params>]" of a candidate, its names through the
 * one escaping rule (cli_text), as the tracked names are. */
static void put_cand(FILE *fp, const rcb_monitor_candidate_info *ci, int with_params) {
  char place[512], params[1024];
  fprintf(fp, "%s at %s", rcb_effect_name(ci->effect),
          cli_text(ci->place ? ci->place : "", place, sizeof place));
  if (with_params) fprintf(fp, ": %s", cli_text(ci->params ? ci->params : "", params, sizeof params));
}

/* A CUSUM alarm of tracked parameter k and what the attribution said (the
 * one rule, rcb_monitor_tracked.named): "kr falling", "kr falling, or
 * <candidate> falling: not separable on these channels", the candidate
 * told apart from kr, or, when a runner-up fits as well as that candidate,
 * "<candidate> falling, or <runner-up>: not separable on these channels;
 * the first told apart from kr"; ", or N other candidates" before the
 * colon when more are not rejected (rivals_open). */
static void print_attribution(FILE *fp, const mon_state *s, const rcb_monitor_result *r,
                              size_t k) {
  const rcb_monitor_tracked *t = &r->tracked[k];
  const char *dir = t->cusum_alarm < 0 ? "falling" : "rising";
  const char *rdir = t->rival_rate[0] < 0 ? "falling" : "rising";
  rcb_monitor_candidate_info ci, ci2;
  char name[1024];
  if (!t->cusum_alarm) return;
  cli_text(s->j->params.items[k].name, name, sizeof name);
  if (t->named == 1 || !t->rival_dof ||
      rcb_monitor_candidate_info_get(s->mon, t->rival, &ci) != RCB_OK) {
    fprintf(fp, "  %s %s", name, dir);
    return;
  }
  if (t->named == 0) {
    const rcb_monitor_separator *sp = mon_separator(s, r, k);
    char resp[256], ref[256];
    fprintf(fp, "  %s %s, or ", name, dir);
    put_cand(fp, &ci, 1);
    fprintf(fp, " %s", rdir);
    if (t->rivals_open) fprintf(fp, ", or %zu other candidates", t->rivals_open);
    fputs(": not separable on these channels", fp);
    if (sp)
      fprintf(fp, "; %s per %s at %.6g rpm would separate them", cli_text(sp->response, resp,
              sizeof resp), cli_text(sp->reference, ref, sizeof ref),
              sp->speed / CLI_RPM_TO_RAD_S);
  } else if (t->rival2_dof && rcb_monitor_candidate_info_get(s->mon, t->rival2, &ci2) == RCB_OK) {
    /* not this parameter, but the data do not say which of the two */
    fputs("  ", fp);
    put_cand(fp, &ci, 1);
    fprintf(fp, " %s, or ", rdir);
    put_cand(fp, &ci2, 1);
    if (t->rivals_open) fprintf(fp, ", or %zu other candidates", t->rivals_open);
    fprintf(fp, ": not separable on these channels; the first told apart from %s", name);
  } else {
    fputs("  ", fp);
    put_cand(fp, &ci, 1);
    fprintf(fp, " %s (told apart from %s)", rdir, name);
  }
}

static void print_line(FILE *fp, const mon_state *s, const mon_record *rec) {
  const rcb_monitor_result *r = &rec->r;
  char flags[32], name[1024];
  size_t k;
  mon_flags(r, flags, sizeof flags);
  fprintf(fp, "%6zu  %-24s %8.3f %8.3f %8.3g  %-12s", r->update,
          cli_text(base_name(s->j->series.files[rec->file]), name, sizeof name), r->error_pct, r->floor_pct,
          r->T / r->threshold, flags);
  for (k = 0; k < r->ntracked; k++)
    fprintf(fp, "  %.6g [%.6g, %.6g] %+.4g [%+.4g, %+.4g]", r->tracked[k].value,
            r->tracked[k].ci_lo, r->tracked[k].ci_hi, r->tracked[k].change,
            r->tracked[k].change_lo, r->tracked[k].change_hi);
  if (r->alarm && r->ntop > 0) {
    const rcb_monitor_candidate *c = &r->top[0];
    rcb_monitor_candidate_info ci;
    if (rcb_monitor_candidate_info_get(s->mon, c->index, &ci) == RCB_OK) {
      fputs("  -> ", fp);
      put_cand(fp, &ci, 1);
      fprintf(fp, " %.6g [%.6g, %.6g]", c->size[0], c->ci_lo[0], c->ci_hi[0]);
    }
    /* the one rule: the data may not tell the first from the second */
    if (rcb_monitor_named(s->mon, r) == 0 &&
        rcb_monitor_candidate_info_get(s->mon, r->top[1].index, &ci) == RCB_OK) {
      fputs(", or ", fp);
      put_cand(fp, &ci, 0);
      fputs(": not separable on these channels (rcbtool plan)", fp);
    }
  }
  for (k = 0; k < r->ntracked; k++)
    print_attribution(fp, s, r, k);
  if (r->drift_alarm) {
    rcb_monitor_candidate_info ci;
    if (rcb_monitor_candidate_info_get(s->mon, r->drift_index, &ci) == RCB_OK) {
      fputs("  drift: ", fp);
      put_cand(fp, &ci, 1);
      fprintf(fp, " %+.4g per update over %zu updates", r->drift_rate[0], r->drift_onset);
    }
  }
  fputc('\n', fp);
}

/* The separating measurement of every not-separable attribution of r
 * (rcb_monitor_separating, the diagnosis' plan), asked once per pair. */
static int separators(mon_state *s, rcb_monitor *mon, const rcb_monitor_result *r) {
  size_t k, i;
  for (k = 0; k < r->ntracked; k++) {
    const rcb_monitor_tracked *t = &r->tracked[k];
    mon_sep *p;
    if (!t->cusum_alarm || t->named != 0 || !t->rival_dof) continue;
    for (i = 0; i < s->nseps; i++)
      if (s->seps[i].tracked == k && s->seps[i].cand == t->rival) break;
    if (i < s->nseps) continue;
    if (!(p = realloc(s->seps, (s->nseps + 1) * sizeof *p)))
      return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    s->seps = p;
    p += s->nseps++;
    p->tracked = k, p->cand = t->rival;
    p->ok = rcb_monitor_separating(mon, k, t->rival, NULL, 0, &p->sep) == RCB_OK;
  }
  return 0;
}

const rcb_monitor_separator *mon_separator(const mon_state *s, const rcb_monitor_result *r,
                                           size_t k) {
  const rcb_monitor_tracked *t = &r->tracked[k];
  size_t i;
  if (!t->cusum_alarm || t->named != 0 || !t->rival_dof) return NULL;
  for (i = 0; i < s->nseps; i++)
    if (s->seps[i].tracked == k && s->seps[i].cand == t->rival)
      return s->seps[i].ok && s->seps[i].sep.found ? &s->seps[i].sep : NULL;
  return NULL;
}

static int keep(mon_state *s, rcb_monitor *mon, size_t file, const rcb_monitor_result *r) {
  int rc;
  if ((rc = separators(s, mon, r))) return rc;
  if (s->nrec == s->cap) {
    size_t cap = s->cap ? 2 * s->cap : 64;
    mon_record *p = realloc(s->rec, cap * sizeof *p);
    if (!p) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    s->rec = p;
    s->cap = cap;
  }
  s->rec[s->nrec].file = file;
  s->rec[s->nrec].r = *r;
  s->nrec++;
  return 0;
}

/* --state: every new file's content hash (x->hash[k - first]), checked
 * before any update: a content the series already had (an update in the
 * state, or an earlier file of this run) is refused. 0 or exit 3. */
static int not_seen(mon_ctx *x, const mon_state *s, size_t first) {
  size_t k, i, n = x->j->series.n - first;
  int ok;
  if (!(x->hash = calloc(n ? n : 1, sizeof *x->hash)))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (k = 0; k < n; k++) {
    const char *path = x->j->series.files[first + k];
    x->hash[k] = mon_file_hash(path, &ok);
    if (!ok) return cli_fail(CLI_EXIT_INPUT, "%s: cannot read '%s'", x->a->cmd, path);
    for (i = 0; i < s->nrec; i++)
      if (s->rec[i].hash == x->hash[k])
        return cli_fail(CLI_EXIT_INPUT, "%s: '%s' has the content of update %zu ('%s') of the "
                        "series in --state '%s': an update is taken once; give only new "
                        "measurements (nothing was changed)", x->a->cmd, path,
                        s->rec[i].r.update, x->j->series.files[s->rec[i].file], x->j->state);
    for (i = 0; i < k; i++)
      if (x->hash[i] == x->hash[k])
        return cli_fail(CLI_EXIT_INPUT, "%s: '%s' has the content of '%s' given before it: an "
                        "update is taken once (nothing was changed)", x->a->cmd, path,
                        x->j->series.files[first + i]);
  }
  return 0;
}

static int one_update(mon_ctx *x, mon_state *s, rcb_monitor *mon, size_t k) {
  rcb_meas *ms = NULL;
  rcb_monitor_result r;
  rcb_status st;
  uint64_t hash = x->hash ? x->hash[k - (x->j->resume ? x->j->resume : x->j->commission)] : 0;
  int rc, have_sd = 0;
  if ((rc = read_file(x, k, &ms))) return rc;
  gather(ms, x->perm, x->nc, x->n, x->values);
  rc = file_sd(x, ms, x->j->series.files[k], &have_sd);
  rcb_meas_destroy(ms);
  if (rc) return rc;
  if ((st = rcb_monitor_update(mon, x->values, have_sd ? x->sd : NULL, &r)))
    return cli_fail(st == RCB_ERR_ARG ? CLI_EXIT_INPUT : cli_status_exit(st), "%s: '%s': %s",
                    x->a->cmd, x->j->series.files[k], cli_msg(rcb_monitor_errmsg(mon), st));
  if ((rc = keep(s, mon, k, &r))) return rc;
  s->rec[s->nrec - 1].hash = hash;
  return 0;
}

static void summary(FILE *fp, const mon_state *s) {
  size_t i, nt = 0, ncu = 0, ft = 0, fc = 0;
  for (i = 0; i < s->nrec; i++) {
    const rcb_monitor_result *r = &s->rec[i].r;
    if (r->alarm && !nt++) ft = r->update;
    if (r->cusum_alarm && !ncu++) fc = r->update;
  }
  fprintf(fp, "# %zu updates: %zu with a TEST alarm", s->nrec, nt);
  if (nt) fprintf(fp, " (first at update %zu)", ft);
  fprintf(fp, ", %zu with a CUSUM alarm", ncu);
  if (ncu) fprintf(fp, " (first at update %zu)", fc);
  fputc('\n', fp);
}

static int updates(mon_ctx *x, mon_state *s, rcb_monitor *mon, cli_out *o) {
  cli_progress p;
  size_t first = x->j->resume ? x->j->resume : x->j->commission, k,
         total = x->j->series.n - first;
  int rc = 0;
  memset(&p, 0, sizeof p);
  if (x->j->state && (rc = not_seen(x, s, first))) return rc;
  /* on a terminal the lines are the progress: the counter only when they go elsewhere */
  if (x->a->progress || x->a->json || o->fp != stdout || !isatty(fileno(stdout)))
    cli_progress_start(&p, x->a, "monitor", "updates", total);
  if (!x->a->json) print_header(o->fp, s);
  for (k = first; k < x->j->series.n && !rc; k++) {
    if (!(rc = one_update(x, s, mon, k)) && !x->a->json) {
      print_line(o->fp, s, &s->rec[s->nrec - 1]);
      if (o->fp == stdout) fflush(stdout);
    }
    cli_progress_step(&p, k + 1 - first);
  }
  cli_progress_end(&p);
  if (!rc && !x->a->json) summary(o->fp, s);
  return rc;
}

static void describe(mon_state *s, const mon_ctx *x, const rcb_monitor *mon) {
  s->memory = rcb_monitor_memory(mon);
  s->candidates = rcb_monitor_candidate_count(mon);
  rcb_monitor_rank(mon, &s->rank, &s->rank_tracked);
  s->channels = x->nc;
  s->points = x->n;
  s->kind = rcb_meas_get_type(x->setup) == RCB_MEAS_FRF ? "frf" : "unbalance";
  s->noise_scale = x->noise_scale, s->scatter = x->scatter, s->scale_from = x->scale_from;
  s->rpm = rcb_meas_get_type(x->setup) == RCB_MEAS_FRF
               ? rcb_meas_speed(x->setup) / CLI_RPM_TO_RAD_S
               : (double)NAN;
}

/* --state: the library's state loaded into the monitor just created and the
 * series' records so far into s; 0 or exit 3 naming the state file. */
static int resume(const mon_ctx *x, mon_state *s, rcb_monitor *mon) {
  const mon_saved *sv = x->j->saved;
  rcb_status st = rcb_monitor_load(mon, sv->blob, sv->nblob);
  size_t k;
  int rc;
  if (st)
    return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': %s%s", x->a->cmd, x->j->state,
                    cli_msg(rcb_monitor_errmsg(mon), st),
                    st == RCB_ERR_OTHER_MODEL ? " (give the baseline model the series was "
                                                "started with)" : "");
  if ((rc = mon_saved_check(x->a->cmd, x->j->state, sv, mon))) return rc;
  for (k = 0; k < sv->nrec; k++) {
    if ((rc = keep(s, mon, sv->ncomm + k, &sv->rec[k].r))) return rc;
    s->rec[s->nrec - 1].hash = sv->rec[k].hash;
  }
  return 0;
}

/* --state: the series' state written to a temporary (renamed by the caller). */
static int save_state(const mon_ctx *x, const mon_state *s, const rcb_monitor *mon,
                      cli_tmpfile *t) {
  mon_saved sv;
  char **names = NULL, **opts = NULL;
  size_t k;
  int rc;
  memset(&sv, 0, sizeof sv);
  sv.nblob = rcb_monitor_state_size(mon);
  sv.blob = malloc(sv.nblob ? sv.nblob : 1);
  sv.rec = malloc((s->nrec + 1) * sizeof *sv.rec);
  names = malloc((s->nrec + 1) * sizeof *names);
  if (!sv.blob || !sv.rec || !names || rcb_monitor_save(mon, sv.blob, sv.nblob, NULL)) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "%s: out of memory (state)", x->a->cmd);
    goto done;
  }
  sv.opts = x->j->saved ? x->j->saved->opts : x->j->setopts;
  sv.nopts = x->j->saved ? x->j->saved->nopts : x->j->nsetopts;
  if (!x->j->saved && x->scale_opt[0]) { /* the measured scale: a setting from now on */
    opts = malloc((sv.nopts + 1) * sizeof *opts);
    if (!opts) {
      rc = cli_fail(CLI_EXIT_NUMERIC, "%s: out of memory (state)", x->a->cmd);
      goto done;
    }
    memcpy(opts, sv.opts, sv.nopts * sizeof *opts);
    opts[sv.nopts++] = (char *)x->scale_opt;
    sv.opts = opts;
  }
  sv.comm = x->j->series.files;
  sv.ncomm = x->j->commission;
  sv.setup = x->avg ? x->avg : x->setup;
  for (k = 0; k < s->nrec; k++) {
    sv.rec[k] = s->rec[k];
    names[k] = x->j->series.files[s->rec[k].file];
  }
  sv.recfile = names;
  sv.nrec = s->nrec;
  rc = mon_saved_write(x->a->cmd, x->j->state, &sv, t);
done:
  free(opts);
  free(sv.blob);
  free(sv.rec);
  free(names);
  return rc;
}

int mon_run(const cli_args *a, const mon_job *j) {
  mon_ctx x;
  mon_state s;
  rcb_monitor *mon = NULL;
  cli_out o;
  cli_tmpfile st, it;
  int rc;
  memset(&st, 0, sizeof st);
  memset(&it, 0, sizeof it);
  memset(&x, 0, sizeof x);
  memset(&s, 0, sizeof s);
  memset(&o, 0, sizeof o);
  x.a = s.a = a;
  x.j = s.j = j;
  if ((rc = cli_load_model(a, &x.m))) return rc;
  if ((rc = commission(&x)) || (rc = create_monitor(&x, &mon))) goto done;
  if (j->saved && (rc = resume(&x, &s, mon))) goto done;
  s.mon = mon;
  describe(&s, &x, mon);
  if ((rc = cli_out_open(&o, a))) goto done;
  if ((rc = updates(&x, &s, mon, &o))) {
    cli_out_abort(&o);
    goto done;
  }
  if (a->json) mon_print_json(o.fp, &s);
  /* the state written (fsync'ed) first, then the log and the plot; the run's
   * plan renames them all, -o too, only when every one is written, and fsyncs
   * their directories (cli_plan_finish) */
  if (j->state && (rc = save_state(&x, &s, mon, &st))) {
    cli_out_abort(&o);
    goto done;
  }
  if (x.new_image && (rc = mon_image_write(a->cmd, j->image, mon, &it))) {
    cli_tmpfile_close(&st, 0);
    cli_out_abort(&o);
    goto done;
  }
  if ((rc = cli_out_flush(&o)) || (rc = mon_write_outputs(&s))) {
    if (j->state) cli_tmpfile_close(&st, 0);
    if (x.new_image) cli_tmpfile_close(&it, 0);
    cli_out_abort(&o);
    goto done;
  }
  if (j->state && (rc = cli_tmpfile_close(&st, 1))) {
    if (x.new_image) cli_tmpfile_close(&it, 0);
    cli_out_abort(&o);
    goto done;
  }
  if (x.new_image && (rc = cli_tmpfile_close(&it, 1))) {
    cli_out_abort(&o);
    goto done;
  }
  rc = cli_out_close(&o);
done:
  rcb_monitor_destroy(mon);
  rcb_meas_destroy(x.avg);
  free(x.hash);
  free(x.image);
  rcb_meas_destroy(x.setup);
  rcb_model_destroy(x.m);
  free(x.perm);
  free(x.values);
  free(x.reps);
  free(x.sd);
  free(s.rec);
  free(s.seps);
  return rc;
}
