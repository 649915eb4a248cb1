/* rcbtool compare: where does the model fail? Per-channel errors, the worst
 * frequency bands, the peak table (measured resonances vs model modes), as
 * text or JSON; --plot draws the overlay and the residual map through
 * tools/python/rcb_plots.py (matplotlib). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"

const char cli_help_compare[] =
    "usage: rcbtool compare MODEL.ini MEAS.uff|MEAS.unv|MEAS.csv [--map NODE=STATION,...]\n"
    "                       [--rpm R] [--bands N] [--worst N] [--prominence DB] [--tol PCT]\n"
    "                       [--sd STATS.csv] [--plot PREFIX] [--json] [-o FILE]\n"
    "\n"
    "Compares the model with a measurement (FRFs at a rotor speed, synchronous FRFs,\n"
    "or unbalance responses over speed): the model is evaluated at every measured\n"
    "point, as the measured kind (receptance, mobility, inertance).\n"
    "  --map LIST       UFF node number <-> model station, e.g. 10=DA,20=C.A, added to\n"
    "                   the model's [uff] map; nodes without one read as \"#N\" (warned);\n"
    "                   a CSV's numeric stations (2.x/11.x_re) map through it too;\n"
    "                   NODE.DIR=STATION.DIR maps one channel in any direction\n"
    "                   (1.z=DA.x: an accelerometer's own z; 3.s=DB.y: a scalar)\n"
    "  --rpm R          rotor speed of an FRF test, rpm (default: the file's, else the\n"
    "                   model's [test] rpm, else 0 with a warning)\n"
    "  --sd FILE        standard deviations of the measured values (the --stats file\n"
    "                   of rcbtool estimate or order): adds each channel's noise floor\n"
    "                   % and chi-square per degree of freedom (about 1 when the model\n"
    "                   agrees with the measurement to within its noise)\n"
    "  --bands N        frequency bands of the residual map (default 10)\n"
    "  --worst N        bands listed as the worst (default 3)\n"
    "  --prominence DB  a measured resonance stands at least DB above the higher of\n"
    "                   its two bounding minima of the channel-summed magnitude\n"
    "                   (default 2; lower finds shoulders, and noise)\n"
    "  --tol PCT        a measured peak and a model mode pair within PCT % of the\n"
    "                   measured frequency (default 10)\n"
    "  --plot PREFIX    also write PREFIX_overlay.png (measured vs model magnitude and\n"
    "                   phase per channel, worst bands shaded), PREFIX_residual_map.png\n"
    "                   and the JSON they are drawn from, PREFIX_compare.json; needs\n"
    "                   Python 3 with matplotlib (RCB_PYTHON = the interpreter, default\n"
    "                   python3; RCB_PLOTS = the path of rcb_plots.py)\n"
    "\n"
    "Prints per channel: the paper's error % (100 ||(|m| - |e|)|| / || |e| ||), FRAC\n"
    "(|sum conj(e) m|^2 / (sum |e|^2 sum |m|^2); 1 = same shape), RMS log10 magnitude\n"
    "error (decades) and RMS phase error (deg); the mean CSAC and CSF across channels;\n"
    "the worst bands with their worst channel; the peak table: each measured\n"
    "resonance (frequency, half-power damping ratio) with the paired model mode\n"
    "(damped modes at the test speed for FRFs; 1X critical speeds for unbalance data\n"
    "and synchronous FRFs): frequency error % (mode wd and the model's own peak),\n"
    "damping error %, measured/model amplitude ratio; measured peaks without a model\n"
    "mode and model modes without a measured peak are named as such.\n"
    "A sensor (a response over all its references) whose error % exceeds\n"
    "max(2 x the median of the other sensors', median + 6 x 1.4826 x their MAD) and\n"
    "1 % is named with a line \"check this sensor (gain, phase, mounting) before the\n"
    "model\" (at least 4 sensors); with --sd, its chi2/dof against 4 x the median,\n"
    "the MAD term and its own 0.999 chi-square limit. A sensor with several\n"
    "references that stands out on one channel only has that channel named instead\n"
    "(against the other channels: its cable, connector or reference).\n"
    "Abscissa on output: Hz for FRFs, rpm for unbalance responses.\n"
    "JSON: {\"type\", \"x_unit\", \"x\": [...], \"rpm\", \"summary\": {...}, \"channels\":\n"
    "[{\"response\", \"reference\", \"kind\", \"error_pct\", \"frac\", \"log_rms\",\n"
    "\"phase_rms_deg\", \"floor_pct\", \"chi2_dof\" (null without --sd), \"meas_re\",\n"
    "\"meas_im\", \"model_re\", \"model_im\"}], \"outliers\": [{\"response\", \"reference\",\n"
    "\"error_pct\", \"others_lo\", \"others_hi\", \"by_chi2\", \"chi2_dof\", \"chi2_lo\",\n"
    "\"chi2_hi\", \"threshold\"}], \"csac\",\n"
    "\"csf\", \"bands\": [{\"lo\", \"hi\", \"first\", \"count\", \"rms\"}], \"residual_map\":\n"
    "[[per band] per channel], \"worst_bands\": [...], \"peaks\": [{\"match\", ...}]}\n"
    "Exit codes: 2 usage, 3 bad model or measurement (a channel the model does not\n"
    "know), 4 numerical failure, 5 output or plots not written.\n";

typedef struct cmp_job {
  const char *meas_path, *plot;
  size_t bands, worst;
  double prom_db, tol_pct;
  double xscale; /* output abscissa per rad/s: Hz or rpm */
  const char *xunit;
} cmp_job;

static int parse_job(const cli_args *a, cmp_job *j) {
  int rc;
  if ((rc = cli_opt_count(a, "--bands", 10, &j->bands)) ||
      (rc = cli_opt_count(a, "--worst", 3, &j->worst)) ||
      (rc = cli_opt_double(a, "--prominence", "dB", 2.0, &j->prom_db)) ||
      (rc = cli_opt_double(a, "--tol", "%", 10.0, &j->tol_pct)))
    return rc;
  if (j->bands > 1000)
    return cli_usage(a->cmd, "option --bands %zu: expected 1 to 1000", j->bands);
  if (!(j->prom_db > 0))
    return cli_usage(a->cmd, "option --prominence %g: expected a value > 0 dB (e.g. 3)",
                     j->prom_db);
  if (!(j->tol_pct > 0 && j->tol_pct <= 100))
    return cli_usage(a->cmd, "option --tol %g: expected a percentage in (0, 100]", j->tol_pct);
  j->plot = cli_opt_value(a, "--plot");
  if (j->plot && *j->plot == '\0')
    return cli_usage(a->cmd, "option --plot expects a file name prefix, e.g. out/run1");
  return 0;
}

/* ---- reporting helpers ---- */

static const char *kind_name(rcb_frf_kind k) {
  return k == RCB_MOBILITY ? "mobility" : k == RCB_INERTANCE ? "inertance" : "receptance";
}

static const char *match_name(rcb_peak_match m) {
  return m == RCB_PEAK_MATCHED ? "matched"
         : m == RCB_PEAK_MEASURED_ONLY ? "measured_only"
                                       : "model_only";
}

/* RMS over channels of one band's cells (NaN cells left out). */
static double band_rms(const rcb_compare *c, size_t b) {
  size_t k, nch = rcb_compare_channel_count(c), n = 0;
  const double *map = rcb_compare_residual_map(c);
  double s = 0.0;
  for (k = 0; k < nch; k++) {
    double v = map[k + nch * b];
    if (!isfinite(v)) continue;
    s += v * v;
    n++;
  }
  return n ? sqrt(s / (double)n) : (double)NAN;
}

/* Band indices by decreasing RMS (NaN last). */
static void band_order(const rcb_compare *c, size_t *ord) {
  size_t nb = rcb_compare_band_count(c), i, j;
  for (i = 0; i < nb; i++) ord[i] = i;
  for (i = 1; i < nb; i++) {
    size_t t = ord[i];
    double vt = band_rms(c, t);
    for (j = i; j > 0; j--) {
      double vp = band_rms(c, ord[j - 1]);
      if (!(isnan(vp) || (isfinite(vt) && vt > vp))) break;
      ord[j] = ord[j - 1];
    }
    ord[j] = t;
  }
}

/* ---- text ---- */

static void print_channels(FILE *fp, const rcb_compare *c) {
  size_t k, nch = rcb_compare_channel_count(c);
  rcb_compare_summary s;
  rcb_compare_get_summary(c, &s);
  fprintf(fp, "overall: error %.3g %%, mean FRAC %.4f, RMS log10 error %.3g (factor %.3g), "
          "RMS phase error %.3g deg, mean CSAC %.4f, mean CSF %.4f\n\n",
          s.error_pct, s.frac_mean, s.log_rms, pow(10.0, s.log_rms), s.phase_rms_deg,
          s.csac_mean, s.csf_mean);
  if (!isnan(s.chi2_dof))
    fprintf(fp, "noise (--sd): floor %.3g %% (the error the standard deviations alone "
            "explain), chi-square per degree of freedom %.4g (about 1 at the noise)\n\n",
            s.floor_pct, s.chi2_dof);
  fprintf(fp, "%-14s %-14s %-10s %10s %8s %9s %10s", "channel", "reference", "kind",
          "error_%", "FRAC", "log_rms", "phase_deg");
  if (!isnan(s.chi2_dof)) fprintf(fp, " %9s %10s", "floor_%", "chi2/dof");
  fputc('\n', fp);
  for (k = 0; k < nch; k++) {
    rcb_compare_channel ch;
    rcb_compare_get_channel(c, k, &ch);
    fprintf(fp, "%-14s %-14s %-10s %10.4g %8.4f %9.4f %10.3g", ch.response,
            ch.reference ? ch.reference : "-", kind_name(ch.kind), ch.error_pct, ch.frac,
            ch.log_rms, ch.phase_rms_deg);
    if (!isnan(s.chi2_dof)) fprintf(fp, " %9.4g %10.4g", ch.floor_pct, ch.chi2_dof);
    fputc('\n', fp);
  }
}

/* One line per sensor or channel whose misfit stands out (rcb_compare_outlier). */
static void print_outliers(FILE *fp, const rcb_compare *c) {
  size_t i, n = rcb_compare_outlier_count(c);
  for (i = 0; i < n; i++) {
    rcb_compare_outlier o;
    rcb_compare_get_outlier(c, i, &o);
    fputs(i ? "" : "\n", fp);
    if (o.reference)
      fprintf(fp, "%s/%s: ", o.response, o.reference);
    else
      fprintf(fp, "%s: ", o.response);
    if (o.by_chi2)
      fprintf(fp, "chi2/dof %.3g where the other %s are %.3g-%.3g (error %.3g %%, the others "
              "%.3g-%.3g %%)", o.chi2_dof, o.reference ? "channels" : "sensors", o.chi2_lo,
              o.chi2_hi, o.error_pct, o.others_lo, o.others_hi);
    else
      fprintf(fp, "%.3g %% where the other %s are %.3g-%.3g %%", o.error_pct,
              o.reference ? "channels" : "sensors", o.others_lo, o.others_hi);
    fprintf(fp, ": check this %s before the model\n",
            o.reference ? "channel (cable, connector, reference)"
                        : "sensor (gain, phase, mounting)");
  }
}

static void print_bands(FILE *fp, const rcb_compare *c, const cmp_job *j, const size_t *ord) {
  size_t nb = rcb_compare_band_count(c), nch = rcb_compare_channel_count(c), r, k;
  const double *map = rcb_compare_residual_map(c);
  fprintf(fp, "\nworst bands (RMS log10 magnitude error over channels; %zu bands):\n", nb);
  fprintf(fp, "%-5s %12s %12s %9s  %s\n", "rank", "from", "to", "log_rms", "worst channel");
  for (r = 0; r < nb && r < j->worst; r++) {
    size_t b = ord[r], wk = 0;
    double lo, hi;
    rcb_compare_channel ch;
    rcb_compare_band(c, b, &lo, &hi, NULL, NULL);
    for (k = 1; k < nch; k++)
      if (map[k + nch * b] > map[wk + nch * b] || isnan(map[wk + nch * b])) wk = k;
    rcb_compare_get_channel(c, wk, &ch);
    fprintf(fp, "%-5zu %8.4g %-3s %8.4g %-3s %9.4f  %s%s%s (%.4f)\n", r + 1, lo * j->xscale,
            j->xunit, hi * j->xscale, j->xunit, band_rms(c, b), ch.response,
            ch.reference ? "/" : "", ch.reference ? ch.reference : "", map[wk + nch * b]);
  }
}

static void print_peaks(FILE *fp, const rcb_compare *c, const cmp_job *j) {
  size_t p, np = rcb_compare_peak_count(c), hidden = 0;
  fprintf(fp, "\npeaks (measured resonances vs model %s, pairing within %g %%):\n",
          rcb_compare_type(c) == RCB_MEAS_FRF ? "modes" : "1X critical speeds", j->tol_pct);
  if (np == 0) {
    fprintf(fp, "  none: no prominent measured resonance and no model mode in the range\n");
    return;
  }
  fprintf(fp, "%-14s %10s %9s %10s %9s %9s %9s %9s %9s  %s\n", "match", "meas", "zeta",
          "model", "zeta", "freq_%", "peak_%", "zeta_%", "amp_ratio", "channel");
  for (p = 0; p < np; p++) {
    rcb_compare_peak r;
    rcb_compare_channel ch;
    rcb_compare_get_peak(c, p, &r);
    rcb_compare_get_channel(c, r.channel, &ch);
    if (r.match == RCB_PEAK_MODEL_ONLY) {
      if (!r.model_visible) {
        hidden++;
        continue;
      }
      fprintf(fp, "%-14s %10s %9s %10.5g %9.4f %9s %9s %9s %9s  %s\n", "model_only", "-", "-",
              r.model_freq * j->xscale, r.model_zeta, "-", "-", "-", "-",
              "<- no measured peak; the model shows one in these channels");
      continue;
    }
    fprintf(fp, "%-14s %10.5g %9.4f ", match_name(r.match), r.meas_freq * j->xscale,
            r.meas_zeta);
    if (r.match == RCB_PEAK_MATCHED)
      fprintf(fp, "%10.5g %9.4f %9.3g %9.3g %9.3g ", r.model_freq * j->xscale, r.model_zeta,
              r.freq_err_pct, r.peak_err_pct, r.zeta_err_pct);
    else
      fprintf(fp, "%10s %9s %9s %9s %9s ", "-", "-", "-", "-", "-");
    fprintf(fp, "%9.3g  %s%s%s%s\n", r.amp_ratio, ch.response, ch.reference ? "/" : "",
            ch.reference ? ch.reference : "",
            r.match == RCB_PEAK_MEASURED_ONLY ? "  <- no model mode within the tolerance" : "");
  }
  if (hidden) {
    fprintf(fp, "model modes in the range that neither the measurement nor the model's own "
            "response shows in these channels (%zu):", hidden);
    for (p = 0; p < np; p++) {
      rcb_compare_peak r;
      rcb_compare_get_peak(c, p, &r);
      if (r.match == RCB_PEAK_MODEL_ONLY && !r.model_visible)
        fprintf(fp, " %.5g", r.model_freq * j->xscale);
    }
    fprintf(fp, " %s\n", j->xunit);
  }
  fprintf(fp, "(abscissa in %s; freq_%%: 100 (model wd - measured)/measured; peak_%%: the "
          "model's own peak instead of wd; zeta_%%: 100 (model - measured)/measured; "
          "amp_ratio: measured/model at the measured peak)\n", j->xunit);
}

static void print_text(FILE *fp, const cli_args *a, const cmp_job *j, const rcb_meas *ms,
                       const rcb_compare *c, const size_t *ord) {
  fputs("# rcbtool compare: ", fp); /* file names escaped (cli_text.c) */
  cli_put_text(fp, a->model);
  fputs(" vs ", fp);
  cli_put_text(fp, j->meas_path);
  fputc('\n', fp);
  if (rcb_meas_get_type(ms) == RCB_MEAS_UNBALANCE)
    fprintf(fp, "# unbalance responses, ");
  else if (rcb_meas_speed(ms) < 0)
    fprintf(fp, "# synchronous FRFs, ");
  else
    fprintf(fp, "# FRFs at %.6g rpm, ", rcb_meas_speed(ms) / CLI_RPM_TO_RAD_S);
  fprintf(fp, "%zu channels x %zu points, %.6g to %.6g %s\n", rcb_compare_channel_count(c),
          rcb_compare_point_count(c), rcb_compare_grid(c)[0] * j->xscale,
          rcb_compare_grid(c)[rcb_compare_point_count(c) - 1] * j->xscale, j->xunit);
  if (rcb_meas_magnitude_only_count(ms)) /* issue #35 item 4 */
    fprintf(fp, "# %zu of %zu channels hold magnitudes only (no phase): their FRAC and phase "
            "error are nan, and they are left out of the mean FRAC, CSAC and CSF\n",
            rcb_meas_magnitude_only_count(ms), rcb_meas_channel_count(ms));
  print_channels(fp, c);
  print_outliers(fp, c);
  print_bands(fp, c, j, ord);
  print_peaks(fp, c, j);
}

/* ---- JSON ---- */

static void json_complex_parts(FILE *fp, const rcb_complex *v, size_t n, int im) {
  size_t i;
  fputc('[', fp);
  for (i = 0; i < n; i++) {
    const double *d = (const double *)&v[i]; /* layout double[2] */
    if (i) fputc(',', fp);
    cli_json_num(fp, d[im]);
  }
  fputc(']', fp);
}

static void json_key_num(FILE *fp, const char *key, double v, int comma) {
  fprintf(fp, "%s\"%s\": ", comma ? ", " : "", key);
  cli_json_num(fp, v);
}

static void json_channels(FILE *fp, const rcb_compare *c) {
  size_t k, nch = rcb_compare_channel_count(c), n = rcb_compare_point_count(c);
  fputs(",\n\"channels\": [", fp);
  for (k = 0; k < nch; k++) {
    rcb_compare_channel ch;
    rcb_compare_get_channel(c, k, &ch);
    fputs(k ? ",\n {\"response\": " : "\n {\"response\": ", fp);
    cli_json_str(fp, ch.response);
    fputs(", \"reference\": ", fp);
    if (ch.reference)
      cli_json_str(fp, ch.reference);
    else
      fputs("null", fp);
    fprintf(fp, ", \"kind\": \"%s\"", kind_name(ch.kind));
    json_key_num(fp, "error_pct", ch.error_pct, 1);
    json_key_num(fp, "frac", ch.frac, 1);
    json_key_num(fp, "log_rms", ch.log_rms, 1);
    json_key_num(fp, "phase_rms_deg", ch.phase_rms_deg, 1);
    json_key_num(fp, "floor_pct", ch.floor_pct, 1);
    json_key_num(fp, "chi2_dof", ch.chi2_dof, 1);
    fputs(",\n  \"meas_re\": ", fp);
    json_complex_parts(fp, ch.meas, n, 0);
    fputs(",\n  \"meas_im\": ", fp);
    json_complex_parts(fp, ch.meas, n, 1);
    fputs(",\n  \"model_re\": ", fp);
    json_complex_parts(fp, ch.model, n, 0);
    fputs(",\n  \"model_im\": ", fp);
    json_complex_parts(fp, ch.model, n, 1);
    fputc('}', fp);
  }
  fputs("]", fp);
}

static void json_outliers(FILE *fp, const rcb_compare *c) {
  size_t i, n = rcb_compare_outlier_count(c);
  fputs(",\n\"outliers\": [", fp);
  for (i = 0; i < n; i++) {
    rcb_compare_outlier o;
    rcb_compare_get_outlier(c, i, &o);
    fputs(i ? ",\n {\"response\": " : "\n {\"response\": ", fp);
    cli_json_str(fp, o.response);
    fputs(", \"reference\": ", fp);
    if (o.reference)
      cli_json_str(fp, o.reference);
    else
      fputs("null", fp);
    json_key_num(fp, "error_pct", o.error_pct, 1);
    json_key_num(fp, "others_lo", o.others_lo, 1);
    json_key_num(fp, "others_hi", o.others_hi, 1);
    fprintf(fp, ", \"by_chi2\": %s", o.by_chi2 ? "true" : "false");
    json_key_num(fp, "chi2_dof", o.chi2_dof, 1);
    json_key_num(fp, "chi2_lo", o.chi2_lo, 1);
    json_key_num(fp, "chi2_hi", o.chi2_hi, 1);
    json_key_num(fp, "threshold", o.threshold, 1);
    fputc('}', fp);
  }
  fputc(']', fp);
}

static void json_bands(FILE *fp, const rcb_compare *c, const cmp_job *j, const size_t *ord) {
  size_t b, k, nb = rcb_compare_band_count(c), nch = rcb_compare_channel_count(c);
  const double *map = rcb_compare_residual_map(c);
  fputs(",\n\"bands\": [", fp);
  for (b = 0; b < nb; b++) {
    double lo, hi;
    size_t first, count;
    rcb_compare_band(c, b, &lo, &hi, &first, &count);
    fputs(b ? ", {" : "{", fp);
    json_key_num(fp, "lo", lo * j->xscale, 0);
    json_key_num(fp, "hi", hi * j->xscale, 1);
    fprintf(fp, ", \"first\": %zu, \"count\": %zu", first, count);
    json_key_num(fp, "rms", band_rms(c, b), 1);
    fputc('}', fp);
  }
  fputs("],\n\"residual_map\": [", fp);
  for (k = 0; k < nch; k++) {
    fputs(k ? ", " : "", fp);
    cli_json_nums(fp, map + k, nb, nch);
  }
  fputs("],\n\"worst_bands\": [", fp);
  for (b = 0; b < nb && b < j->worst; b++) fprintf(fp, "%s%zu", b ? ", " : "", ord[b]);
  fputc(']', fp);
}

static void json_peaks(FILE *fp, const rcb_compare *c, const cmp_job *j) {
  size_t p, np = rcb_compare_peak_count(c);
  fputs(",\n\"peaks\": [", fp);
  for (p = 0; p < np; p++) {
    rcb_compare_peak r;
    rcb_compare_get_peak(c, p, &r);
    fprintf(fp, "%s{\"match\": \"%s\"", p ? ",\n " : "\n ", match_name(r.match));
    json_key_num(fp, "meas_x", r.meas_freq * j->xscale, 1);
    json_key_num(fp, "meas_zeta", r.meas_zeta, 1);
    json_key_num(fp, "meas_zeta_hp", r.meas_zeta_hp, 1);
    if (r.match == RCB_PEAK_MODEL_ONLY)
      fputs(", \"channel\": null", fp);
    else
      fprintf(fp, ", \"channel\": %zu", r.channel);
    json_key_num(fp, "meas_amp", r.meas_amp, 1);
    json_key_num(fp, "model_amp", r.model_amp, 1);
    json_key_num(fp, "amp_ratio", r.amp_ratio, 1);
    json_key_num(fp, "model_x", r.model_freq * j->xscale, 1);
    json_key_num(fp, "model_zeta", r.model_zeta, 1);
    fprintf(fp, ", \"model_visible\": %s", r.model_visible ? "true" : "false");
    json_key_num(fp, "model_peak_x", r.model_peak * j->xscale, 1);
    json_key_num(fp, "freq_err_pct", r.freq_err_pct, 1);
    json_key_num(fp, "peak_err_pct", r.peak_err_pct, 1);
    json_key_num(fp, "zeta_err_pct", r.zeta_err_pct, 1);
    fputc('}', fp);
  }
  fputs("]", fp);
}

static void print_json(FILE *fp, const cli_args *a, const cmp_job *j, const rcb_meas *ms,
                       const rcb_compare *c, const size_t *ord) {
  size_t n = rcb_compare_point_count(c), i;
  const double *x = rcb_compare_grid(c);
  rcb_compare_summary s;
  int unb = rcb_meas_get_type(ms) == RCB_MEAS_UNBALANCE;
  rcb_compare_get_summary(c, &s);
  fputs("{\"model\": ", fp);
  cli_json_str(fp, a->model);
  fputs(", \"measurement\": ", fp);
  cli_json_str(fp, j->meas_path);
  fprintf(fp, ", \"type\": \"%s\", \"x_unit\": \"%s\", \"rpm\": ",
          unb ? "unbalance" : rcb_meas_speed(ms) < 0 ? "synchronous" : "frf", j->xunit);
  if (unb || rcb_meas_speed(ms) < 0)
    fputs("null", fp);
  else
    cli_json_num(fp, rcb_meas_speed(ms) / CLI_RPM_TO_RAD_S);
  fputs(",\n\"x\": [", fp);
  for (i = 0; i < n; i++) {
    if (i) fputc(',', fp);
    cli_json_num(fp, x[i] * j->xscale);
  }
  fputs("],\n\"summary\": {", fp);
  json_key_num(fp, "error_pct", s.error_pct, 0);
  json_key_num(fp, "frac_mean", s.frac_mean, 1);
  json_key_num(fp, "log_rms", s.log_rms, 1);
  json_key_num(fp, "phase_rms_deg", s.phase_rms_deg, 1);
  json_key_num(fp, "csac_mean", s.csac_mean, 1);
  json_key_num(fp, "csf_mean", s.csf_mean, 1);
  json_key_num(fp, "floor_pct", s.floor_pct, 1);
  json_key_num(fp, "chi2_dof", s.chi2_dof, 1);
  fputc('}', fp);
  json_channels(fp, c);
  json_outliers(fp, c);
  fputs(",\n\"csac\": ", fp);
  cli_json_nums(fp, rcb_compare_csac(c), n, 1);
  fputs(",\n\"csf\": ", fp);
  cli_json_nums(fp, rcb_compare_csf(c), n, 1);
  json_bands(fp, c, j, ord);
  json_peaks(fp, c, j);
  fputs("}\n", fp);
}

/* ---- plots ---- */

/* A failed --plot leaves no output file (the run failed as a whole). */
#define NOTHING_KEPT "no output file was kept (run without --plot for the comparison alone)"

/* PREFIX + @p suffix, or NULL (message printed). */
static char *prefixed(const char *prefix, const char *suffix) {
  char *s = malloc(strlen(prefix) + strlen(suffix) + 1);
  if (!s) {
    cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    return NULL;
  }
  strcpy(s, prefix);
  return strcat(s, suffix);
}

/* The plotter draws under a temporary prefix beside PREFIX (PREFIX.XXXXXX_*.png,
 * on the signal handler's list); the JSON and the pictures are handed to the
 * plan, renamed onto PREFIX_* only when the whole run succeeded. */
static int write_plots(const cli_args *a, const cmp_job *j, const rcb_meas *ms,
                       const rcb_compare *c, const size_t *ord) {
  static const char *const pics[2] = {"_overlay.png", "_residual_map.png"};
  cli_args pa = *a;
  cli_out o;
  char *json = prefixed(j->plot, "_compare.json"), *tp = prefixed(j->plot, ".XXXXXX");
  char *tpic[2] = {NULL, NULL}, *pic[2] = {NULL, NULL};
  int rc = json && tp ? 0 : CLI_EXIT_NUMERIC, fd = -1, k, slot[3] = {-1, -1, -1};
  if (!rc && (fd = cli_mkstemp(tp, &slot[2])) < 0)
    rc = cli_fail(cli_errno_exit(errno), "--plot %s: cannot write beside it: %s", j->plot,
                  strerror(errno));
  if (fd >= 0) close(fd);
  for (k = 0; k < 2 && !rc; k++) {
    if (!(pic[k] = prefixed(j->plot, pics[k])) || !(tpic[k] = prefixed(tp, pics[k])))
      rc = CLI_EXIT_NUMERIC;
    else
      slot[k] = cli_tmp_register(tpic[k]);
  }
  pa.output = json;
  if (!rc && !(rc = cli_out_open(&o, &pa))) {
    print_json(o.fp, a, j, ms, c, ord);
    if (!(rc = cli_out_flush(&o)) &&
        !(rc = cli_plot_run("compare", o.tmp ? o.tmp : json, tp, NULL, NOTHING_KEPT)))
      rc = cli_out_close(&o);
    else
      cli_out_abort(&o);
  }
  for (k = 0; k < 2 && !rc; k++) /* a picture the plotter did not draw is not an output */
    if (access(tpic[k], F_OK) == 0) rc = cli_plan_adopt(tpic[k], pic[k]);
  for (k = 0; k < 3; k++) cli_tmp_release(slot[k]);
  for (k = 0; k < 2; k++) /* adopted ones are on the plan's list again */
    if (rc && tpic[k]) remove(tpic[k]);
  if (fd >= 0) remove(tp);
  free(json);
  free(tp);
  for (k = 0; k < 2; k++) {
    free(pic[k]);
    free(tpic[k]);
  }
  return rc;
}

/* ---- the job ---- */

static int compare_fail(const rcb_compare *c, rcb_status st, const char *path) {
  const char *msg = cli_msg(rcb_compare_errmsg(c), st);
  if (st == RCB_ERR_NOT_FOUND)
    return cli_fail(CLI_EXIT_INPUT, "compare: %s (measurement '%s'; map UFF nodes to model "
                    "stations with --map NODE=STATION,... or the model's [uff] section)",
                    msg, path);
  return cli_fail(st == RCB_ERR_ARG ? CLI_EXIT_INPUT : cli_status_exit(st), "compare: %s", msg);
}

static int run(const cli_args *a, cmp_job *j) {
  rcb_model *m = NULL;
  rcb_meas *ms = NULL;
  rcb_compare *c = NULL;
  size_t *ord = NULL;
  cli_out o;
  rcb_status st;
  int rc;
  if ((rc = cli_load_model(a, &m))) return rc;
  if ((rc = cli_meas_read(a, j->meas_path, m, &ms))) goto done;
  if (rcb_meas_get_type(ms) == RCB_MEAS_UNBALANCE) {
    j->xscale = 1.0 / CLI_RPM_TO_RAD_S;
    j->xunit = "rpm";
  } else {
    j->xscale = 1.0 / CLI_HZ_TO_RAD_S;
    j->xunit = "Hz";
  }
  if (rcb_compare_create(&c, NULL)) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    goto done;
  }
  if (cli_opt_value(a, "--sd")) {
    double *sd = NULL;
    if ((rc = cli_sd_read(cli_opt_value(a, "--sd"), ms, &sd))) goto done;
    st = rcb_compare_set_sd(c, sd, rcb_meas_channel_count(ms) * rcb_meas_point_count(ms));
    free(sd);
    if (st) {
      rc = cli_fail(CLI_EXIT_INPUT, "%s: --sd: %s", a->cmd, rcb_compare_errmsg(c));
      goto done;
    }
  }
  if ((st = rcb_compare_set_bands(c, j->bands)) ||
      (st = rcb_compare_set_peaks(c, j->prom_db, j->tol_pct / 100.0)) ||
      (st = rcb_compare_run(c, m, ms))) {
    rc = compare_fail(c, st, j->meas_path);
    goto done;
  }
  /* calloc: the analyzer cannot tell that band_order and the printers see one count */
  ord = calloc(rcb_compare_band_count(c) + 1, sizeof *ord);
  if (!ord) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    goto done;
  }
  band_order(c, ord);
  if ((rc = cli_out_open(&o, a))) goto done;
  if (a->json)
    print_json(o.fp, a, j, ms, c, ord);
  else
    print_text(o.fp, a, j, ms, c, ord);
  /* -o FILE is renamed into place only once the plots are done */
  if (j->plot && ((rc = cli_out_flush(&o)) || (rc = cli_plot_mkdir(j->plot)) ||
                  (rc = write_plots(a, j, ms, c, ord)))) {
    cli_out_abort(&o);
    goto done;
  }
  rc = cli_out_close(&o);
done:
  free(ord);
  rcb_compare_destroy(c);
  rcb_meas_destroy(ms);
  rcb_model_destroy(m);
  return rc;
}

int cmd_compare(int argc, char **argv) {
  cli_opt opts[] = {{"--map", "NODE=STATION,...", NULL}, {"--rpm", "R", NULL},
                    {"--bands", "N", NULL},
                    {"--worst", "N", NULL},              {"--prominence", "DB", NULL},
                    {"--tol", "PCT", NULL},              {"--plot", "PREFIX", NULL},
                    {"--sd", "FILE", NULL}};
  size_t nopts = sizeof opts / sizeof opts[0];
  cmp_job j;
  cli_args a;
  char **args = NULL;
  int rc;
  static const cli_file_opt files[] = {{"--sd", CLI_IO_IN}}; /* --plot PREFIX: cli_guard_outputs */
  memset(&j, 0, sizeof j);
  cli_plan_options(files, sizeof files / sizeof files[0]);
  if (!(rc = cli_parse_meas_cmd(argc, argv, opts, nopts, cli_help_compare,
                                "'rcbtool compare MODEL.ini MEAS.uff|MEAS.csv'",
                                &a, &j.meas_path, &args)) &&
      !(rc = parse_job(&a, &j)))
    rc = run(&a, &j);
  free(args);
  return rc < 0 ? CLI_EXIT_OK : rc;
}
