/* rcbtool estimate, impact tests: the hits as the averages. A hit is one
 * signals file, one record of each channel of a UFF file, or (--trigger) a cut
 * of a long recording at a force level; each is one segment of the Welch
 * average (no overlap), after a check for a double hit and for an overload,
 * reported hit by hit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_estimate.h"

/* The options only hits take (refused for a single stream). */
static const char *const hit_opts[] = {"--hit-length", "--double-frac", "--clip-run",
                                       "--range",      "--reject",      "--keep-flagged",
                                       "--report"};

typedef struct est_hit {
  size_t file, rec; /* which file (index into a->files) and record of it */
  size_t start;     /* first sample, into the file's channels */
  double t;         /* s from the record's start (--trigger) */
  rcb_hit_pulse pulse;
  rcb_hit_overload over; /* the first overloaded channel's (or the first channel's) */
  size_t over_ch;        /* that channel (0 .. p + q) */
  int user, flagged, kept;
} est_hit;

typedef struct est_hits {
  est_job *j;
  rcb_signals **sig; /* per file (sig[0] is j->sig) */
  size_t *idx;       /* per file, p + q channel indices */
  size_t nf, len, rec_len;
  est_hit *h;
  size_t nh, cap;
  double frac, *range; /* --double-frac; --range per channel (SI, 0 none) */
  size_t clip_run;
  char trig[64]; /* --trigger's channel */
} est_hits;

int est_hits_mode(const est_job *j) {
  return j->a->nfiles > 1 || cli_opt_value(j->a, "--trigger") != NULL ||
         rcb_signals_record_count(j->sig) > 1;
}

int est_hits_options(est_job *j, int hits) {
  const cli_args *a = j->a;
  size_t i;
  if (!hits) {
    for (i = 0; i < sizeof hit_opts / sizeof hit_opts[0]; i++)
      if (cli_opt_value(a, hit_opts[i]))
        return cli_usage(a->cmd, "%s applies to an impact test's hits: several signals files "
                         "(one per hit), a UFF file with several records per channel, or "
                         "--trigger CH:LEVEL on a long recording", hit_opts[i]);
    return 0;
  }
  if (cli_opt_value(a, "--nseg") || cli_opt_value(a, "--overlap"))
    return cli_usage(a->cmd, "%s does not apply to hits: each hit is one segment (its file's "
                     "or record's length, or --hit-length with --trigger), without overlap",
                     cli_opt_value(a, "--nseg") ? "--nseg" : "--overlap");
  if (cli_opt_value(a, "--hit-length") && !cli_opt_value(a, "--trigger"))
    return cli_usage(a->cmd, "--hit-length goes with --trigger (a hit of a file or record is "
                     "all of it)");
  if (j->p != 1)
    return cli_usage(a->cmd, "an impact test has one force (--input): %zu given", j->p);
  if (!j->window_given) j->o.window = RCB_WINDOW_FORCE_EXP;
  j->o.no_detrend = 1; /* an impact response's mean belongs to it */
  return 0;
}

/* "12.5", "12.5N", "0.1kN", "5g": a value with an optional unit, in SI; the
 * unit must be of quantity @p q. */
static int value_si(const est_job *j, const char *opt, const char *text, rcb_quantity q,
                    double *si) {
  char *end;
  double v = strtod(text, &end), f = 1.0;
  rcb_quantity uq = q;
  if (end == text || !isfinite(v))
    return cli_usage(j->a->cmd, "%s: '%s' is not a number (with an optional unit, e.g. 50N, "
                     "2g)", opt, text);
  if (*end && rcb_unit_parse(end, &uq, &f))
    return cli_usage(j->a->cmd, "%s: '%s' is not a unit librcb knows", opt, end);
  if (uq != q)
    return cli_usage(j->a->cmd, "%s: '%s' is %s, the channel is %s", opt, end,
                     rcb_quantity_name(uq), rcb_quantity_name(q));
  *si = v * f;
  return 0;
}

/* Channel @p name among the input and outputs (its position), else usage. */
static int used_channel(const est_job *j, const char *opt, const char *name, size_t *c) {
  for (*c = 0; *c < j->p + j->q; (*c)++)
    if (strcmp(j->names[*c], name) == 0) return 0;
  return cli_usage(j->a->cmd, "%s: '%s' is not the input nor an output channel", opt, name);
}

/* --range CH:MAX[UNIT],...: the recorder's full scale per channel. */
static int ranges(est_hits *H) {
  est_job *j = H->j;
  const char *v = cli_opt_value(j->a, "--range");
  char *buf, *p;
  int rc = 0;
  if (!v) return 0;
  if (!(buf = malloc(strlen(v) + 1))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(buf, v);
  for (p = buf; p && !rc;) {
    char *comma = strchr(p, ','), *colon;
    size_t c;
    rcb_quantity q;
    if (comma) *comma = '\0';
    colon = strrchr(p, ':');
    if (!colon || colon == p || !colon[1]) {
      rc = cli_usage(j->a->cmd, "--range item '%s': expected CH:MAX (e.g. f:2000N,DA.x:5g)", p);
      break;
    }
    *colon = '\0';
    if (!(rc = used_channel(j, "--range", p, &c))) {
      rcb_signals_channel(j->sig, j->idx[c], NULL, &q, NULL);
      if (!(rc = value_si(j, "--range", colon + 1, q, &H->range[c])) && !(H->range[c] > 0.0))
        rc = cli_usage(j->a->cmd, "--range %s: expected a full scale > 0", colon + 1);
    }
    p = comma ? comma + 1 : NULL;
  }
  free(buf);
  return rc;
}

/* The other files: read, and the same channels, rate and hit length as the first. */
static int read_files(est_hits *H) {
  est_job *j = H->j;
  const cli_args *a = j->a;
  size_t f, c, n0 = rcb_signals_length(j->sig) / rcb_signals_record_count(j->sig);
  double rate = rcb_signals_rate(j->sig);
  int rc;
  H->rec_len = n0;
  for (c = 0; c < j->p + j->q; c++) H->idx[c] = j->idx[c];
  H->sig[0] = j->sig;
  for (f = 1; f < H->nf; f++) {
    const char *path = a->files[f];
    size_t n;
    if (rcb_signals_create(&H->sig[f], NULL)) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    rcb_signals_set_join_records(H->sig[f], 1);
    if ((rc = cli_signals_read_path(a, path, H->sig[f]))) return rc;
    for (c = 0; c < j->p + j->q; c++) {
      rcb_quantity q0, q;
      size_t *k = &H->idx[f * (j->p + j->q) + c];
      if (rcb_signals_find(H->sig[f], j->names[c], k))
        return cli_fail(CLI_EXIT_INPUT, "%s: no channel '%s' (%s has it): every hit needs the "
                        "same channels", path, j->names[c], a->model);
      rcb_signals_channel(j->sig, j->idx[c], NULL, &q0, NULL);
      rcb_signals_channel(H->sig[f], *k, NULL, &q, NULL);
      if (q != q0)
        return cli_fail(CLI_EXIT_INPUT, "%s: channel '%s' is %s, in %s %s", path, j->names[c],
                        rcb_quantity_name(q), a->model, rcb_quantity_name(q0));
    }
    if (fabs(rcb_signals_rate(H->sig[f]) - rate) > 1e-6 * rate)
      return cli_fail(CLI_EXIT_INPUT, "%s: %.9g samples/s, %s has %.9g: every hit needs the "
                      "same sample rate", path, rcb_signals_rate(H->sig[f]), a->model, rate);
    n = rcb_signals_length(H->sig[f]) / rcb_signals_record_count(H->sig[f]);
    if (n != n0 && !cli_opt_value(a, "--trigger"))
      return cli_fail(CLI_EXIT_INPUT, "%s: %zu samples per hit, %s has %zu: every hit is one "
                      "segment and needs the same length (cut them alike, or record one "
                      "stream and give --trigger)", path, n, a->model, n0);
  }
  return 0;
}

static int add_hit(est_hits *H, size_t f, size_t rec, size_t start, double t) {
  est_hit *h;
  if (H->nh == H->cap) {
    size_t cap = H->cap ? 2 * H->cap : 16;
    est_hit *nh = realloc(H->h, cap * sizeof *nh);
    if (!nh) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    H->h = nh;
    H->cap = cap;
  }
  h = &H->h[H->nh++];
  memset(h, 0, sizeof *h);
  h->file = f;
  h->rec = rec;
  h->start = start;
  h->t = t;
  return 0;
}

/* --trigger CH:LEVEL[:PRE] and --hit-length S: samples of a hit and before
 * the crossing, the channel and the level (SI). */
static int trigger_opts(est_hits *H, size_t *ch, double *level, size_t *pre) {
  est_job *j = H->j;
  const char *v = cli_opt_value(j->a, "--trigger");
  char buf[256], *c1, *c2;
  double len_s = 0.0, pre_s, rate = rcb_signals_rate(j->sig);
  rcb_quantity q;
  int rc;
  if (strlen(v) >= sizeof buf || !(c1 = strchr(strcpy(buf, v), ':')) || c1 == buf || !c1[1])
    return cli_usage(j->a->cmd, "--trigger '%s': expected CH:LEVEL[:PRE] (e.g. f:20N:0.01)", v);
  *c1++ = '\0';
  if ((c2 = strchr(c1, ':'))) *c2++ = '\0';
  if (rcb_signals_find(j->sig, buf, ch) || strlen(buf) >= sizeof H->trig)
    return cli_fail(CLI_EXIT_INPUT, "%s: --trigger: no channel '%s' in the file", j->a->model,
                    buf);
  strcpy(H->trig, buf);
  rcb_signals_channel(j->sig, *ch, NULL, &q, NULL);
  if (q != RCB_QTY_FORCE)
    return cli_usage(j->a->cmd, "--trigger: channel '%s' is %s; the trigger is the force", buf,
                     rcb_quantity_name(q));
  if ((rc = value_si(j, "--trigger", c1, q, level))) return rc;
  if (*level == 0.0) return cli_usage(j->a->cmd, "--trigger: a level of 0 is no trigger");
  if ((rc = cli_opt_require(j->a, "--hit-length", "the length of a hit, s (with --trigger)")) ||
      (rc = cli_opt_nonneg(j->a, "--hit-length", "s", 0.0, &len_s)))
    return rc;
  H->len = (size_t)floor(len_s * rate + 0.5);
  pre_s = 0.02 * len_s;
  if (c2) {
    char *end;
    pre_s = strtod(c2, &end);
    if (end == c2 || *end || !(pre_s >= 0.0) || !isfinite(pre_s))
      return cli_usage(j->a->cmd, "--trigger: pre-trigger '%s': expected a time >= 0, s", c2);
  }
  *pre = (size_t)floor(pre_s * rate + 0.5);
  if (H->len < 8 || *pre >= H->len)
    return cli_usage(j->a->cmd, "--hit-length %g s is %zu samples, pre-trigger %zu: expected at "
                     "least 8 samples and a pre-trigger shorter than the hit", len_s, H->len,
                     *pre);
  return 0;
}

/* The hits: every record of every file, cut at the trigger's crossings. */
static int list_hits(est_hits *H) {
  est_job *j = H->j;
  size_t f, r, i, ch = 0, pre = 0, cut = 0;
  double level = 0.0;
  int rc, trig = cli_opt_value(j->a, "--trigger") != NULL;
  H->len = H->rec_len;
  if (trig && (rc = trigger_opts(H, &ch, &level, &pre))) return rc;
  for (f = 0; f < H->nf; f++) {
    size_t nrec = rcb_signals_record_count(H->sig[f]);
    size_t len = rcb_signals_length(H->sig[f]) / nrec, k = ch;
    const double *v;
    if (trig && rcb_signals_find(H->sig[f], H->trig, &k))
      return cli_fail(CLI_EXIT_INPUT, "%s: --trigger: no channel '%s' (%s has it)",
                      j->a->files[f], H->trig, j->a->model);
    for (r = 0; r < nrec; r++) {
      size_t count = 0, partial = 0, *st;
      if (!trig) {
        if ((rc = add_hit(H, f, r, r * len, 0.0))) return rc;
        continue;
      }
      rcb_signals_channel(H->sig[f], k, NULL, NULL, &v);
      rcb_hit_triggers(v + r * len, len, level, pre, H->len, NULL, 0, &count, &partial);
      cut += partial;
      if (!count) continue;
      if (!(st = malloc(count * sizeof *st))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
      rcb_hit_triggers(v + r * len, len, level, pre, H->len, st, count, &count, &partial);
      for (i = 0; i < count && !rc; i++)
        rc = add_hit(H, f, r, r * len + st[i], (double)st[i] / rcb_signals_rate(j->sig));
      free(st);
      if (rc) return rc;
    }
  }
  if (cut)
    cli_warn("estimate: %zu crossing%s of the trigger too near the start or the end for a whole "
             "hit (pre-trigger %zu samples, hit %zu): not used", cut, cut > 1 ? "s" : "", pre,
             H->len);
  if (!H->nh)
    return cli_fail(CLI_EXIT_INPUT, "%s: no hit: the force never crosses the trigger level %g N "
                    "(with a whole hit around it)", j->a->model, level);
  return 0;
}

/* --reject N,M,...: hits the user drops, by number (1 = the first listed). */
static int user_rejects(est_hits *H) {
  const char *v = cli_opt_value(H->j->a, "--reject"), *p = v;
  while (p && *p) {
    char *end;
    long k = strtol(p, &end, 10);
    if (end == p || (*end && *end != ',') || k < 1 || (size_t)k > H->nh)
      return cli_usage(H->j->a->cmd, "--reject '%s': expected hit numbers 1 to %zu, comma "
                       "separated", v, H->nh);
    H->h[k - 1].user = 1;
    p = *end ? end + 1 : end;
  }
  return 0;
}

static const double *chan(const est_hits *H, const est_hit *h, size_t c) {
  const double *v;
  rcb_signals_channel(H->sig[h->file], H->idx[h->file * (H->j->p + H->j->q) + c], NULL, NULL, &v);
  return v + h->start;
}

/* Each hit's pulse (double hit) and every channel's overload; which are kept. */
static int check_hits(est_hits *H) {
  est_job *j = H->j;
  double rate = rcb_signals_rate(j->sig);
  int keep = cli_opt_value(j->a, "--keep-flagged") != NULL;
  size_t i, c;
  for (i = 0; i < H->nh; i++) {
    est_hit *h = &H->h[i];
    rcb_hit_overload o;
    if (rcb_hit_pulse_find(chan(H, h, 0), H->len, rate, H->frac, &h->pulse))
      return cli_fail(CLI_EXIT_NUMERIC, "estimate: hit %zu: the pulse check failed", i + 1);
    for (c = 0; c < j->p + j->q; c++) {
      if (rcb_hit_overload_find(chan(H, h, c), H->len, H->clip_run, H->range[c], &o))
        return cli_fail(CLI_EXIT_NUMERIC, "estimate: hit %zu: the overload check failed", i + 1);
      if (o.overload && !h->over.overload) h->over = o, h->over_ch = c;
    }
    h->flagged = h->pulse.double_hit || h->over.overload || h->pulse.peak == 0.0;
    h->kept = !h->user && (!h->flagged || (keep && h->pulse.peak != 0.0));
  }
  return 0;
}

/* Why hit @p h is flagged, in words (empty if it is not). */
static void reasons(const est_hits *H, const est_hit *h, char *buf, size_t size) {
  double rate = rcb_signals_rate(H->j->sig);
  const rcb_hit_overload *o = &h->over;
  size_t n = 0;
  int k = 0;
  buf[0] = '\0';
  if (h->pulse.peak == 0.0) k = snprintf(buf, size, "no force pulse (the force is 0 throughout)");
  if (k > 0) n += (size_t)k;
  if (h->pulse.double_hit && n < size) {
    k = snprintf(buf + n, size - n, "%sa double hit (a second pulse of %.0f %% of the peak at "
                 "%.4g s)", n ? " and " : "", 100.0 * h->pulse.second, h->pulse.second_time);
    if (k > 0) n += (size_t)k;
  }
  if (o->overload && n < size) {
    if (o->at_range)
      snprintf(buf + n, size - n, "%san overload: '%s' reached its --range (%.6g SI at %.4g s)",
               n ? " and " : "", H->j->names[h->over_ch], o->level, (double)o->at / rate);
    else
      snprintf(buf + n, size - n, "%san overload: '%s' clipped (%zu equal samples of %.6g SI "
               "from %.4g s)", n ? " and " : "", H->j->names[h->over_ch], o->run, o->level,
               (double)o->at / rate);
  }
}

static const char *name_of(const est_hits *H, const est_hit *h, char *buf, size_t size) {
  return cli_text(H->j->a->files[h->file], buf, size);
}

/* The per-hit table on stderr. */
static void report_text(const est_hits *H) {
  double rate = rcb_signals_rate(H->j->sig);
  size_t i;
  char nm[40], ch[40];
  fprintf(stderr, "rcbtool: estimate: %zu hits, force '%s'\n", H->nh,
          cli_text(H->j->names[0], ch, sizeof ch));
  fprintf(stderr, "  hit  %-24s  rec  start_s     peak_N     width_ms  2nd_%%  double  "
          "overload              kept\n", "file");
  for (i = 0; i < H->nh; i++) {
    const est_hit *h = &H->h[i];
    char ov[48];
    if (h->over.overload)
      snprintf(ov, sizeof ov, "%s %s", cli_text(H->j->names[h->over_ch], ch, sizeof ch),
               h->over.at_range ? "at range" : "clipped");
    else
      snprintf(ov, sizeof ov, "n");
    fprintf(stderr, "  %3zu  %-24s  %3zu  %-10.6g  %-9.6g  %-8.4g  %-5.1f  %-6s  %-20s  %s\n",
            i + 1, name_of(H, h, nm, sizeof nm), h->rec + 1, h->t, h->pulse.peak,
            1e3 * h->pulse.width, 100.0 * h->pulse.second, h->pulse.double_hit ? "y" : "n", ov,
            h->kept ? "y" : h->user ? "n (--reject)" : "n");
  }
  (void)rate;
}

/* --report FILE: the same as CSV, one row per hit. */
static int report_csv(const est_hits *H, const char *path) {
  cli_out out;
  size_t i;
  int rc;
  char why[400];
  if ((rc = est_side_open(H->j, path, &out))) return rc;
  fputs("hit,file,record,start_s,peak_N,width_s,second_frac,second_s,double_hit,overload,"
        "overload_channel,kept,reason\n", out.fp);
  for (i = 0; i < H->nh; i++) {
    const est_hit *h = &H->h[i];
    fprintf(out.fp, "%zu,", i + 1);
    cli_put_text(out.fp, H->j->a->files[h->file]);
    fprintf(out.fp, ",%zu,", h->rec + 1);
    cli_csv_num(out.fp, h->t);
    fputc(',', out.fp);
    cli_csv_num(out.fp, h->pulse.peak);
    fputc(',', out.fp);
    cli_csv_num(out.fp, h->pulse.width);
    fputc(',', out.fp);
    cli_csv_num(out.fp, h->pulse.second);
    fputc(',', out.fp);
    cli_csv_num(out.fp, h->pulse.second_time);
    fprintf(out.fp, ",%s,%s,", h->pulse.double_hit ? "y" : "n",
            !h->over.overload ? "n" : h->over.at_range ? "at range" : "clipped");
    if (h->over.overload) cli_put_text(out.fp, H->j->names[h->over_ch]);
    reasons(H, h, why, sizeof why);
    fprintf(out.fp, ",%s,%s\n", h->kept ? "y" : "n",
            h->user ? "--reject" : h->flagged ? (h->pulse.double_hit ? "double hit" :
            h->over.overload ? "overload" : "no pulse") : "");
  }
  return cli_out_close(&out);
}

/* Warnings: each flagged hit, dropped or kept, and the force window. */
static void warn_hits(est_hits *H) {
  est_job *j = H->j;
  double fw = ceil(j->o.force_frac * (double)H->len) / rcb_signals_rate(j->sig);
  size_t i, kept = 0, len = 0;
  char why[400], nm[80];
  for (i = 0; i < H->nh; i++) {
    const est_hit *h = &H->h[i];
    kept += h->kept != 0;
    if (h->flagged && !h->user) {
      reasons(H, h, why, sizeof why);
      cli_warn("estimate: hit %zu (%s) %s: %s", i + 1, name_of(H, h, nm, sizeof nm),
               h->kept ? "kept (--keep-flagged)" : "dropped (--keep-flagged keeps it)", why);
    }
    if (h->kept && j->o.window == RCB_WINDOW_FORCE_EXP && h->pulse.end > fw)
      cli_warn("estimate: hit %zu (%s): the force pulse ends at %.4g s, after the force window "
               "(%.4g s, --force-frac): its tail is cut off", i + 1,
               name_of(H, h, nm, sizeof nm), h->pulse.end, fw);
  }
  len = (size_t)snprintf(j->hits_note, sizeof j->hits_note, "hits = %zu of %zu averaged", kept,
                         H->nh);
  for (i = 0; i < H->nh && len + 16 < sizeof j->hits_note; i++)
    if (!H->h[i].kept)
      len += (size_t)snprintf(j->hits_note + len, sizeof j->hits_note - len, "%s%zu",
                              len && strchr(j->hits_note, '(') ? " " : " (dropped: ", i + 1);
  if (strchr(j->hits_note, '(') && len + 2 < sizeof j->hits_note) strcat(j->hits_note, ")");
  if (kept == 1)
    cli_warn("estimate: one hit averaged: its standard deviations need two or more (NaN)");
}

/* The kept hits, one segment each. */
static int feed(est_hits *H) {
  est_job *j = H->j;
  const double **seg = calloc(j->p + j->q, sizeof *seg);
  size_t i, c;
  rcb_status st = RCB_OK;
  int rc;
  if (!seg) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  j->o.nseg = H->len;
  j->o.noverlap = 0;
  if ((rc = est_setup(j))) {
    free(seg);
    return rc;
  }
  for (i = 0; i < H->nh && !st; i++) {
    if (!H->h[i].kept) continue;
    for (c = 0; c < j->p + j->q; c++) seg[c] = chan(H, &H->h[i], c);
    st = rcb_spectral_add_segment(j->e, seg);
  }
  free(seg);
  if (st) return cli_fail(cli_status_exit(st), "%s", cli_msg(rcb_spectral_errmsg(j->e), st));
  return 0;
}

static int run(est_hits *H) {
  est_job *j = H->j;
  const char *report = cli_opt_value(j->a, "--report");
  size_t i, kept = 0;
  int rc;
  if ((rc = cli_opt_nonneg(j->a, "--double-frac", "", 0.1, &H->frac)) ||
      (rc = cli_opt_count(j->a, "--clip-run", 5, &H->clip_run)))
    return rc;
  if (!(H->frac > 0.0 && H->frac < 1.0))
    return cli_usage(j->a->cmd, "--double-frac %g: expected 0 < F < 1", H->frac);
  if (H->clip_run < 2) return cli_usage(j->a->cmd, "--clip-run 1: expected 2 or more");
  if ((rc = ranges(H)) || (rc = read_files(H)) || (rc = list_hits(H)) ||
      (rc = user_rejects(H)) || (rc = check_hits(H)))
    return rc;
  if (H->len < 8)
    return cli_fail(CLI_EXIT_INPUT, "%s: %zu samples per hit: expected at least 8",
                    j->a->model, H->len);
  if (!report) report_text(H);
  warn_hits(H);
  for (i = 0; i < H->nh; i++) kept += H->h[i].kept != 0;
  if (!kept && report) report_text(H);
  if (!kept)
    return cli_fail(CLI_EXIT_INPUT, "estimate: no hit left to average: all %zu were dropped "
                    "(the warnings and the table say why)", H->nh);
  if ((rc = feed(H))) return rc;
  if (report) rc = report_csv(H, report);
  return rc;
}

int est_hits_average(est_job *j) {
  est_hits H;
  size_t f, nc = j->p + j->q;
  int rc;
  memset(&H, 0, sizeof H);
  H.j = j;
  H.nf = j->a->nfiles;
  H.sig = calloc(H.nf, sizeof(rcb_signals *));
  H.idx = calloc(H.nf * nc, sizeof *H.idx);
  H.range = calloc(nc, sizeof *H.range);
  rc = H.sig && H.idx && H.range ? run(&H) : cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (f = 1; H.sig && f < H.nf; f++) rcb_signals_destroy(H.sig[f]);
  free(H.sig);
  free(H.idx);
  free(H.range);
  free(H.h);
  return rc;
}
