/* rcbtool order: run-up / coast-down signals with a keyphasor -> 1X (and 2X)
 * unbalance responses per speed bin, with their standard deviations. */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_order[] =
    "usage: rcbtool order SIGNALS --kp CH --outputs CH,... -o OUT [options]\n"
    "\n"
    "Order tracking of a run-up or coast-down: the keyphasor's crossings of --trigger\n"
    "(rising, or falling with --kp-edge falling) mark the revolutions (the shaft\n"
    "angle a quadratic in time through three pulses: constant acceleration), each\n"
    "revolution goes to the speed bin of its mean speed, and per bin (--method):\n"
    "  fit (default) every sample of the bin's revolutions, at its own shaft angle,\n"
    "      is fitted by least squares with the offset and 1X..8X (--orders) together,\n"
    "      each phasor a quadratic in speed across the bin, reported at the bin's\n"
    "      mean speed; the sd from the fit's residual (white noise assumed). Orders are\n"
    "      separated when they change within a revolution (a 1X resonance does not\n"
    "      leak into 2X). The bin is the fit's window: keep 3 or more revolutions in\n"
    "      it (run-up rate in rpm/s x 60 / rpm = rpm per revolution); docs/signals.md\n"
    "      gives the measured errors against bin width and run-up rate\n"
    "  rev-dft  each revolution resampled to 64 angles and its DFT taken (1X, 2X),\n"
    "      averaged over the bin, the sd from the revolutions' scatter about a line\n"
    "      in speed (before issue #25). An order that changes within a revolution\n"
    "      leaks into the others: near a resonance about 0.4 x (speed change per\n"
    "      revolution / half-power band) of the peak 1X shows at 2X\n"
    "OUT (.uff/.unv: UFF dataset 58, or .csv) holds the 1X\n"
    "responses as an unbalance-response measurement (Bode/polar data) that compare,\n"
    "fit and diagnose read; the phase is relative to the keyphasor mark (plus\n"
    "--kp-angle), as the model's unbalance angles are relative to the rotor's angle 0.\n"
    "Conventions (stated in the CSV's '# phase = ...' line): by default the phase is a\n"
    "LEAD, y = |Q| cos(Omega t + phase), the model's, measured from the keyphasor's\n"
    "RISING edge. Vibration monitors show a LAG (the response peaks that many degrees\n"
    "after the mark; lag = -lead) and a notch keyphasor marks the revolution at its\n"
    "FALLING edge: give --phase lag --kp-edge falling to read as they do. compare,\n"
    "fit and diagnose read either CSV back to the model's convention.\n"
    "  SIGNALS        .csv as rcbtool transient --signals writes ('# units = V,m',\n"
    "                 'time_s,KP,DA.x,...'); responses in m, mm, um or mil; or .uff\n"
    "                 (UFF58 time records, --map) or .wav (as rcbtool estimate);\n"
    "                 --units CH=U,... and --allow-truncated as for rcbtool estimate\n"
    "  --kp CH        keyphasor channel\n"
    "  --outputs LIST response channels (NAME or NAME=STATION.DIR)\n"
    "  --bin-rpm W    speed bin width, rpm (default 50)\n"
    "  --rpm-max R    highest speed binned, rpm (default 20000)\n"
    "  --trigger V    keyphasor threshold (default halfway between its min and max)\n"
    "  --kp-angle DEG shaft angle at the keyphasor mark, deg (default 0)\n"
    "  --kp-edge E    rising (default) or falling: the keyphasor edge that marks a\n"
    "                 revolution (a notch gives a falling edge, a projection rising)\n"
    "  --phase P      lead (default: the model's) or lag (vibration monitors'), as\n"
    "                 the CSV written presents the phase (.csv only: UFF holds the\n"
    "                 model's complex values)\n"
    "  --min-revs N   revolutions a bin needs (default 3)\n"
    "  --method M     fit (default) or rev-dft: how a bin's orders are estimated (above)\n"
    "  --orders N     fit: orders fitted together, 1X..NX (2 to 8, default 8; those\n"
    "                 above 0.45 x the sample rate left out); an order in the signal\n"
    "                 and not fitted leaks into 1X and 2X when a bin holds few\n"
    "                 revolutions (a 5X of 10 % of the peak 1X, 4 revolutions per\n"
    "                 bin: 2X 4.1 % off with N = 4, 0.09 % with 8); 1X and 2X are\n"
    "                 written\n"
    "  --order2 FILE  write the 2X responses there too (same format as OUT)\n"
    "  --stats FILE   CSV: rpm, revolutions, per channel '<CH> 1X sd' and '<CH> 2X sd'\n"
    "                 (m, of Re and of Im of the bin's mean phasor)\n"
    "  --map LIST     UFF node map, NODE=STATION,... and NODE.DIR=STATION.DIR,...\n"
    "                 (1.z=DA.x; as rcbtool convert); a channel no entry names keeps\n"
    "                 its file name (#1.z, DA.z, #3)\n"
    "  --plot FILE    also draw FILE (PNG): Bode plot (1X amplitude and phase against\n"
    "                 speed) and polar plot of every channel (Python 3 with matplotlib:\n"
    "                 RCB_PYTHON, RCB_PLOTS as for compare --plot); drawn first, a\n"
    "                 failed plot writes nothing\n"
    "Files are written atomically. Exit codes: 2 usage, 3 bad signals (no keyphasor\n"
    "pulses, a response not a displacement), 5 output not written.\n";

static const char *const edge_names[] = {"rising", "falling"};
static const char *const phase_names[] = {"lead", "lag"};
static const char *const method_names[] = {"fit", "rev-dft"}; /* as rcb_order_method */

typedef struct ord_job {
  const cli_args *a;
  int edge, lag, method; /* --kp-edge falling, --phase lag, --method */
  rcb_signals *sig;
  char *buf;
  char *names[257], *model[257]; /* [0] keyphasor */
  size_t idx[257], q;
  rcb_order_opts o;
  rcb_order *e;
  void *work;
} ord_job;

static int ord_channels(ord_job *j) {
  const char *kp = cli_opt_value(j->a, "--kp"), *out = cli_opt_value(j->a, "--outputs");
  char *p;
  size_t i;
  j->buf = malloc(strlen(kp) + strlen(out) + 2);
  if (!j->buf) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(j->buf, kp);
  j->names[0] = j->model[0] = j->buf;
  p = j->buf + strlen(kp) + 1;
  strcpy(p, out);
  while (p) {
    char *comma = strchr(p, ','), *eq;
    if (comma) *comma = '\0';
    eq = strchr(p, '=');
    if (!*p || eq == p || (eq && !eq[1]) || j->q == 256)
      return cli_usage(j->a->cmd, "--outputs: items NAME or NAME=STATION.DIR, at most 256");
    if (eq) *eq = '\0';
    j->q++;
    j->names[j->q] = p;
    j->model[j->q] = eq ? eq + 1 : p;
    p = comma ? comma + 1 : NULL;
  }
  for (i = 0; i <= j->q; i++) {
    rcb_quantity qt;
    int rc;
    if ((rc = cli_signals_find(j->a, j->sig, j->names[i], &j->idx[i])) ||
        (i > 0 && (rc = cli_signals_model_channel(j->a, j->names[i], j->model[i]))))
      return rc;
    rcb_signals_channel(j->sig, j->idx[i], NULL, &qt, NULL);
    if (i > 0 && qt != RCB_QTY_DISPLACEMENT)
      return cli_fail(CLI_EXIT_INPUT, "%s: output channel '%s' is %s; the unbalance response "
                      "is a displacement (m, mm, um, mil): give its unit in the file",
                      j->a->model, j->names[i], rcb_quantity_name(qt));
  }
  return 0;
}

static int ord_track(ord_job *j) {
  double w = 50.0, rmax = 20000.0, kpa = 0.0;
  size_t bytes = 0, minrev = 3, nord = 8, i;
  const double *kp, **ch = calloc(j->q, sizeof *ch);
  rcb_status st;
  int rc;
  if (!ch) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  memset(&j->o, 0, sizeof j->o);
  j->o.trigger = NAN;
  if ((rc = cli_opt_nonneg(j->a, "--bin-rpm", "rpm", 50.0, &w)) ||
      (rc = cli_opt_nonneg(j->a, "--rpm-max", "rpm", 20000.0, &rmax)) ||
      (rc = cli_opt_double(j->a, "--kp-angle", "deg", 0.0, &kpa)) ||
      (rc = cli_opt_count(j->a, "--min-revs", 3, &minrev)) ||
      (rc = cli_opt_count(j->a, "--orders", 8, &nord)) ||
      (rc = cli_opt_choice(j->a, "--kp-edge", edge_names, 2, 0, &j->edge)) ||
      (rc = cli_opt_choice(j->a, "--phase", phase_names, 2, 0, &j->lag)) ||
      (rc = cli_opt_choice(j->a, "--method", method_names, 2, 0, &j->method)) ||
      (cli_opt_value(j->a, "--trigger") &&
       (rc = cli_opt_double(j->a, "--trigger", "", 0.0, &j->o.trigger)))) {
    free(ch);
    return rc;
  }
  if (!(w > 0.0) || !(rmax > w)) {
    free(ch);
    return cli_usage(j->a->cmd, "--bin-rpm must be > 0 and below --rpm-max");
  }
  if (nord < 2 || nord > 8) {
    free(ch);
    return cli_usage(j->a->cmd, "--orders must be 2 to 8 (1X and 2X are written)");
  }
  j->o.norders = j->method ? 2 : nord;
  j->o.bin_width = w * CLI_RPM_TO_RAD_S;
  j->o.speed_max = rmax * CLI_RPM_TO_RAD_S;
  j->o.kp_angle = kpa * CLI_PI / 180.0;
  j->o.min_revs = minrev;
  j->o.kp_falling = j->edge;
  j->o.method = j->method ? RCB_ORDER_REV_DFT : RCB_ORDER_FIT;
  if (rcb_order_workspace_size(&j->o, j->q, &bytes) || !(j->work = malloc(bytes)) ||
      rcb_order_init(&j->e, &j->o, j->q, j->work, bytes)) {
    free(ch);
    return cli_fail(CLI_EXIT_NUMERIC, "order: cannot set up the tracker");
  }
  rcb_signals_channel(j->sig, j->idx[0], NULL, NULL, &kp);
  for (i = 0; i < j->q; i++) rcb_signals_channel(j->sig, j->idx[i + 1], NULL, NULL, &ch[i]);
  st = rcb_order_add(j->e, rcb_signals_rate(j->sig), rcb_signals_length(j->sig), kp, ch);
  free(ch);
  if (st) return cli_fail(CLI_EXIT_INPUT, "%s: %s", j->a->model, rcb_order_errmsg(j->e));
  return 0;
}

/* Bins with enough revolutions, ascending speed. */
static size_t ord_bins(const ord_job *j, size_t *bins) {
  size_t b, n = 0, nr;
  for (b = 0; b < rcb_order_bin_count(j->e); b++) {
    rcb_order_result(j->e, b, 0, 1, NULL, NULL, NULL, &nr);
    if (nr >= j->o.min_revs) bins[n++] = b;
  }
  return n;
}

static int ord_write(const ord_job *j, const size_t *bins, size_t nb, size_t m, const char *path) {
  double *x = malloc((nb ? nb : 1) * sizeof *x);
  rcb_complex *y = malloc((nb ? nb : 1) * sizeof *y);
  rcb_meas *ms = NULL;
  rcb_status st = RCB_ERR_NOMEM;
  cli_uff_map mp;
  size_t c, i;
  int rc = 0;
  if (x && y && !rcb_meas_create(&ms, NULL)) {
    for (i = 0; i < nb; i++) rcb_order_result(j->e, bins[i], 0, 1, &x[i], NULL, NULL, NULL);
    st = rcb_meas_set_grid(ms, RCB_MEAS_UNBALANCE, nb, x, 0.0);
    for (c = 0; !st && c < j->q; c++) {
      for (i = 0; i < nb; i++) rcb_order_result(j->e, bins[i], c, m, NULL, &y[i], NULL, NULL);
      st = rcb_meas_add_channel(ms, j->model[c + 1], NULL, RCB_RECEPTANCE, y);
    }
    if (!st) { /* the convention, stated in the CSV */
      char ref[80];
      snprintf(ref, sizeof ref, "keyphasor %s edge, shaft angle %.6g deg there",
               edge_names[j->edge], j->o.kp_angle * 180.0 / CLI_PI);
      st = rcb_meas_set_phase(ms, j->lag ? RCB_PHASE_LAG : RCB_PHASE_LEAD, ref);
    }
    if (st)
      rc = cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "order: %s",
                    cli_msg(rcb_meas_errmsg(ms), st));
  } else {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  if (!rc && (rc = cli_uff_map_parse(j->a, "--map", NULL, &mp)) == 0) {
    rc = cli_meas_write(j->a->cmd, ms, path, 0, &mp);
    cli_uff_map_free(&mp);
  }
  rcb_meas_destroy(ms);
  free(x);
  free(y);
  return rc;
}

static int ord_stats(const ord_job *j, const size_t *bins, size_t nb, const char *path) {
  cli_args b = *j->a;
  cli_out out;
  size_t i, c, m;
  int rc;
  b.output = path;
  if ((rc = cli_out_open(&out, &b))) return rc;
  fputs("rpm,revolutions", out.fp);
  for (c = 0; c < j->q; c++) fprintf(out.fp, ",%s 1X sd,%s 2X sd", j->model[c + 1], j->model[c + 1]);
  fputc('\n', out.fp);
  for (i = 0; i < nb; i++) {
    double speed, sd;
    size_t nr;
    rcb_order_result(j->e, bins[i], 0, 1, &speed, NULL, NULL, &nr);
    cli_csv_num(out.fp, speed / CLI_RPM_TO_RAD_S);
    fprintf(out.fp, ",%zu", nr);
    for (c = 0; c < j->q; c++)
      for (m = 1; m <= 2; m++) {
        rcb_order_result(j->e, bins[i], c, m, NULL, NULL, &sd, NULL);
        fputc(',', out.fp);
        cli_csv_num(out.fp, sd);
      }
    fputc('\n', out.fp);
  }
  return cli_out_close(&out);
}

typedef struct ord_plot {
  const ord_job *j;
  const size_t *bins;
  size_t nb;
} ord_plot;

/* --plot: the 1X vectors of every channel per speed bin, for rcb_plots.py order. */
static void plot_json(FILE *fp, const void *ctx) {
  const ord_plot *pc = ctx;
  size_t i, c, nb = pc->nb;
  double *v = malloc((nb ? nb : 1) * 3 * sizeof *v);
  if (!v) return; /* an empty file: the plotter refuses it */
  for (i = 0; i < nb; i++) {
    rcb_order_result(pc->j->e, pc->bins[i], 0, 1, &v[i], NULL, NULL, NULL);
    v[i] /= CLI_RPM_TO_RAD_S;
  }
  fputs("{\"order\": 1, \"rpm\": ", fp);
  cli_json_nums(fp, v, nb, 1);
  fputs(",\n\"channels\": [", fp);
  for (c = 0; c < pc->j->q; c++) {
    for (i = 0; i < nb; i++) {
      rcb_complex q;
      rcb_order_result(pc->j->e, pc->bins[i], c, 1, NULL, &q, &v[2 * nb + i], NULL);
      v[2 * i] = creal(q), v[2 * i + 1] = pc->j->lag ? -cimag(q) : cimag(q); /* as --phase */
    }
    fputs(c ? ",\n {\"name\": " : "\n {\"name\": ", fp);
    cli_json_str(fp, pc->j->model[c + 1]);
    fputs(", \"re\": ", fp);
    cli_json_nums(fp, v, nb, 2);
    fputs(", \"im\": ", fp);
    cli_json_nums(fp, v + 1, nb, 2);
    fputs(", \"sd\": ", fp);
    cli_json_nums(fp, v + 2 * nb, nb, 1);
    fputs("}", fp);
  }
  fputs("]}\n", fp);
  free(v);
}

static int order_run(const cli_args *a) {
  ord_job j;
  size_t *bins = NULL, nb = 0;
  int is_uff = 0;
  const char *o2 = cli_opt_value(a, "--order2"), *stats = cli_opt_value(a, "--stats");
  const char *plot = cli_opt_value(a, "--plot");
  int rc;
  memset(&j, 0, sizeof j);
  j.a = a;
  if (!a->output) return cli_usage(a->cmd, "missing -o OUT (.uff, .unv or .csv) for the 1X data");
  if ((rc = cli_opt_require(a, "--kp", "the keyphasor channel, e.g. --kp KP")) ||
      (rc = cli_opt_require(a, "--outputs", "the response channels, e.g. --outputs DA.x")) ||
      (rc = cli_meas_format(a->cmd, a->output, &is_uff)) ||
      (o2 && (rc = cli_meas_format(a->cmd, o2, &is_uff))))
    return rc;
  if (cli_opt_value(a, "--phase") && strcmp(cli_opt_value(a, "--phase"), "lag") == 0) {
    int uff1 = 0, uff2 = 0;
    if ((rc = cli_meas_format(a->cmd, a->output, &uff1)) ||
        (o2 && (rc = cli_meas_format(a->cmd, o2, &uff2))))
      return rc;
    if (uff1 || uff2)
      return cli_usage(a->cmd, "--phase lag applies to a .csv output: a UFF file holds the "
                       "model's complex values (phase lead)");
  }
  if (rcb_signals_create(&j.sig, NULL)) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  rc = cli_signals_read(a, j.sig);
  if (!rc) rc = ord_channels(&j);
  if (!rc) rc = ord_track(&j);
  if (!rc) {
    bins = malloc((rcb_order_bin_count(j.e) + 1) * sizeof *bins);
    if (!bins) rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  if (!rc && (nb = ord_bins(&j, bins)) < 2)
    rc = cli_fail(CLI_EXIT_INPUT, "%s: %zu speed bins with %zu revolutions or more; need two: "
                  "a longer record or wider --bin-rpm", a->model, nb, j.o.min_revs);
  if (!rc && plot) { /* first: a failed plot leaves no output */
    ord_plot pc = {&j, bins, nb};
    rc = cli_plot_write("order", plot, plot_json, &pc,
                        "no output file was written (run without --plot for the 1X data alone)");
  }
  if (!rc && stats) rc = ord_stats(&j, bins, nb, stats);
  if (!rc && o2) rc = ord_write(&j, bins, nb, 2, o2);
  if (!rc) rc = ord_write(&j, bins, nb, 1, a->output);
  free(bins);
  free(j.work);
  free(j.buf);
  rcb_signals_destroy(j.sig);
  return rc;
}

int cmd_order(int argc, char **argv) {
  cli_opt opts[] = {{"--kp", "CH", NULL},         {"--outputs", "LIST", NULL},
                    {"--bin-rpm", "W", NULL},     {"--rpm-max", "R", NULL},
                    {"--trigger", "V", NULL},     {"--kp-angle", "DEG", NULL},
                    {"--min-revs", "N", NULL},    {"--order2", "FILE", NULL},
                    {"--stats", "FILE", NULL},    {"--map", "NODE=STATION,...", NULL},
                    {"--wav-names", "LIST", NULL}, {"--wav-units", "LIST", NULL},
                    {"--wav-scale", "LIST", NULL}, {"--plot", "FILE.png", NULL},
                    {"--units", "CH=UNIT,...", NULL}, {"--allow-truncated", NULL, NULL},
                    {"--kp-edge", "E", NULL},     {"--phase", "P", NULL},
                    {"--method", "M", NULL},      {"--orders", "N", NULL}};
  static const cli_file_opt files[] = {
      {"--order2", CLI_IO_OUT}, {"--stats", CLI_IO_OUT}, {"--plot", CLI_IO_OUT | CLI_IO_MKDIR}};
  cli_args a;
  int rc;
  cli_plan_options(files, sizeof files / sizeof files[0]);
  rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc || a.help) return rc ? rc : cli_print_help(cli_help_order);
  if (a.json) return cli_usage(a.cmd, "--json does not apply: the format follows OUT's extension");
  return order_run(&a);
}
