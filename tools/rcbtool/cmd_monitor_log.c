/* rcbtool monitor: the log (JSON or CSV) and the trend plot, each written to
 * a temporary file and renamed only when all of them are complete. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cmd_monitor.h"

int mon_log_is_csv(const char *path) { return mon_has_ext(path, ".csv"); }

const char *mon_plot_format(const char *path) {
  static const char *const fmt[] = {"png", "pdf", "svg"};
  static const char *const ext[] = {".png", ".pdf", ".svg"};
  size_t i;
  for (i = 0; i < 3; i++)
    if (mon_has_ext(path, ext[i])) return fmt[i];
  return NULL;
}

static const char *file_of(const mon_state *s, size_t k) {
  const char *p = s->j->series.files[s->rec[k].file], *b = strrchr(p, '/');
  return b ? b + 1 : p;
}

static void json_key_num(FILE *fp, const char *key, double x) {
  fprintf(fp, ", \"%s\": ", key);
  cli_json_num(fp, x);
}

static void json_candidate(FILE *fp, const mon_state *s, const rcb_monitor_candidate *c) {
  rcb_monitor_candidate_info ci;
  memset(&ci, 0, sizeof ci);
  rcb_monitor_candidate_info_get(s->mon, c->index, &ci);
  fputs("{\"effect\": ", fp);
  cli_json_str(fp, rcb_effect_name(c->effect));
  fputs(", \"place\": ", fp);
  cli_json_str(fp, ci.place ? ci.place : "");
  fputs(", \"description\": ", fp);
  cli_json_str(fp, ci.description ? ci.description : "");
  fputs(", \"params\": ", fp);
  cli_json_str(fp, ci.params ? ci.params : "");
  fputs(", \"size\": ", fp);
  cli_json_nums(fp, c->size, c->np, 1);
  fputs(", \"ci_lo\": ", fp);
  cli_json_nums(fp, c->ci_lo, c->np, 1);
  fputs(", \"ci_hi\": ", fp);
  cli_json_nums(fp, c->ci_hi, c->np, 1);
  json_key_num(fp, "score", c->score);
  fprintf(fp, ", \"dof\": %zu", c->dof);
  json_key_num(fp, "p_value", c->p_value);
  fprintf(fp, ", \"implausible\": %s", c->implausible ? "true" : "false");
  fputc('}', fp);
}

/* A candidate by index: effect, place, params and its rate per update. */
static void json_rate(FILE *fp, const mon_state *s, size_t index, const double *rate) {
  rcb_monitor_candidate_info ci;
  memset(&ci, 0, sizeof ci);
  rcb_monitor_candidate_info_get(s->mon, index, &ci);
  fputs("{\"effect\": ", fp);
  cli_json_str(fp, rcb_effect_name(ci.effect));
  fputs(", \"place\": ", fp);
  cli_json_str(fp, ci.place ? ci.place : "");
  fputs(", \"params\": ", fp);
  cli_json_str(fp, ci.params ? ci.params : "");
  if (rate) {
    fputs(", \"rate\": ", fp);
    cli_json_nums(fp, rate, ci.np, 1);
  }
}

static void json_tracked(FILE *fp, const mon_state *s, const rcb_monitor_tracked *t,
                         const char *name, const rcb_monitor_separator *sep) {
  fputs("{\"name\": ", fp);
  cli_json_str(fp, name);
  json_key_num(fp, "value", t->value);
  json_key_num(fp, "ci_lo", t->ci_lo);
  json_key_num(fp, "ci_hi", t->ci_hi);
  json_key_num(fp, "abs_stderr", t->abs_stderr);
  json_key_num(fp, "change", t->change);
  json_key_num(fp, "change_lo", t->change_lo);
  json_key_num(fp, "change_hi", t->change_hi);
  json_key_num(fp, "stderr", t->stderr_);
  json_key_num(fp, "z", t->z);
  json_key_num(fp, "u", t->u);
  json_key_num(fp, "cusum_up", t->cusum_up);
  json_key_num(fp, "cusum_down", t->cusum_down);
  fprintf(fp, ", \"cusum_alarm\": %d, \"out_of_range\": %s", t->cusum_alarm,
          t->out_of_range ? "true" : "false");
  /* a CUSUM alarm's attribution (the one rule): 1 this parameter, 0 it or
   * the rival (not separable), -1 the rival */
  fprintf(fp, ", \"named\": %d, \"rival\": ", t->named);
  if (t->cusum_alarm && t->rival_dof) {
    json_rate(fp, s, t->rival, t->rival_rate);
    fputc('}', fp);
  } else {
    fputs("null", fp);
  }
  /* named -1 but the runner-up not separable from the rival: both, no rate */
  fputs(", \"rival2\": ", fp);
  if (t->cusum_alarm && t->named == -1 && t->rival2_dof) {
    json_rate(fp, s, t->rival2, NULL);
    fputc('}', fp);
  } else {
    fputs("null", fp);
  }
  /* candidates beyond rival and rival2 the rule's test does not reject */
  fprintf(fp, ", \"rivals_open\": %zu", t->cusum_alarm ? t->rivals_open : (size_t)0);
  json_key_num(fp, "cusum_allow", t->cusum_allow);
  /* not separable: the measurement the plan names (rcb_monitor_separating) */
  fputs(", \"separate_by\": ", fp);
  if (sep) {
    fputs("{\"response\": ", fp);
    cli_json_str(fp, sep->response);
    fputs(", \"reference\": ", fp);
    cli_json_str(fp, sep->reference);
    json_key_num(fp, "rpm", sep->speed / CLI_RPM_TO_RAD_S);
    json_key_num(fp, "chi2_present", sep->chi2_present);
    json_key_num(fp, "chi2_after", sep->chi2_after);
    json_key_num(fp, "level_db", sep->level_db);
    fputc('}', fp);
  } else {
    fputs("null", fp);
  }
  fputc('}', fp);
}

static void json_update(FILE *fp, const mon_state *s, size_t k) {
  const rcb_monitor_result *r = &s->rec[k].r;
  size_t i;
  fprintf(fp, "  {\"update\": %zu, \"file\": ", r->update);
  cli_json_str(fp, file_of(s, k));
  json_key_num(fp, "error_pct", r->error_pct);
  json_key_num(fp, "change_pct", r->change_pct);
  json_key_num(fp, "floor_pct", r->floor_pct);
  json_key_num(fp, "T", r->T);
  json_key_num(fp, "threshold", r->threshold);
  fprintf(fp, ", \"dof\": %zu", r->dof);
  json_key_num(fp, "p_value", r->p_value);
  fprintf(fp, ", \"alarm\": %s, \"cusum_alarm\": %s,\n   \"tracked\": [",
          r->alarm ? "true" : "false", r->cusum_alarm ? "true" : "false");
  for (i = 0; i < r->ntracked; i++) {
    if (i) fputs(", ", fp);
    json_tracked(fp, s, &r->tracked[i], s->j->params.items[i].name, mon_separator(s, r, i));
  }
  fputs("],\n   \"top\": [", fp);
  for (i = 0; i < r->ntop; i++) {
    if (i) fputs(",\n    ", fp);
    json_candidate(fp, s, &r->top[i]);
  }
  { /* rcb_monitor_named: the first told apart from the second (null: < 2 ranked) */
    int named = rcb_monitor_named(s->mon, r);
    fprintf(fp, "], \"separable\": %s", named < 0 ? "null" : named ? "true" : "false");
    json_key_num(fp, "apart_p", r->apart_p); /* null when the BIC half fails */
  }
  fputs(",\n   \"drift\": ", fp); /* the drift test's best supported candidate */
  if (!r->drift_dof) {
    fputs("null}", fp);
  } else {
    json_rate(fp, s, r->drift_index, r->drift_rate);
    json_key_num(fp, "glr", r->drift_glr);
    fprintf(fp, ", \"dof\": %zu", r->drift_dof);
    json_key_num(fp, "p_value", r->drift_p);
    fprintf(fp, ", \"alarm\": %s, \"onset\": %zu}}", r->drift_alarm ? "true" : "false",
            r->drift_onset);
  }
}

void mon_print_json(FILE *fp, const mon_state *s) {
  size_t k;
  double alpha = NAN, cusum_k = NAN, cusum_h = NAN;
  rcb_monitor_thresholds(s->mon, &alpha, NULL, &cusum_k, &cusum_h); /* the defaults resolved */
  fputs("{\"model\": ", fp);
  cli_json_str(fp, s->a->model);
  fputs(", \"commissioning\": [", fp);
  for (k = 0; k < s->j->commission; k++) {
    if (k) fputs(", ", fp);
    cli_json_str(fp, s->j->series.files[k]);
  }
  fprintf(fp, "], \"type\": \"%s\"", s->kind);
  json_key_num(fp, "rpm", s->rpm);
  fprintf(fp, ", \"channels\": %zu, \"points\": %zu, \"candidates\": %zu, \"rank\": %zu, "
          "\"rank_tracked\": %zu, \"memory_bytes\": %zu", s->channels, s->points,
          s->candidates, s->rank, s->rank_tracked, s->memory);
  json_key_num(fp, "alpha", alpha);
  json_key_num(fp, "cusum_k", cusum_k);
  json_key_num(fp, "cusum_h", cusum_h);
  fputs(", \"noise\": ", fp);
  if (s->j->sd_path)
    cli_json_str(fp, s->j->sd_path);
  else
    fprintf(fp, "[%.17g, %.17g, %.17g]", s->j->beta_a, s->j->beta_s, s->j->phase_deg);
  json_key_num(fp, "noise_scale", s->noise_scale);
  fprintf(fp, ", \"noise_scale_from\": \"%s\"",
          s->scale_from == MON_SCALE_MEASURED  ? "commissioning scatter"
          : s->scale_from == MON_SCALE_GIVEN   ? "option"
          : s->scale_from == MON_SCALE_TOO_LOW ? "declared (scatter too low)"
                                               : "declared");
  if (s->scatter.dof > 0) {
    json_key_num(fp, "scatter_chi2", s->scatter.chi2);
    json_key_num(fp, "scatter_dof", s->scatter.dof);
  }
  fputs(",\n\"tracked\": [", fp);
  for (k = 0; k < s->j->params.n; k++) {
    const char *name = NULL;
    double base = NAN;
    rcb_monitor_tracked_info(s->mon, k, &name, &base);
    fputs(k ? ", {\"name\": " : "{\"name\": ", fp);
    cli_json_str(fp, s->j->params.items[k].name);
    json_key_num(fp, "baseline", base);
    json_key_num(fp, "baseline_sd", s->j->have_baseline_sd ? s->j->baseline_sd[k] : 0.0);
    fputc('}', fp);
  }
  fputs("],\n\"updates\": [\n", fp);
  for (k = 0; k < s->nrec; k++) {
    json_update(fp, s, k);
    fputs(k + 1 < s->nrec ? ",\n" : "\n", fp);
  }
  fputs("]}\n", fp);
}

/* A CSV text field, quoted (the file and place names may hold commas). */
static void csv_str(FILE *fp, const char *s) {
  char buf[4096];
  const char *t = cli_text(s, buf, sizeof buf); /* the one rule: no raw control byte */
  fputc('"', fp);
  for (; *t; t++) {
    if (*t == '"') fputc('"', fp);
    fputc(*t, fp);
  }
  fputc('"', fp);
}

static void csv_row(FILE *fp, const mon_state *s, size_t k) {
  const rcb_monitor_result *r = &s->rec[k].r;
  const double v[] = {r->error_pct, r->change_pct, r->floor_pct, r->T, r->threshold,
                      (double)r->dof, r->p_value};
  char flags[32];
  size_t i;
  fprintf(fp, "%zu,", r->update);
  csv_str(fp, file_of(s, k));
  for (i = 0; i < sizeof v / sizeof v[0]; i++) {
    fputc(',', fp);
    cli_csv_num(fp, v[i]);
  }
  mon_flags(r, flags, sizeof flags);
  fprintf(fp, ",%d,%d,", r->alarm, r->cusum_alarm);
  csv_str(fp, flags);
  for (i = 0; i < r->ntracked; i++) {
    const rcb_monitor_tracked *t = &r->tracked[i];
    const double tv[] = {t->value,     t->ci_lo,  t->ci_hi,     t->z,         t->u,
                         t->cusum_down, t->cusum_up, t->change, t->change_lo, t->change_hi};
    size_t q;
    for (q = 0; q < sizeof tv / sizeof tv[0]; q++) {
      fputc(',', fp);
      cli_csv_num(fp, tv[q]);
    }
  }
  fputc(',', fp);
  if (r->ntop > 0) {
    rcb_monitor_candidate_info ci;
    memset(&ci, 0, sizeof ci);
    rcb_monitor_candidate_info_get(s->mon, r->top[0].index, &ci);
    csv_str(fp, rcb_effect_name(r->top[0].effect));
    fputc(',', fp);
    csv_str(fp, ci.place ? ci.place : "");
    fputc(',', fp);
    cli_csv_num(fp, r->top[0].p_value);
  } else {
    fputs("\"\",\"\",", fp);
  }
  fputc('\n', fp);
}

static void print_csv(FILE *fp, const mon_state *s) {
  size_t k;
  fputs("# rcbtool monitor ", fp);
  cli_put_text(fp, s->a->model);
  fputs(", commissioned on ", fp);
  cli_put_text(fp, s->j->series.files[0]);
  fputs("; SI units\n", fp);
  fputs("update,file,error_pct,change_pct,floor_pct,T,threshold,dof,p_value,alarm,"
        "cusum_alarm,flags", fp);
  for (k = 0; k < s->j->params.n; k++) {
    const char *n = s->j->params.items[k].name;
    fprintf(fp, ",%s,%s ci_lo,%s ci_hi,%s z,%s u,%s cusum_down,%s cusum_up,%s change,"
            "%s change_lo,%s change_hi", n, n, n, n, n, n, n, n, n, n);
  }
  fputs(",top_effect,top_place,top_p_value\n", fp);
  for (k = 0; k < s->nrec; k++) csv_row(fp, s, k);
}

/* The mode a plain fopen would have given (0666 & ~umask): mkstemp made 0600. */
static void plain_mode(const char *path) {
  mode_t mask = umask(0);
  umask(mask);
  (void)chmod(path, (mode_t)(0666 & ~mask));
}

/* Write a temporary for @p path with @p fn; 0 or exit 5 (the temporary removed). */
static int write_tmp(cli_tmpfile *t, const char *path, const mon_state *s,
                     void (*fn)(FILE *, const mon_state *)) {
  FILE *fp;
  int rc = cli_tmpfile_open(t, path), bad, e;
  if (rc) return rc;
  if (!(fp = fopen(t->write_path, "w"))) {
    e = errno;
    cli_tmpfile_close(t, 0);
    return cli_fail(cli_errno_exit(e), "cannot write output file '%s': %s", path, strerror(e));
  }
  plain_mode(t->write_path);
  errno = 0; /* the first failing write sets it: its reason is the message's */
  fn(fp, s);
  bad = ferror(fp) != 0 || fflush(fp) != 0;
  e = errno;
  if (fclose(fp) != 0 && !bad) {
    bad = 1;
    e = errno;
  }
  if (bad) {
    cli_tmpfile_close(t, 0);
    return cli_fail(cli_errno_exit(e ? e : EIO), "cannot write output file '%s': %s", path,
                    strerror(e ? e : EIO));
  }
  return 0;
}

#define NOTHING_KEPT "no log, plot or output file was kept (run without --plot to get the rest)"

int mon_write_outputs(const mon_state *s) {
  cli_tmpfile log, pic, pj;
  int rc = 0, have_log = 0, have_pic = 0;
  memset(&log, 0, sizeof log);
  if (s->j->log) {
    if ((rc = write_tmp(&log, s->j->log, s, mon_log_is_csv(s->j->log) ? print_csv
                                                                         : mon_print_json)))
      return rc;
    have_log = 1;
  }
  if (s->j->plot) {
    /* the plotter reads the JSON from a temporary beside the picture (removed; a
     * temporary of the declared --plot, as every file goes through the run's plan) */
    rc = cli_plot_mkdir(s->j->plot);
    if (!rc && !(rc = write_tmp(&pj, s->j->plot, s, mon_print_json))) {
      if (!(rc = cli_tmpfile_open(&pic, s->j->plot))) {
        have_pic = 1;
        rc = cli_plot_run("monitor", pj.write_path, pic.write_path,
                             mon_plot_format(s->j->plot), NOTHING_KEPT);
      }
      cli_tmpfile_close(&pj, 0);
    }
  }
  if (have_pic) {
    int r2;
    if (!rc) plain_mode(pic.write_path);
    r2 = cli_tmpfile_close(&pic, !rc);
    if (!rc) rc = r2;
  }
  if (have_log) {
    int r2 = cli_tmpfile_close(&log, !rc);
    if (!rc) rc = r2;
  }
  return rc;
}
