/* rcbtool campbell: damped frequencies over a speed range and 1X critical speeds. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_campbell[] =
    "usage: rcbtool campbell MODEL.ini --rpm-max B [--rpm-min A] [--points N]\n"
    "                        [--modes N] [--max-zeta Z] [--json] [-o FILE] [--progress]\n"
    "\n"
    "Campbell diagram data: the first N damped modes (by increasing frequency) at\n"
    "speeds Omega_i = A + i (B - A)/(P - 1), and the 1X critical speeds, where a\n"
    "curve crosses wd = Omega (linear interpolation between speeds).\n"
    "  --rpm-min A   first speed, rpm (default 0)\n"
    "  --rpm-max B   last speed, rpm (required, >= rpm-min)\n"
    "  --points P    number of speeds (default 50, >= 1; with P > 1 rpm-min < rpm-max)\n"
    "  --modes N     curves per speed (default 6)\n"
    "  --max-zeta Z  leave out roots with damping ratio above Z (default "
    CLI_STR(RCB_MODES_MAX_ZETA_DEFAULT) ")\n"
    "\n"
    "CSV: lines \"# kind = campbell\", \"# critical_rpm = ...\" and \"# critical_mode =\n"
    "...\", then one table rpm,fd1_hz..fdN_hz,logdec1..logdecN,whirl1..whirlN (nan\n"
    "and an empty whirl where fewer modes exist). With -o FILE.csv the critical\n"
    "speeds also go to FILE_critical.csv, a table critical_rpm,mode.\n"
    "JSON: {\"rpm\": [...], \"fd_hz\": [[per mode] per speed], \"logdec\": [[...]],\n"
    "\"whirl\": [[...]], \"critical_rpm\": [...], \"critical_mode\": [...]}\n"
    "(null where fewer modes exist; critical_mode numbered from 1).\n";

typedef struct camp_job {
  size_t ns, nm;   /* speeds, modes */
  double max_zeta; /* roots with a larger damping ratio are left out */
  double *rpm;     /* rpm, ns */
  double *speed;   /* rad/s, ns */
  double *wd;      /* rad/s, nm x ns column-major */
  double *logdec;  /* -, nm x ns */
  rcb_whirl *whirl; /* nm x ns */
  double *crit;    /* critical speeds, rad/s */
  size_t *crit_mode, ncrit;
} camp_job;

static int alloc_job(camp_job *j) {
  size_t t = j->ns * j->nm;
  j->rpm = malloc(j->ns * sizeof *j->rpm);
  j->speed = malloc(j->ns * sizeof *j->speed);
  /* calloc: the static analyzer cannot see rcb_campbell fill them */
  j->wd = calloc(t, sizeof *j->wd);
  j->logdec = calloc(t, sizeof *j->logdec);
  j->whirl = calloc(t, sizeof *j->whirl);
  j->crit = calloc(t, sizeof *j->crit);
  j->crit_mode = calloc(t, sizeof *j->crit_mode);
  if (!j->rpm || !j->speed || !j->wd || !j->logdec || !j->whirl || !j->crit || !j->crit_mode)
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  return 0;
}

static void free_job(camp_job *j) {
  free(j->rpm);
  free(j->speed);
  free(j->wd);
  free(j->logdec);
  free(j->whirl);
  free(j->crit);
  free(j->crit_mode);
}

/* One rcb_campbell call per speed (the library sorts modes per speed), so the
 * progress line can follow the sweep. */
static int sweep(const cli_args *a, camp_job *j, rcb_modes *e) {
  size_t i, off, ncrit = 0;
  rcb_status st = RCB_OK;
  cli_progress pr;
  cli_progress_start(&pr, a, "campbell", "speeds", j->ns);
  for (i = 0; i < j->ns && !st; i++) {
    off = i * j->nm;
    st = rcb_campbell(e, 1, &j->speed[i], j->nm, j->wd + off, j->logdec + off,
                      j->whirl + off);
    if (st) break;
    cli_progress_step(&pr, i + 1);
  }
  cli_progress_end(&pr);
  if (st)
    return cli_fail(cli_status_exit(st), "campbell at %.17g rpm: %s", j->rpm[i],
                    cli_msg(rcb_modes_errmsg(e), st));
  if (j->ns < 2) return 0; /* one speed: no crossing can be located */
  /* a local count: &j->ncrit would let the analyzer forget j's other pointers */
  st = rcb_critical_speeds(j->ns, j->speed, j->nm, j->wd, 1.0, j->ns * j->nm, j->crit,
                           j->crit_mode, &ncrit);
  j->ncrit = ncrit;
  if (st) return cli_fail(cli_status_exit(st), "critical speeds: %s", rcb_status_str(st));
  return 0;
}

static int compute(const cli_args *a, const rcb_model *m, camp_job *j) {
  rcb_modes *e = NULL;
  int rc;
  rcb_status st = rcb_modes_create(&e, m, NULL);
  if (!st) st = rcb_modes_set_max_zeta(e, j->max_zeta);
  if (st)
    rc = cli_fail(cli_status_exit(st), "campbell: %s",
                  cli_msg(e ? rcb_modes_errmsg(e) : rcb_model_errmsg(m), st));
  else
    rc = sweep(a, j, e);
  rcb_modes_destroy(e);
  return rc;
}

/* The 1X critical speeds as "# critical_rpm = a, b" and "# critical_mode = i, j"
 * lines: the speed table below them stays one table a CSV reader loads. */
static void write_crit_comments(FILE *fp, const camp_job *j) {
  size_t k;
  fputs("# critical_rpm =", fp);
  for (k = 0; k < j->ncrit; k++) {
    fputs(k ? ", " : " ", fp);
    cli_csv_num(fp, j->crit[k] / CLI_RPM_TO_RAD_S);
  }
  fputs("\n# critical_mode =", fp);
  for (k = 0; k < j->ncrit; k++) fprintf(fp, "%s%zu", k ? ", " : " ", j->crit_mode[k] + 1);
  fputc('\n', fp);
}

/* The critical speeds as their own table (the second file of -o FILE). */
static void write_crit_csv(FILE *fp, const camp_job *j) {
  size_t k;
  fputs("# kind = campbell critical speeds (1X)\ncritical_rpm,mode\n", fp);
  for (k = 0; k < j->ncrit; k++) {
    cli_csv_num(fp, j->crit[k] / CLI_RPM_TO_RAD_S);
    fprintf(fp, ",%zu\n", j->crit_mode[k] + 1);
  }
}

static void write_csv(FILE *fp, const camp_job *j) {
  size_t i, k, nm = j->nm;
  fputs("# kind = campbell\n", fp);
  write_crit_comments(fp, j);
  fputs("rpm", fp);
  for (k = 1; k <= nm; k++) fprintf(fp, ",fd%zu_hz", k);
  for (k = 1; k <= nm; k++) fprintf(fp, ",logdec%zu", k);
  for (k = 1; k <= nm; k++) fprintf(fp, ",whirl%zu", k);
  fputc('\n', fp);
  for (i = 0; i < j->ns; i++) {
    const size_t off = i * nm;
    cli_csv_num(fp, j->rpm[i]);
    for (k = 0; k < nm; k++) {
      fputc(',', fp);
      cli_csv_num(fp, j->wd[off + k] / CLI_HZ_TO_RAD_S);
    }
    for (k = 0; k < nm; k++) {
      fputc(',', fp);
      cli_csv_num(fp, isnan(j->wd[off + k]) ? (double)NAN : j->logdec[off + k]);
    }
    for (k = 0; k < nm; k++)
      fprintf(fp, ",%s", isnan(j->wd[off + k]) ? "" : cli_whirl_name(j->whirl[off + k]));
    fputc('\n', fp);
  }
}

/* -o OUT.csv also writes OUT_critical.csv (NULL when out of memory). */
static char *critical_name(const char *output) {
  size_t n = output ? strlen(output) : 0;
  size_t stem = n >= 4 && strcmp(output + n - 4, ".csv") == 0 ? n - 4 : n;
  char *name = output ? malloc(stem + sizeof "_critical.csv") : NULL;
  if (!name) return NULL;
  memcpy(name, output, stem);
  strcpy(name + stem, "_critical.csv");
  return name;
}

/* -o FILE.csv: the critical speeds also go to FILE_critical.csv; both files
 * are renamed into place together (by the run's plan), or neither. */
static int write_csv_files(const cli_args *a, const camp_job *j, cli_out *o) {
  char *name = critical_name(a->output);
  cli_args ca = *a;
  cli_out c;
  int rc;
  write_csv(o->fp, j);
  if (!name) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  ca.output = name;
  if (!(rc = cli_out_flush(o)) && !(rc = cli_out_open(&c, &ca))) {
    write_crit_csv(c.fp, j);
    if ((rc = cli_out_flush(&c)) || (rc = cli_out_close(o)))
      cli_out_abort(&c);
    else
      rc = cli_out_close(&c);
  }
  cli_out_abort(o);
  free(name);
  return rc;
}

/* A per-speed list of per-mode values: [[...], [...]]; x NULL writes whirl names. */
static void json_table(FILE *fp, const char *key, const camp_job *j, const double *x,
                       double scale) {
  size_t i, k;
  fprintf(fp, ",\n\"%s\": [", key);
  for (i = 0; i < j->ns; i++) {
    fputs(i ? ",\n  [" : "\n  [", fp);
    for (k = 0; k < j->nm; k++) {
      size_t c = i * j->nm + k;
      fputs(k ? ", " : "", fp);
      if (isnan(j->wd[c]))
        fputs("null", fp); /* fewer modes than asked at this speed */
      else if (x)
        cli_json_num(fp, x[c] * scale);
      else
        fprintf(fp, "\"%s\"", cli_whirl_name(j->whirl[c]));
    }
    fputc(']', fp);
  }
  fputc(']', fp);
}

static void write_json(FILE *fp, const camp_job *j) {
  size_t k;
  fputs("{\"rpm\": ", fp);
  cli_json_nums(fp, j->rpm, j->ns, 1);
  json_table(fp, "fd_hz", j, j->wd, 1.0 / CLI_HZ_TO_RAD_S);
  json_table(fp, "logdec", j, j->logdec, 1.0);
  json_table(fp, "whirl", j, NULL, 0.0);
  fputs(",\n\"critical_rpm\": [", fp);
  for (k = 0; k < j->ncrit; k++) {
    fputs(k ? ", " : "", fp);
    cli_json_num(fp, j->crit[k] / CLI_RPM_TO_RAD_S);
  }
  fputs("],\n\"critical_mode\": [", fp);
  for (k = 0; k < j->ncrit; k++) fprintf(fp, "%s%zu", k ? ", " : "", j->crit_mode[k] + 1);
  fputs("]}\n", fp);
}

static int run(const cli_args *a, const rcb_model *m, camp_job *j, double lo, double hi) {
  cli_out o;
  size_t i;
  int rc = cli_check_size(a, (double)j->ns, 1.0 + 3.0 * (double)j->nm);
  if (rc || (rc = alloc_job(j))) return rc;
  cli_linspace(lo, hi, j->ns, j->rpm);
  for (i = 0; i < j->ns; i++) j->speed[i] = j->rpm[i] * CLI_RPM_TO_RAD_S;
  if ((rc = compute(a, m, j)) || (rc = cli_out_open(&o, a))) return rc;
  if (!a->json && o.tmp) return write_csv_files(a, j, &o);
  (a->json ? write_json : write_csv)(o.fp, j);
  return cli_out_close(&o);
}

static int parse_job(const cli_args *a, camp_job *j, double *lo, double *hi) {
  int rc;
  if ((rc = cli_opt_require(a, "--rpm-max", "the highest rotor speed in rpm")) ||
      (rc = cli_opt_nonneg(a, "--rpm-min", "rpm", 0.0, lo)) ||
      (rc = cli_opt_nonneg(a, "--rpm-max", "rpm", 0.0, hi)) ||
      (rc = cli_opt_count(a, "--points", 50, &j->ns)) ||
      (rc = cli_opt_count(a, "--modes", 6, &j->nm)) ||
      (rc = cli_opt_nonneg(a, "--max-zeta", "damping ratio", RCB_MODES_MAX_ZETA_DEFAULT, &j->max_zeta)))
    return rc;
  if (*lo > *hi)
    return cli_usage(a->cmd, "--rpm-min %g is above --rpm-max %g; expected rpm-min <= rpm-max",
                     *lo, *hi);
  if (*lo == *hi && j->ns > 1)
    return cli_usage(a->cmd, "%zu speeds between --rpm-min %g and --rpm-max %g; expected "
                     "rpm-min < rpm-max (or --points 1)", j->ns, *lo, *hi);
  return 0;
}

int cmd_campbell(int argc, char **argv) {
  cli_opt opts[] = {{"--rpm-min", "A", NULL},
                    {"--rpm-max", "B", NULL},
                    {"--points", "N", NULL},
                    {"--modes", "N", NULL},
                    {"--max-zeta", "Z", NULL}};
  camp_job j = {0};
  cli_args a;
  rcb_model *m = NULL;
  double lo = 0.0, hi = 0.0;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_campbell);
  if ((rc = parse_job(&a, &j, &lo, &hi))) return rc;
  if (a.output && !a.json && strcmp(a.output, "-") != 0) { /* the plan's side output */
    char *crit = critical_name(a.output);
    if (!crit) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    cli_plan_output(crit, "-o (critical speeds)", 0);
    free(crit);
    if ((rc = cli_plan_check())) return rc;
  }
  if ((rc = cli_load_model(&a, &m))) return rc;
  rc = run(&a, m, &j, lo, hi);
  free_job(&j);
  rcb_model_destroy(m);
  return rc;
}
