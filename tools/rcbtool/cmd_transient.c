/* rcbtool transient: time histories (constant speed, run-up, coast-down) by
 * SUNDIALS time integration; rcbtool timecheck: the steady 1X response by
 * time integration against the frequency-domain unbalance response. */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_transient[] =
    "usage: rcbtool transient MODEL.ini --out CH[,CH...] --rpm A [--rpm-end B --accel R]\n"
    "                         [--t-end S] [--dt S] [--rtol X] [--atol Q,V]\n"
    "                         [--signals [--noise SD] [--seed N]\n"
    "                          [--force random|impact --force-at CH [--force-amp F]\n"
    "                           [--hits N] [--pulse S]]]\n"
    "                         [--json] [-o FILE] [--progress]\n"
    "\n"
    "Integrates M q'' + (C + Omega(t) G) q' + K q = f(t) from rest (CVODE BDF, SUNDIALS)\n"
    "with the model's [unbalance] sections as forcing (including the angular-\n"
    "acceleration term). Omega starts at A rpm and moves to B rpm at R rpm/s\n"
    "(run-up if B > A, coast-down if B < A), then stays at B.\n"
    "  --out CH,...  output channels STATION.DIR (DIR x, y, rx, ry), e.g. DA.x,DA.y\n"
    "  --rpm A       start speed, rpm (required)\n"
    "  --rpm-end B   end speed, rpm (default A: constant speed)\n"
    "  --accel R     angular acceleration magnitude, rpm/s (required when B != A)\n"
    "  --t-end S     duration, s (default: the ramp time |B - A|/R, required at\n"
    "                constant speed)\n"
    "  --dt S        sampling interval, s (default: 1/40 of the revolution at the\n"
    "                highest speed)\n"
    "  --rtol X      integrator relative tolerance (default 1e-7)\n"
    "  --atol Q,V    absolute tolerances on displacements, m, and velocities, m/s\n"
    "                (default 1e-13,1e-10). A random force kinks at every sample and\n"
    "                costs steps: loosen both for long records (e.g. --rtol 1e-4\n"
    "                --atol 1e-10,1e-7)\n"
    "  --signals     write the signals a data recorder would hold instead: CSV\n"
    "                '# units = V,m,...', 'time_s,KP,<out>,...' that rcbtool order\n"
    "                and rcbtool estimate read; KP is a 5 V once-per-revolution\n"
    "                keyphasor whose rising edge (linear over +-7.2 deg of shaft\n"
    "                angle) crosses 2.5 V at the mark, angle 0 of the unbalances\n"
    "  --noise SD    with --signals: Gaussian sensor noise, m RMS, on every output\n"
    "  --seed N      noise and random-force seed (default 1)\n"
    "  --force random|impact  with --signals: an external force at --force-at CH\n"
    "                (STATION.DIR), integrated with the unbalances and written as\n"
    "                the column 'force' (N) after KP, for rcbtool estimate\n"
    "                (--input force=CH). random: Gaussian white samples every --dt\n"
    "                (band-limited white: flat to the Nyquist frequency 1/(2 dt)),\n"
    "                --force-amp RMS (default 50 N), seeded by --seed. impact: N\n"
    "                (--hits, default 5) half-sine hammer pulses of --pulse s\n"
    "                (default 1 ms, at least 4 samples) and peak --force-amp (default\n"
    "                500 N), one per block of B = floor(t_end / (N dt)) samples,\n"
    "                each starting 2 samples into its block: estimate with --nseg B\n"
    "                --overlap 0 --window force-exp (the pulse lies in the force\n"
    "                window while --pulse <= 0.1 B dt - 2 dt). The force is linear\n"
    "                between samples (as a force-cell record is read).\n"
    "\n"
    "CSV: t_s,rpm,angle_deg,<out>,... (displacements m, rotations rad) - orbit plots\n"
    "pair the x and y columns of a station; the rpm column per sample makes the\n"
    "history waterfall-ready (short-time spectra against speed).\n"
    "JSON: {\"t\": [...], \"rpm\": [...], \"channels\": [{\"output\", \"q\": [...]}],\n"
    "\"stats\": {\"steps\", \"rhs_evals\", \"jac_evals\", \"lin_setups\", \"lin_solves\"}}\n"
    "Not available when librcb was built without SUNDIALS (exit 4).\n";

const char cli_help_timecheck[] =
    "usage: rcbtool timecheck MODEL.ini --out CH[,CH...] --rpm-max B [--rpm-min A]\n"
    "                         [--points N] [--rtol X] [--steady-tol X]\n"
    "                         [--json] [-o FILE] [--progress]\n"
    "\n"
    "Cross-check of `rcbtool unbalance`: at each speed Omega_i = A + i (B - A)/(N - 1)\n"
    "the steady 1X response is computed twice, in the frequency domain (one complex\n"
    "solve) and by time integration from rest until the transient has decayed\n"
    "(estimated relative error below --steady-tol), with a DFT over whole\n"
    "revolutions. Speeds must be > 0.\n"
    "  --points N      number of speeds (default 10)\n"
    "  --rtol X        integrator relative tolerance (default 1e-7)\n"
    "  --steady-tol X  steady-state tolerance (default 1e-5)\n"
    "\n"
    "CSV: rpm,<out> amp_freq,<out> amp_time,<out> amp_diff_pct,<out> phase_freq_deg,\n"
    "<out> phase_time_deg,<out> phase_diff_deg,...,revolutions,steps\n"
    "JSON: {\"rpm\": [...], \"channels\": [{\"output\", \"amp_freq\", \"amp_time\",\n"
    "\"phase_freq_deg\", \"phase_time_deg\"}], \"revolutions\": [...], \"steps\": [...]}\n";

/* ---- transient ---- */

typedef struct tr_hist {
  size_t nout, n, cap;
  double *t, *rpm, *ang, *q; /* q[k * nout + o] */
  int nomem;
} tr_hist;

static int keep_sample(void *user, const rcb_transient_sample *s) {
  tr_hist *h = user;
  size_t o;
  if (h->n == h->cap) {
    size_t cap = h->cap ? 2 * h->cap : 1024;
    double *t = realloc(h->t, cap * sizeof *t), *r, *a, *q;
    if (t) h->t = t;
    r = realloc(h->rpm, cap * sizeof *r);
    if (r) h->rpm = r;
    a = realloc(h->ang, cap * sizeof *a);
    if (a) h->ang = a;
    q = realloc(h->q, cap * (h->nout ? h->nout : 1) * sizeof *q);
    if (q) h->q = q;
    if (!t || !r || !a || !q) {
      h->nomem = 1;
      return 1;
    }
    h->cap = cap;
  }
  h->t[h->n] = s->t;
  h->rpm[h->n] = s->speed / CLI_RPM_TO_RAD_S;
  h->ang[h->n] = fmod(s->angle, 2.0 * CLI_PI) * 180.0 / CLI_PI;
  for (o = 0; o < h->nout; o++) h->q[h->n * h->nout + o] = s->out[o];
  h->n++;
  return 0;
}

static void tr_csv(FILE *fp, const tr_hist *h, const cli_channels *ch) {
  size_t k, o;
  fputs("t_s,rpm,angle_deg", fp);
  for (o = 0; o < ch->n; o++) fprintf(fp, ",%s", ch->names[o]);
  fputc('\n', fp);
  for (k = 0; k < h->n; k++) {
    cli_csv_num(fp, h->t[k]);
    fputc(',', fp);
    cli_csv_num(fp, h->rpm[k]);
    fputc(',', fp);
    cli_csv_num(fp, h->ang[k]);
    for (o = 0; o < ch->n; o++) {
      fputc(',', fp);
      cli_csv_num(fp, h->q[k * h->nout + o]);
    }
    fputc('\n', fp);
  }
}

/* The keyphasor: 5 V pulse over [0, 45 deg) of shaft angle, its rising edge
 * linear over +-7.2 deg so that a sampled record locates the mark (2.5 V)
 * by interpolation, as a proximity probe over a notch does. */
static double kp_volts(double ang_deg) {
  double w = ang_deg >= 180.0 ? ang_deg - 360.0 : ang_deg;
  if (w >= -7.2 && w <= 7.2) return 2.5 + 2.5 * w / 7.2;
  return w > 7.2 && w < 45.0 ? 5.0 : 0.0;
}

/* Gaussian samples (xorshift64* + Box-Muller), reproducible on every platform. */
static double noise_gauss(unsigned long long *s) {
  double u[2];
  int k;
  for (k = 0; k < 2; k++) {
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    u[k] = ((double)((*s * 2685821657736338717ULL) >> 11) + 0.5) / 9007199254740992.0;
  }
  return sqrt(-2.0 * log(u[0])) * cos(2.0 * CLI_PI * u[1]);
}

/* The external force of --force: none, random, impact. */
typedef struct tr_force {
  int kind;     /* 0 none, 1 random, 2 impact */
  rcb_dof dof;
  double amp;   /* N: RMS (random) or peak (impact) */
  double pulse; /* s, impact */
  size_t hits, block; /* impact: pulses, samples per block */
  double *f;    /* samples every dt, n */
  size_t n;
} tr_force;

static void tr_signals(FILE *fp, const tr_hist *h, const cli_channels *ch, double sd,
                       unsigned long long seed, const tr_force *fo) {
  size_t k, o;
  unsigned long long s = seed * 0x9E3779B97F4A7C15ULL + 1;
  fprintf(fp, "# rcbtool transient --signals: keyphasor in V, %sdisplacements in m\n"
          "# units = V%s", fo->kind ? "force in N, " : "", fo->kind ? ",N" : "");
  for (o = 0; o < ch->n; o++) fputs(",m", fp);
  fputs(fo->kind ? "\ntime_s,KP,force" : "\ntime_s,KP", fp);
  for (o = 0; o < ch->n; o++) fprintf(fp, ",%s", ch->names[o]);
  fputc('\n', fp);
  for (k = 0; k < h->n; k++) {
    cli_csv_num(fp, h->t[k]);
    fputc(',', fp);
    cli_csv_num(fp, kp_volts(h->ang[k]));
    if (fo->kind) {
      fputc(',', fp);
      cli_csv_num(fp, k < fo->n ? fo->f[k] : 0.0);
    }
    for (o = 0; o < ch->n; o++) {
      fputc(',', fp);
      cli_csv_num(fp, h->q[k * h->nout + o] + (sd > 0.0 ? sd * noise_gauss(&s) : 0.0));
    }
    fputc('\n', fp);
  }
}

static void tr_json(FILE *fp, const tr_hist *h, const cli_channels *ch,
                    const rcb_transient_stats *s) {
  size_t o;
  fputs("{\"t\": ", fp);
  cli_json_nums(fp, h->t, h->n, 1);
  fputs(",\n\"rpm\": ", fp);
  cli_json_nums(fp, h->rpm, h->n, 1);
  fputs(",\n\"channels\": [", fp);
  for (o = 0; o < ch->n; o++) {
    fputs(o ? ",\n  {\"output\": " : "\n  {\"output\": ", fp);
    cli_json_str(fp, ch->names[o]);
    fputs(", \"q\": ", fp);
    cli_json_nums(fp, h->q + o, h->n, h->nout);
    fputs("}", fp);
  }
  fprintf(fp,
          "],\n\"stats\": {\"steps\": %ld, \"rhs_evals\": %ld, \"jac_evals\": %ld, "
          "\"lin_setups\": %ld, \"lin_solves\": %ld}}\n",
          s->steps, s->rhs_evals, s->jac_evals, s->lin_setups, s->lin_solves);
}

typedef struct tr_opts {
  rcb_speed_profile p; /* rad/s, rad/s^2 */
  double t_end, dt, rtol, atol_q, atol_v;
} tr_opts;

static int tr_parse(const cli_args *a, tr_opts *o) {
  double r0, r1, acc;
  int rc;
  if ((rc = cli_opt_require(a, "--out", "output channels STATION.DIR[,...]")) ||
      (rc = cli_opt_require(a, "--rpm", "the start speed in rpm")) ||
      (rc = cli_opt_nonneg(a, "--rpm", "rpm", 0.0, &r0)) ||
      (rc = cli_opt_nonneg(a, "--rpm-end", "rpm", r0, &r1)) ||
      (rc = cli_opt_nonneg(a, "--accel", "rpm/s", 0.0, &acc)) ||
      (rc = cli_opt_nonneg(a, "--t-end", "s", 0.0, &o->t_end)) ||
      (rc = cli_opt_nonneg(a, "--dt", "s", 0.0, &o->dt)) ||
      (rc = cli_opt_nonneg(a, "--rtol", "-", 1e-7, &o->rtol)))
    return rc;
  o->atol_q = 1e-13, o->atol_v = 1e-10;
  if (cli_opt_value(a, "--atol")) {
    const char *v = cli_opt_value(a, "--atol"), *c = strchr(v, ',');
    char *e1 = NULL, *e2 = NULL;
    o->atol_q = strtod(v, &e1);
    if (c) o->atol_v = strtod(c + 1, &e2);
    if (!c || e1 != c || *e2 || !(o->atol_q > 0.0) || !(o->atol_v > 0.0) ||
        !isfinite(o->atol_q) || !isfinite(o->atol_v))
      return cli_usage(a->cmd, "option --atol expects Q,V: absolute tolerances > 0 on "
                       "displacements (m) and velocities (m/s), got '%s'", v);
  }
  if (r1 != r0 && acc <= 0.0)
    return cli_usage(a->cmd, "--rpm-end %g differs from --rpm %g; expected --accel > 0 (rpm/s)",
                     r1, r0);
  /* a stated 0 is refused, not replaced by the default (issue #17) */
  if (cli_opt_value(a, "--dt") && !(o->dt > 0.0))
    return cli_usage(a->cmd, "option --dt expects a sampling interval > 0 (s); leave it out "
                     "for the default (1/40 of the revolution at the highest speed)");
  if (cli_opt_value(a, "--t-end") && !(o->t_end > 0.0))
    return cli_usage(a->cmd, "option --t-end expects a duration > 0 (s); leave it out for the "
                     "ramp time |B - A|/R");
  if (o->t_end <= 0.0) {
    if (r1 == r0) return cli_usage(a->cmd, "expected --t-end S (s) at constant speed");
    o->t_end = fabs(r1 - r0) / acc;
  }
  if (o->dt <= 0.0) o->dt = fmax(r0, r1) > 0.0 ? 60.0 / fmax(r0, r1) / 40.0 : o->t_end / 1000.0;
  o->p.speed0 = r0 * CLI_RPM_TO_RAD_S;
  o->p.speed1 = r1 * CLI_RPM_TO_RAD_S;
  o->p.accel = acc * CLI_RPM_TO_RAD_S;
  return 0;
}

/* --force random|impact: parse and make the samples (every dt, t = 0 ..
 * t_end). */
static int tr_force_make(const cli_args *a, rcb_model *m, const tr_opts *o, size_t seed,
                         tr_force *fo) {
  static const char *const kinds[] = {"none", "random", "impact"};
  cli_channels at = {0};
  size_t k, nsamp = (size_t)floor(o->t_end / o->dt * (1.0 + 1e-12)) + 1;
  int rc;
  if ((rc = cli_opt_choice(a, "--force", kinds, 3, 0, &fo->kind))) return rc;
  if (!fo->kind) {
    if (cli_opt_value(a, "--force-at") || cli_opt_value(a, "--force-amp") ||
        cli_opt_value(a, "--hits") || cli_opt_value(a, "--pulse"))
      return cli_usage(a->cmd, "--force-at, --force-amp, --hits and --pulse apply with "
                       "--force random|impact");
    return 0;
  }
  if (!cli_opt_value(a, "--signals"))
    return cli_usage(a->cmd, "--force writes the force beside the responses: give --signals");
  if ((rc = cli_opt_require(a, "--force-at", "the forced channel STATION.DIR, e.g. DA.x")) ||
      (rc = cli_opt_nonneg(a, "--force-amp", "N", fo->kind == 1 ? 50.0 : 500.0, &fo->amp)) ||
      (rc = cli_opt_count(a, "--hits", 5, &fo->hits)) ||
      (rc = cli_opt_nonneg(a, "--pulse", "s", 1e-3, &fo->pulse)))
    return rc;
  if ((rc = cli_channels_parse(a, m, "--force-at", &at))) return rc;
  if (at.n != 1) {
    cli_channels_free(&at);
    return cli_usage(a->cmd, "--force-at expects one channel STATION.DIR");
  }
  fo->dof = at.dofs[0];
  cli_channels_free(&at);
  if (fo->kind == 2) {
    fo->block = fo->hits ? nsamp / fo->hits : 0;
    if (fo->hits == 0 || fo->pulse < 4.0 * o->dt || (double)fo->block * o->dt < 10.0 * fo->pulse)
      return cli_usage(a->cmd, "--force impact: %zu hits of %g s pulses in %g s at dt %g s; "
                       "expected hits >= 1, a pulse of at least 4 samples (--pulse >= %g s) "
                       "and blocks (t_end / hits) at least 10 pulses long", fo->hits,
                       fo->pulse, o->t_end, o->dt, 4.0 * o->dt);
  }
  if (!(fo->f = calloc(nsamp, sizeof *fo->f))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  fo->n = nsamp;
  if (fo->kind == 1) {
    unsigned long long s = (unsigned long long)seed * 0xD1B54A32D192ED03ULL + 7;
    for (k = 0; k < nsamp; k++) fo->f[k] = fo->amp * noise_gauss(&s);
  } else {
    size_t hit;
    for (hit = 0; hit < fo->hits; hit++) {
      double t0 = (double)(hit * fo->block + 2) * o->dt; /* 2 samples into the block */
      for (k = hit * fo->block + 2; k < nsamp; k++) {
        double tau = (double)k * o->dt - t0;
        if (tau > fo->pulse) break;
        fo->f[k] = fo->amp * sin(CLI_PI * tau / fo->pulse);
      }
    }
  }
  return 0;
}

static int tr_compute(const cli_args *a, rcb_model *m, const cli_channels *ch, const tr_opts *o,
                      const tr_force *fo, tr_hist *h, rcb_transient_stats *s) {
  rcb_transient *t = NULL;
  rcb_status st = rcb_transient_create(&t, m, ch->n, ch->dofs, NULL);
  int rc = 0;
  (void)a;
  if (!st) st = rcb_transient_set_tolerances(t, o->rtol, o->atol_q, o->atol_v);
  if (!st && fo->kind) st = rcb_transient_set_force(t, fo->dof, fo->f, fo->n, o->dt);
  if (!st) st = rcb_transient_run(t, &o->p, o->t_end, o->dt, NULL, NULL, keep_sample, h);
  if (h->nomem) rc = cli_fail(CLI_EXIT_NUMERIC, "transient: out of memory storing samples");
  else if (st)
    rc = cli_fail(cli_status_exit(st), "transient: %s",
                  cli_msg(t ? rcb_transient_errmsg(t) : rcb_model_errmsg(m), st));
  if (t) rcb_transient_get_stats(t, s);
  rcb_transient_destroy(t);
  return rc;
}

int cmd_transient(int argc, char **argv) {
  cli_opt opts[] = {{"--out", "CH,...", NULL}, {"--rpm", "A", NULL},  {"--rpm-end", "B", NULL},
                    {"--accel", "R", NULL},    {"--t-end", "S", NULL}, {"--dt", "S", NULL},
                    {"--rtol", "X", NULL},     {"--atol", "Q,V", NULL},
                    {"--signals", NULL, NULL},
                    {"--noise", "SD", NULL},   {"--seed", "N", NULL},
                    {"--force", "random|impact", NULL}, {"--force-at", "CH", NULL},
                    {"--force-amp", "F", NULL}, {"--hits", "N", NULL},
                    {"--pulse", "S", NULL}};
  cli_args a;
  cli_channels ch = {0};
  double noise = 0.0;
  size_t seed = 1;
  tr_opts o = {{0, 0, 0}, 0, 0, 0, 0, 0};
  tr_hist h = {0};
  tr_force fo = {0};
  rcb_transient_stats s = {0};
  rcb_model *m = NULL;
  cli_out out;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_transient);
  if ((rc = tr_parse(&a, &o)) || (rc = cli_opt_nonneg(&a, "--noise", "m", 0.0, &noise)) ||
      (rc = cli_opt_count(&a, "--seed", 1, &seed)))
    return rc;
  if ((noise > 0.0 || cli_opt_value(&a, "--seed")) && !cli_opt_value(&a, "--signals"))
    return cli_usage(a.cmd, "--noise and --seed apply with --signals");
  if (a.json && cli_opt_value(&a, "--signals"))
    return cli_usage(a.cmd, "--signals writes CSV: drop --json");
  if ((rc = cli_load_model(&a, &m))) return rc;
  if (!(rc = cli_channels_parse(&a, m, "--out", &ch)) &&
      !(rc = cli_check_size(&a, floor(o.t_end / o.dt) + 1.0, 3.0 + (double)ch.n)) &&
      !(rc = tr_force_make(&a, m, &o, seed, &fo))) {
    h.nout = ch.n;
    if (!(rc = tr_compute(&a, m, &ch, &o, &fo, &h, &s)) && !(rc = cli_out_open(&out, &a))) {
      if (cli_opt_value(&a, "--signals"))
        tr_signals(out.fp, &h, &ch, noise, (unsigned long long)seed, &fo);
      else if (a.json)
        tr_json(out.fp, &h, &ch, &s);
      else
        tr_csv(out.fp, &h, &ch);
      rc = cli_out_close(&out);
    }
  }
  free(h.t);
  free(h.rpm);
  free(h.ang);
  free(h.q);
  free(fo.f);
  cli_channels_free(&ch);
  rcb_model_destroy(m);
  return rc;
}

/* ---- timecheck ---- */

typedef struct tc_job {
  size_t npts, nout;
  double *rpm, *steps, *revs;
  rcb_complex *qf, *qt; /* [p * nout + o] */
} tc_job;

static double deg(rcb_complex z) { return carg(z) * 180.0 / CLI_PI; }

static int tc_sweep(const cli_args *a, rcb_frf *f, rcb_transient *t, tc_job *j) {
  size_t p;
  cli_progress pr;
  cli_progress_start(&pr, a, "timecheck", "speeds", j->npts);
  for (p = 0; p < j->npts; p++) {
    double w = j->rpm[p] * CLI_RPM_TO_RAD_S;
    rcb_transient_stats s;
    rcb_status st = rcb_frf_unbalance(f, w, j->qf + p * j->nout);
    if (!st) st = rcb_transient_steady(t, w, j->qt + p * j->nout);
    if (st) {
      cli_progress_end(&pr);
      return cli_fail(cli_status_exit(st), "timecheck at %.17g rpm: %s", j->rpm[p],
                      cli_msg(rcb_transient_errmsg(t)[0] ? rcb_transient_errmsg(t)
                                                         : rcb_frf_errmsg(f),
                              st));
    }
    rcb_transient_get_stats(t, &s);
    j->steps[p] = (double)s.steps;
    j->revs[p] = (double)s.periods;
    cli_progress_step(&pr, p + 1);
  }
  cli_progress_end(&pr);
  return 0;
}

static void tc_csv(FILE *fp, const tc_job *j, const cli_channels *ch) {
  size_t p, o;
  fputs("rpm", fp);
  for (o = 0; o < ch->n; o++) {
    const char *c = ch->names[o];
    fprintf(fp, ",%s amp_freq,%s amp_time,%s amp_diff_pct,%s phase_freq_deg,%s phase_time_deg,"
                "%s phase_diff_deg", c, c, c, c, c, c);
  }
  fputs(",revolutions,steps\n", fp);
  for (p = 0; p < j->npts; p++) {
    cli_csv_num(fp, j->rpm[p]);
    for (o = 0; o < ch->n; o++) {
      rcb_complex qf = j->qf[p * j->nout + o], qt = j->qt[p * j->nout + o];
      double v[6] = {cabs(qf), cabs(qt), 100.0 * (cabs(qt) / cabs(qf) - 1.0),
                     deg(qf), deg(qt), deg(qt / qf)};
      size_t k;
      for (k = 0; k < 6; k++) {
        fputc(',', fp);
        cli_csv_num(fp, v[k]);
      }
    }
    fprintf(fp, ",%.0f,%.0f\n", j->revs[p], j->steps[p]);
  }
}

static void tc_json_arr(FILE *fp, const tc_job *j, size_t o, int time, int phase) {
  size_t p;
  fputc('[', fp);
  for (p = 0; p < j->npts; p++) {
    rcb_complex z = (time ? j->qt : j->qf)[p * j->nout + o];
    fputs(p ? ", " : "", fp);
    cli_json_num(fp, phase ? deg(z) : cabs(z));
  }
  fputc(']', fp);
}

static void tc_json(FILE *fp, const tc_job *j, const cli_channels *ch) {
  size_t o;
  fputs("{\"rpm\": ", fp);
  cli_json_nums(fp, j->rpm, j->npts, 1);
  fputs(",\n\"channels\": [", fp);
  for (o = 0; o < ch->n; o++) {
    fputs(o ? ",\n  {\"output\": " : "\n  {\"output\": ", fp);
    cli_json_str(fp, ch->names[o]);
    fputs(", \"amp_freq\": ", fp);
    tc_json_arr(fp, j, o, 0, 0);
    fputs(", \"amp_time\": ", fp);
    tc_json_arr(fp, j, o, 1, 0);
    fputs(", \"phase_freq_deg\": ", fp);
    tc_json_arr(fp, j, o, 0, 1);
    fputs(", \"phase_time_deg\": ", fp);
    tc_json_arr(fp, j, o, 1, 1);
    fputs("}", fp);
  }
  fputs("],\n\"revolutions\": ", fp);
  cli_json_nums(fp, j->revs, j->npts, 1);
  fputs(",\n\"steps\": ", fp);
  cli_json_nums(fp, j->steps, j->npts, 1);
  fputs("}\n", fp);
}

static int tc_run(const cli_args *a, rcb_model *m, const cli_channels *ch, tc_job *j,
                  double rtol, double sstol) {
  rcb_frf *f = NULL;
  rcb_transient *t = NULL;
  cli_out out;
  int rc;
  rcb_status st = rcb_frf_create(&f, m, ch->n, ch->dofs, 0, NULL, RCB_SOLVER_AUTO, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "timecheck: %s",
                  cli_msg(f ? rcb_frf_errmsg(f) : rcb_model_errmsg(m), st));
    rcb_frf_destroy(f);
    return rc;
  }
  st = rcb_transient_create(&t, m, ch->n, ch->dofs, NULL);
  if (!st) st = rcb_transient_set_tolerances(t, rtol, 1e-13, 1e-10);
  if (!st) st = rcb_transient_set_steady(t, sstol, 32, 20000);
  if (st)
    rc = cli_fail(cli_status_exit(st), "timecheck: %s",
                  cli_msg(t ? rcb_transient_errmsg(t) : rcb_model_errmsg(m), st));
  else if (!(rc = tc_sweep(a, f, t, j)) && !(rc = cli_out_open(&out, a))) {
    (a->json ? tc_json : tc_csv)(out.fp, j, ch);
    rc = cli_out_close(&out);
  }
  rcb_transient_destroy(t);
  rcb_frf_destroy(f);
  return rc;
}

int cmd_timecheck(int argc, char **argv) {
  cli_opt opts[] = {{"--out", "CH,...", NULL},  {"--rpm-min", "A", NULL},
                    {"--rpm-max", "B", NULL},   {"--points", "N", NULL},
                    {"--rtol", "X", NULL},      {"--steady-tol", "X", NULL}};
  cli_args a;
  cli_channels ch = {0};
  tc_job j = {0};
  rcb_model *m = NULL;
  double lo, hi, rtol, sstol;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_timecheck);
  if ((rc = cli_opt_require(&a, "--out", "output channels STATION.DIR[,...]")) ||
      (rc = cli_opt_require(&a, "--rpm-max", "the highest rotor speed in rpm")) ||
      (rc = cli_opt_nonneg(&a, "--rpm-max", "rpm", 0.0, &hi)) ||
      (rc = cli_opt_nonneg(&a, "--rpm-min", "rpm", hi, &lo)) ||
      (rc = cli_opt_count(&a, "--points", 10, &j.npts)) ||
      (rc = cli_opt_nonneg(&a, "--rtol", "-", 1e-7, &rtol)) ||
      (rc = cli_opt_nonneg(&a, "--steady-tol", "-", 1e-5, &sstol)))
    return rc;
  if (!(lo > 0.0) || lo > hi)
    return cli_usage(a.cmd, "speeds %g..%g rpm; expected 0 < rpm-min <= rpm-max", lo, hi);
  if ((rc = cli_load_model(&a, &m))) return rc;
  if (!(rc = cli_channels_parse(&a, m, "--out", &ch))) {
    j.nout = ch.n;
    j.rpm = malloc(j.npts * sizeof *j.rpm);
    j.steps = malloc(j.npts * sizeof *j.steps);
    j.revs = malloc(j.npts * sizeof *j.revs);
    j.qf = malloc(j.npts * ch.n * sizeof *j.qf);
    j.qt = malloc(j.npts * ch.n * sizeof *j.qt);
    if (!j.rpm || !j.steps || !j.revs || !j.qf || !j.qt)
      rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    else {
      cli_linspace(lo, hi, j.npts, j.rpm);
      rc = tc_run(&a, m, &ch, &j, rtol, sstol);
    }
  }
  free(j.rpm);
  free(j.steps);
  free(j.revs);
  free(j.qf);
  free(j.qt);
  cli_channels_free(&ch);
  rcb_model_destroy(m);
  return rc;
}
