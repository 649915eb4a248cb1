/* rcbtool estimate: sampled signals (CSV or WAV) -> FRFs by Welch averaging,
 * with coherence and per-line standard deviations (UFF58 or CSV). */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_estimate.h"

const char cli_help_estimate[] =
    "usage: rcbtool estimate SIGNALS [SIGNALS...] --input CH --outputs CH,... -o OUT [options]\n"
    "\n"
    "Estimates FRFs from sampled signals by Welch averaging: segments of --nseg\n"
    "samples, windowed, overlapping, averaged; H1 (default), H2 or Hv; coherence\n"
    "and the standard deviation of each line from the coherence and the number of\n"
    "averages (Bendat & Piersol). OUT (.uff/.unv: UFF dataset 58; .csv) holds the\n"
    "FRFs as a measurement that compare, fit and diagnose read.\n"
    "Impact tests: the hits are the averages, one segment each (no overlap, the\n"
    "mean kept, --window force-exp unless given) when SIGNALS are several files\n"
    "(one hit each: same channels, rate and length), a UFF file holding several\n"
    "records of each channel (one per hit), or with --trigger on a long recording.\n"
    "Each hit is checked for a double hit and an overload; a per-hit table goes to\n"
    "stderr (or --report FILE); a flagged hit is dropped with a warning.\n"
    "  SIGNALS        .csv: optional '# units = U1,U2,...', header 'time_s,CH1,CH2\n"
    "                 [unit],...', rows of numbers (evenly spaced time, s);\n"
    "                 .uff/.unv: UFF58 time records (function type 1, abscissa 17;\n"
    "                 units from the record-9 label or dataset 164; --map)\n"
    "                 .wav: PCM 16/24/32-bit or float; give --wav-names NAME,...,\n"
    "                 --wav-units U,... and --wav-scale S,... (full scale in that unit)\n"
    "  --units CH=U,...  the unit of channels whose file label is missing or unknown\n"
    "                 (UFF: the channel as named, STATION.DIR or #NODE.DIR)\n"
    "  --allow-truncated read the whole frames of a WAV file cut short (or cut\n"
    "                 mid-frame), with a warning (default: refused with the byte counts)\n"
    "  --input CH     force channel (unit N, kN or lbf); several: CH1,CH2 (H1 only)\n"
    "  --outputs LIST response channels: displacement (m, mm, um, mil), velocity\n"
    "                 (m/s, mm/s, in/s) or acceleration (m/s^2, g)\n"
    "                 Items NAME (a model channel STATION.DIR) or NAME=STATION.DIR\n"
    "                 (file channel NAME is model channel STATION.DIR: a driving\n"
    "                 point has force 'f=DA.x' and response 'DA.x')\n"
    "  --kind K       write receptance, mobility or inertance (default: what the\n"
    "                 first output measures; the others are converted to it)\n"
    "  --nseg N       samples per segment (default 4096; not with hits)\n"
    "  --overlap F    overlap fraction of a segment, 0 <= F < 1 (default 0.5)\n"
    "  --window W     hann (default), flattop, rect, force-exp (impact tests)\n"
    "  --force-frac F force window length / segment (force-exp; default 0.1)\n"
    "  --exp-end E    exponential window's last value (force-exp; default 0.01)\n"
    "  --estimator E  h1 (default), h2 or hv (h2 and hv: one input)\n"
    "  --no-detrend   keep each segment's mean (default: removed, as SciPy)\n"
    "  --rpm R        rotor speed during the test, rpm (default 0)\n"
    "  --fmax HZ      write lines up to HZ only (default: up to Nyquist)\n"
    "  --every N      write every N-th line (default 1). Neighbouring lines of a\n"
    "                 Hann-windowed estimate have correlated errors (H1 of random\n"
    "                 excitation: 0.45, two lines apart 0.03): give 2 where a\n"
    "                 statistic adds lines as independent (monitor, diagnose --sd,\n"
    "                 compare --sd)\n"
    "  --stats FILE   CSV: freq_hz, then per FRF 'OUT/IN coh' and 'OUT/IN sd' (sd of\n"
    "                 Re and of Im, in the written kind's unit)\n"
    "  --spectra FILE CSV: freq_hz and the averaged density spectra G (unit^2/Hz,\n"
    "                 SciPy's csd/welch scaling): 'G IN' per input, 'G IN/OUT re',\n"
    "                 'G IN/OUT im' per pair, 'G OUT' per output\n"
    "  --trigger CH:LEVEL[:PRE]  cut each recording into hits: a hit starts PRE s\n"
    "                 (default 2 % of --hit-length) before each crossing of LEVEL\n"
    "                 by force channel CH (rising for LEVEL > 0, falling below 0;\n"
    "                 N, or with a unit: 20N, 0.1kN, 5lbf); the next crossing is\n"
    "                 looked for after the hit's end (hold-off)\n"
    "  --hit-length S length of a hit, s (with --trigger)\n"
    "  --double-frac F  a second force pulse above F x the peak, after the pulse\n"
    "                 has decayed below min(5 %, F/2) of it, is a double hit\n"
    "                 (default 0.1)\n"
    "  --clip-run N   N or more equal samples at a channel's extreme in a hit are\n"
    "                 clipping: an overload (default 5)\n"
    "  --range CH:MAX,...  a channel's recorder range (SI, or with a unit: 5g,\n"
    "                 2000N): a sample reaching it is an overload\n"
    "  --reject N,... drop these hits (numbered as listed: files in order, their\n"
    "                 records, their triggers)\n"
    "  --keep-flagged keep double hits and overloads (with a warning; default:\n"
    "                 dropped with a warning)\n"
    "  --report FILE  CSV of the per-hit table (hit, file, record, start_s, peak_N,\n"
    "                 width_s, second_frac, second_s, double_hit, overload,\n"
    "                 overload_channel, kept, reason) instead of stderr\n"
    "  --map LIST     UFF node map for SIGNALS and OUT, NODE=STATION,... and\n"
    "                 NODE.DIR=STATION.DIR,... (1.z=DA.x, 3.s=DB.y; as convert); a\n"
    "                 channel no entry names keeps its file name (#1.z, DA.z, #3)\n"
    "  --binary       write binary 58b\n"
    "  --plot FILE    also draw FILE (PNG): magnitude and phase of each FRF with the\n"
    "                 coherence below (Python 3 with matplotlib: RCB_PYTHON, RCB_PLOTS\n"
    "                 as for compare --plot); drawn first, a failed plot writes nothing\n"
    "Files are written atomically. Exit codes: 2 usage, 3 bad signals or units,\n"
    "4 numerical failure, 5 output not written.\n";

static const char *const window_names[] = {"hann", "flattop", "rect", "force-exp"};
static const char *const est_names[] = {"h1", "h2", "hv"};
static const char *const kind_names[] = {"receptance", "mobility", "inertance"};

/* Split "A,B,C" into names (appended to j->names). */
static int split_list(est_job *j, char *list, size_t *count) {
  char *p = list;
  *count = 0;
  while (p) {
    char *comma = strchr(p, ',');
    if (comma) *comma = '\0';
    char *eq = strchr(p, '=');
    if (!*p || eq == p || (eq && !eq[1]))
      return cli_usage(j->a->cmd, "empty channel name in a list (items NAME or NAME=STATION.DIR)");
    if (eq) *eq = '\0';
    j->model[j->p + j->q + *count] = eq ? eq + 1 : p;
    j->names[j->p + j->q + (*count)++] = p;
    p = comma ? comma + 1 : NULL;
    if (j->p + j->q + *count >= EST_MAX_IN + EST_MAX_OUT && p)
      return cli_usage(j->a->cmd, "too many channels (at most 64 inputs, 256 outputs)");
  }
  return 0;
}

static int channels(est_job *j) {
  const char *in = cli_opt_value(j->a, "--input"), *out = cli_opt_value(j->a, "--outputs");
  size_t n, i, total;
  int rc;
  j->buf = malloc(strlen(in) + strlen(out) + 2);
  j->names = calloc(EST_MAX_IN + EST_MAX_OUT, sizeof *j->names);
  j->model = calloc(EST_MAX_IN + EST_MAX_OUT, sizeof *j->model);
  j->idx = calloc(EST_MAX_IN + EST_MAX_OUT, sizeof *j->idx);
  if (!j->buf || !j->names || !j->model || !j->idx) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(j->buf, in);
  strcpy(j->buf + strlen(in) + 1, out);
  if ((rc = split_list(j, j->buf, &n))) return rc;
  if (n > 64) return cli_usage(j->a->cmd, "--input: at most 64 inputs");
  j->p = n;
  if ((rc = split_list(j, j->buf + strlen(in) + 1, &n))) return rc;
  if (n > 256) return cli_usage(j->a->cmd, "--outputs: at most 256 outputs");
  j->q = n;
  total = j->p + j->q;
  for (i = 0; i < total; i++) {
    rcb_quantity q;
    if ((rc = cli_signals_find(j->a, j->sig, j->names[i], &j->idx[i])) ||
        (rc = cli_signals_model_channel(j->a, j->names[i], j->model[i])))
      return rc;
    rcb_signals_channel(j->sig, j->idx[i], NULL, &q, NULL);
    if (i < j->p && q != RCB_QTY_FORCE)
      return cli_fail(CLI_EXIT_INPUT, "%s: input channel '%s' is %s; expected a force (N, kN or "
                      "lbf): give its unit in the file ('%s [N]' or '# units = ...')",
                      j->a->model, j->names[i], rcb_quantity_name(q), j->names[i]);
    if (i >= j->p && (q < RCB_QTY_DISPLACEMENT || q > RCB_QTY_ACCELERATION))
      return cli_fail(CLI_EXIT_INPUT, "%s: output channel '%s' is %s; expected a displacement, "
                      "velocity or acceleration (m, mm, um, m/s, m/s^2, g, ...): give its unit "
                      "in the file", j->a->model, j->names[i], rcb_quantity_name(q));
    if (i >= j->p) j->meas_kind[i - j->p] = (rcb_frf_kind)(q - RCB_QTY_DISPLACEMENT);
  }
  return 0;
}

static int options(est_job *j) {
  const cli_args *a = j->a;
  double overlap = 0.5, ff = 0.1, ee = 0.01;
  int w = 0, e = 0, rc;
  size_t nseg = 4096;
  if ((rc = cli_opt_require(a, "--input", "the force channel, e.g. --input C.B.y")) ||
      (rc = cli_opt_require(a, "--outputs", "the response channels, e.g. --outputs DA.x,DA.y")) ||
      (rc = cli_opt_count(a, "--nseg", 4096, &nseg)) ||
      (rc = cli_opt_nonneg(a, "--overlap", "", 0.5, &overlap)) ||
      (rc = cli_opt_choice(a, "--window", window_names, 4, 0, &w)) ||
      (rc = cli_opt_choice(a, "--estimator", est_names, 3, 0, &e)) ||
      (rc = cli_opt_choice(a, "--kind", kind_names, 3, -1, &j->kind)) ||
      (rc = cli_opt_nonneg(a, "--force-frac", "", 0.1, &ff)) ||
      (rc = cli_opt_nonneg(a, "--exp-end", "", 0.01, &ee)))
    return rc;
  if (overlap >= 1.0) return cli_usage(a->cmd, "--overlap %g: expected 0 <= F < 1", overlap);
  if (nseg < 8) return cli_usage(a->cmd, "--nseg %zu: expected at least 8", nseg);
  if (ff <= 0.0 || ff > 1.0 || ee <= 0.0 || ee >= 1.0)
    return cli_usage(a->cmd, "--force-frac in (0, 1] and --exp-end in (0, 1) expected");
  memset(&j->o, 0, sizeof j->o);
  j->o.nseg = nseg;
  j->o.noverlap = (size_t)floor(overlap * (double)nseg);
  j->o.window = (rcb_window)w;
  j->o.force_frac = ff;
  j->o.exp_end = ee;
  j->o.no_detrend = cli_opt_value(a, "--no-detrend") != NULL;
  j->window_given = cli_opt_value(a, "--window") != NULL;
  j->est = (rcb_estimator)e;
  return 0;
}

int est_setup(est_job *j) {
  size_t bytes = 0;
  rcb_status st;
  j->o.ninputs = j->p;
  j->o.noutputs = j->q;
  j->o.rate = rcb_signals_rate(j->sig);
  st = rcb_spectral_workspace_size(&j->o, &bytes);
  if (st) {
    if (st == RCB_ERR_UNSUPPORTED)
      return cli_fail(CLI_EXIT_NUMERIC, "estimate: librcb was built without an FFT backend "
                      "(RCB_WITH_FFTW or RCB_WITH_KISSFFT)");
    return cli_fail(cli_status_exit(st), "estimate: %s", rcb_status_str(st));
  }
  j->work = malloc(bytes);
  if (!j->work || rcb_spectral_init(&j->e, &j->o, j->work, bytes))
    return cli_fail(CLI_EXIT_NUMERIC, "estimate: cannot set up the estimator (%zu bytes)", bytes);
  return 0;
}

/* Feed the segments (progress on long files). */
static int average(est_job *j) {
  size_t n = rcb_signals_length(j->sig), step = j->o.nseg - j->o.noverlap, start, c, nseg;
  const double **seg;
  cli_progress pr;
  size_t done = 0;
  rcb_status st = RCB_OK;
  int rc;
  if (n < j->o.nseg)
    return cli_fail(CLI_EXIT_INPUT, "%s: %zu samples, fewer than one segment (--nseg %zu)",
                    j->a->model, n, j->o.nseg);
  if ((rc = est_setup(j))) return rc;
  if (!(seg = calloc(j->p + j->q, sizeof *seg))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  nseg = (n - j->o.noverlap) / step;
  cli_progress_start(&pr, j->a, "estimate", "segments", nseg);
  for (start = 0; start + j->o.nseg <= n; start += step) {
    for (c = 0; c < j->p + j->q; c++) {
      const double *v;
      rcb_signals_channel(j->sig, j->idx[c], NULL, NULL, &v);
      seg[c] = v + start;
    }
    if ((st = rcb_spectral_add_segment(j->e, seg))) break;
    cli_progress_step(&pr, ++done);
  }
  cli_progress_end(&pr);
  free(seg);
  if (st) return cli_fail(cli_status_exit(st), "%s", cli_msg(rcb_spectral_errmsg(j->e), st));
  return 0;
}

/* Lines written: 1 (DC has no FRF after detrending) up to --fmax, every
 * --every-th of them (*every). */
static int line_range(est_job *j, size_t *k1, size_t *every) {
  double fmax = 0.0, df = rcb_signals_rate(j->sig) / (double)j->o.nseg;
  size_t nb = rcb_spectral_bin_count(j->e);
  int rc;
  if ((rc = cli_opt_nonneg(j->a, "--fmax", "Hz", 0.0, &fmax)) ||
      (rc = cli_opt_count(j->a, "--every", 1, every)))
    return rc;
  *k1 = nb;
  if (fmax > 0.0) *k1 = (size_t)floor(fmax / df) + 1;
  if (*k1 > nb) *k1 = nb;
  if (*k1 < 2) return cli_usage(j->a->cmd, "--fmax %g Hz is below the first line (%g Hz)", fmax, df);
  return 0;
}

/* h (and sd) of output o from the measured kind to the written one: (i w)^d. */
static void to_kind(rcb_complex *h, double *sd, const double *w, size_t n, int d) {
  size_t k;
  for (k = 0; k < n; k++) {
    rcb_complex f = 1.0;
    int i;
    for (i = 0; i < (d > 0 ? d : -d); i++) f *= w[k] * (rcb_complex)_Complex_I;
    if (d < 0) f = 1.0 / f;
    h[k] *= f;
    sd[k] *= cabs(f);
  }
}

typedef struct est_out {
  size_t n;       /* lines written (1 .. k1 - 1) */
  double *w;      /* nb */
  rcb_complex *h; /* pairs * nb */
  double *coh, *sd;
} est_out;

/* --every N: lines 1, 1 + N, 1 + 2N, ... moved to 1, 2, 3, ... in every
 * array (the pairs keep their stride nb). */
static void thin_lines(est_out *r, size_t nb, size_t np, size_t every) {
  size_t c, i, n = every > 1 ? (r->n + every - 1) / every : r->n;
  for (i = 1; i < n; i++) {
    size_t from = 1 + i * every;
    r->w[1 + i] = r->w[from];
    for (c = 0; c < np; c++) {
      r->h[c * nb + 1 + i] = r->h[c * nb + from];
      r->coh[c * nb + 1 + i] = r->coh[c * nb + from];
      r->sd[c * nb + 1 + i] = r->sd[c * nb + from];
    }
  }
  r->n = n;
}

static int compute(est_job *j, est_out *r, size_t k1) {
  size_t nb = rcb_spectral_bin_count(j->e), o, i, np = j->p * j->q;
  int kind = j->kind >= 0 ? j->kind : (int)j->meas_kind[0];
  r->n = k1 - 1;
  r->w = malloc(nb * sizeof *r->w);
  r->h = malloc(np * nb * sizeof *r->h);
  r->coh = malloc(np * nb * sizeof *r->coh);
  r->sd = malloc(np * nb * sizeof *r->sd);
  if (!r->w || !r->h || !r->coh || !r->sd) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  rcb_spectral_frequencies(j->e, r->w);
  j->kind = kind;
  for (o = 0; o < j->q; o++)
    for (i = 0; i < j->p; i++) {
      size_t at = (o * j->p + i) * nb;
      rcb_status st = rcb_spectral_frf(j->e, j->est, o, i, r->h + at, r->coh + at, r->sd + at);
      if (st) return cli_fail(cli_status_exit(st), "%s", cli_msg(rcb_spectral_errmsg(j->e), st));
      to_kind(r->h + at, r->sd + at, r->w, nb, kind - (int)j->meas_kind[o]);
    }
  return 0;
}

static int write_meas(est_job *j, const est_out *r) {
  size_t nb = rcb_spectral_bin_count(j->e), o, i;
  double rpm = 0.0;
  rcb_meas *ms = NULL;
  rcb_status st;
  cli_uff_map mp;
  int rc, is_uff = 0;
  if ((rc = cli_opt_double(j->a, "--rpm", "rpm", 0.0, &rpm)) ||
      (rc = cli_meas_format(j->a->cmd, j->a->output, &is_uff)))
    return rc;
  if (rcb_meas_create(&ms, NULL)) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  st = rcb_meas_set_grid(ms, RCB_MEAS_FRF, r->n, r->w + 1, fabs(rpm) * CLI_RPM_TO_RAD_S);
  for (o = 0; !st && o < j->q; o++)
    for (i = 0; !st && i < j->p; i++)
      st = rcb_meas_add_channel(ms, j->model[j->p + o], j->model[i], (rcb_frf_kind)j->kind,
                                r->h + (o * j->p + i) * nb + 1);
  if (st) {
    rc = cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "estimate: %s",
                  cli_msg(rcb_meas_errmsg(ms), st));
    rcb_meas_destroy(ms);
    return rc;
  }
  if ((rc = cli_uff_map_parse(j->a, "--map", NULL, &mp)) == 0)
    rc = cli_meas_write(j->a->cmd, ms, j->a->output, cli_opt_value(j->a, "--binary") != NULL,
                        &mp);
  cli_uff_map_free(&mp);
  rcb_meas_destroy(ms);
  return rc;
}

/* Open a side file (--stats, --spectra, --report) atomically through cli_out. */
int est_side_open(const est_job *j, const char *path, cli_out *out) {
  cli_args b = *j->a;
  b.output = path;
  return cli_out_open(out, &b);
}

static int write_stats(est_job *j, const est_out *r, const char *path) {
  size_t nb = rcb_spectral_bin_count(j->e), k, c, np = j->p * j->q;
  cli_out out;
  int rc;
  if ((rc = est_side_open(j, path, &out))) return rc;
  fprintf(out.fp, "# estimator = %s, averages = %zu, nseg = %zu, overlap = %zu, window = %s, "
          "kind = %s\n", est_names[j->est], rcb_spectral_averages(j->e), j->o.nseg,
          j->o.noverlap, window_names[j->o.window], kind_names[j->kind]);
  if (j->hits_note[0]) fprintf(out.fp, "# %s\n", j->hits_note);
  fputs("freq_hz", out.fp);
  for (c = 0; c < np; c++)
    fprintf(out.fp, ",%s/%s coh,%s/%s sd", j->model[j->p + c / j->p], j->model[c % j->p],
            j->model[j->p + c / j->p], j->model[c % j->p]);
  fputc('\n', out.fp);
  for (k = 1; k <= r->n; k++) {
    cli_csv_num(out.fp, r->w[k] / CLI_HZ_TO_RAD_S);
    for (c = 0; c < np; c++) {
      fputc(',', out.fp);
      cli_csv_num(out.fp, r->coh[c * nb + k]);
      fputc(',', out.fp);
      cli_csv_num(out.fp, r->sd[c * nb + k]);
    }
    fputc('\n', out.fp);
  }
  return cli_out_close(&out);
}

static int write_spectra(est_job *j, const char *path) {
  size_t nb = rcb_spectral_bin_count(j->e), k, a, b, nc = j->p + j->q;
  rcb_complex *g = malloc(nc * nc * nb * sizeof *g);
  double *w = malloc(nb * sizeof *w); /* every bin (r->w holds the written lines) */
  cli_out out;
  int rc;
  if (!g || !w) {
    free(g);
    free(w);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  rcb_spectral_frequencies(j->e, w);
  for (a = 0; a < nc; a++)
    for (b = 0; b < nc; b++)
      if (a < j->p || a == b) rcb_spectral_cross(j->e, a, b, g + (a * nc + b) * nb);
  if ((rc = est_side_open(j, path, &out))) {
    free(g);
    free(w);
    return rc;
  }
  fputs("freq_hz", out.fp);
  for (a = 0; a < nc; a++) fprintf(out.fp, ",G %s", j->names[a]);
  for (a = 0; a < j->p; a++)
    for (b = a + 1; b < nc; b++)
      fprintf(out.fp, ",G %s/%s re,G %s/%s im", j->names[a], j->names[b], j->names[a],
              j->names[b]);
  fputc('\n', out.fp);
  for (k = 0; k < nb; k++) {
    cli_csv_num(out.fp, w[k] / CLI_HZ_TO_RAD_S);
    for (a = 0; a < nc; a++) {
      fputc(',', out.fp);
      cli_csv_num(out.fp, creal(g[(a * nc + a) * nb + k]));
    }
    for (a = 0; a < j->p; a++)
      for (b = a + 1; b < nc; b++) {
        fputc(',', out.fp);
        cli_csv_num(out.fp, creal(g[(a * nc + b) * nb + k]));
        fputc(',', out.fp);
        cli_csv_num(out.fp, cimag(g[(a * nc + b) * nb + k]));
      }
    fputc('\n', out.fp);
  }
  free(g);
  free(w);
  return cli_out_close(&out);
}

typedef struct est_plot {
  const est_job *j;
  const est_out *r;
} est_plot;

/* --plot: the written lines as rcb_plots.py estimate reads them. */
static void plot_json(FILE *fp, const void *ctx) {
  const est_plot *pc = ctx;
  const est_job *j = pc->j;
  const est_out *r = pc->r;
  size_t nb = rcb_spectral_bin_count(j->e), c, k, np = j->p * j->q;
  double *f = malloc((r->n ? r->n : 1) * sizeof *f);
  double *re = malloc((r->n ? r->n : 1) * 2 * sizeof *re);
  char name[256];
  if (!f || !re) {
    free(f);
    free(re);
    return; /* an empty file: the plotter refuses it */
  }
  for (k = 0; k < r->n; k++) f[k] = r->w[k + 1] / CLI_HZ_TO_RAD_S;
  fprintf(fp, "{\"kind\": \"%s\", \"estimator\": \"%s\", \"averages\": %zu, \"freq_hz\": ",
          kind_names[j->kind], est_names[j->est], rcb_spectral_averages(j->e));
  cli_json_nums(fp, f, r->n, 1);
  fputs(",\n\"channels\": [", fp);
  for (c = 0; c < np; c++) {
    const rcb_complex *h = r->h + c * nb + 1;
    snprintf(name, sizeof name, "%s/%s", j->model[j->p + c / j->p], j->model[c % j->p]);
    fputs(c ? ",\n {\"name\": " : "\n {\"name\": ", fp);
    cli_json_str(fp, name);
    for (k = 0; k < r->n; k++) re[2 * k] = creal(h[k]), re[2 * k + 1] = cimag(h[k]);
    fputs(", \"re\": ", fp);
    cli_json_nums(fp, re, r->n, 2);
    fputs(", \"im\": ", fp);
    cli_json_nums(fp, re + 1, r->n, 2);
    fputs(", \"coh\": ", fp);
    cli_json_nums(fp, r->coh + c * nb + 1, r->n, 1);
    fputs(", \"sd\": ", fp);
    cli_json_nums(fp, r->sd + c * nb + 1, r->n, 1);
    fputs("}", fp);
  }
  fputs("]}\n", fp);
  free(f);
  free(re);
}

static int estimate(const cli_args *a) {
  est_job j;
  est_out r;
  size_t k1 = 0, every = 1;
  int is_uff = 0;
  const char *stats = cli_opt_value(a, "--stats"), *spectra = cli_opt_value(a, "--spectra");
  const char *plot = cli_opt_value(a, "--plot");
  int rc;
  memset(&j, 0, sizeof j);
  memset(&r, 0, sizeof r);
  j.a = a;
  j.kind = -1;
  if (!a->output)
    return cli_usage(a->cmd, "missing -o OUT (.uff, .unv or .csv) for the estimated FRFs");
  if ((rc = options(&j)) || (rc = cli_meas_format(a->cmd, a->output, &is_uff))) return rc;
  if (rcb_signals_create(&j.sig, NULL)) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  rcb_signals_set_join_records(j.sig, 1); /* a UFF file's records of a channel: its hits */
  rc = cli_signals_read(a, j.sig);
  if (!rc) rc = channels(&j);
  if (!rc && j.est != RCB_EST_H1 && j.p != 1)
    rc = cli_usage(a->cmd, "--estimator %s takes one input (%zu given); use h1",
                   est_names[j.est], j.p);
  if (!rc) rc = est_hits_options(&j, est_hits_mode(&j));
  if (!rc) rc = est_hits_mode(&j) ? est_hits_average(&j) : average(&j);
  if (!rc) rc = line_range(&j, &k1, &every);
  if (!rc) rc = compute(&j, &r, k1);
  if (!rc) thin_lines(&r, rcb_spectral_bin_count(j.e), j.p * j.q, every);
  if (!rc && plot) { /* first: a failed plot leaves no output */
    est_plot pc = {&j, &r};
    rc = cli_plot_write("estimate", plot, plot_json, &pc,
                        "no output file was written (run without --plot for the estimate alone)");
  }
  if (!rc && stats) rc = write_stats(&j, &r, stats);
  if (!rc && spectra) rc = write_spectra(&j, spectra);
  if (!rc) rc = write_meas(&j, &r);
  if (j.e) rcb_spectral_release(j.e);
  free(j.work);
  free(r.w);
  free(r.h);
  free(r.coh);
  free(r.sd);
  free(j.buf);
  free(j.names);
  free(j.model);
  free(j.idx);
  rcb_signals_destroy(j.sig);
  return rc;
}

int cmd_estimate(int argc, char **argv) {
  cli_opt opts[] = {{"--input", "CH", NULL},      {"--outputs", "LIST", NULL},
                    {"--kind", "KIND", NULL},     {"--nseg", "N", NULL},
                    {"--overlap", "F", NULL},     {"--window", "W", NULL},
                    {"--force-frac", "F", NULL},  {"--exp-end", "E", NULL},
                    {"--estimator", "E", NULL},   {"--no-detrend", NULL, NULL},
                    {"--rpm", "R", NULL},         {"--fmax", "HZ", NULL},
                    {"--every", "N", NULL},
                    {"--stats", "FILE", NULL},    {"--spectra", "FILE", NULL},
                    {"--map", "NODE=STATION,...", NULL}, {"--binary", NULL, NULL},
                    {"--wav-names", "LIST", NULL}, {"--wav-units", "LIST", NULL},
                    {"--wav-scale", "LIST", NULL}, {"--plot", "FILE.png", NULL},
                    {"--units", "CH=UNIT,...", NULL}, {"--allow-truncated", NULL, NULL},
                    {"--trigger", "CH:LEVEL[:PRE]", NULL}, {"--hit-length", "S", NULL},
                    {"--double-frac", "F", NULL}, {"--clip-run", "N", NULL},
                    {"--range", "CH:MAX,...", NULL}, {"--reject", "N,...", NULL},
                    {"--keep-flagged", NULL, NULL}, {"--report", "FILE", NULL}};
  static const cli_file_opt files[] = {{"--stats", CLI_IO_OUT},
                                       {"--spectra", CLI_IO_OUT},
                                       {"--plot", CLI_IO_OUT | CLI_IO_MKDIR},
                                       {"--report", CLI_IO_OUT}};
  cli_args a;
  int rc;
  cli_plan_options(files, sizeof files / sizeof files[0]);
  rc = cli_parse_files(argc, argv, opts, sizeof opts / sizeof opts[0], CLI_FILES_MAX, &a);
  if (rc || a.help) return rc ? rc : cli_print_help(cli_help_estimate);
  if (a.json) return cli_usage(a.cmd, "--json does not apply: the format follows OUT's extension");
  return estimate(&a);
}
