/* rcbtool modes: damped modes at one rotor speed. */
#include <complex.h>
#include <stdlib.h>

#include "cli.h"

const char cli_help_modes[] =
    "usage: rcbtool modes MODEL.ini [--rpm R] [--modes N] [--max-zeta Z] [--json] [-o FILE]\n"
    "\n"
    "Damped modes from the state-space eigenproblem at rotor speed R, sorted by\n"
    "increasing damped frequency; only oscillating modes (wd > 0) are listed.\n"
    "  --rpm R     rotor speed, rpm (default 0)\n"
    "  --modes N   how many modes at most (default 10)\n"
    "  --max-zeta Z  leave out roots with damping ratio above Z (default "
    CLI_STR(RCB_MODES_MAX_ZETA_DEFAULT) ":\n"
    "              near-critically damped roots of stiffness-proportional damping\n"
    "              are not modes anyone measures; 1 keeps every root, as ROSS)\n"
    "\n"
    "lambda = -zeta wn + i wd; wn = |lambda| (rad/s), wd (rad/s), fd_hz = wd/(2 pi),\n"
    "zeta (-), logdec = 2 pi zeta / sqrt(1 - zeta^2), whirl forward|backward|mixed.\n"
    "CSV: mode,wn_rad_s,wd_rad_s,fd_hz,zeta,logdec,whirl (mode numbered from 1).\n"
    "JSON: {\"rpm\": R, \"modes\": [{\"wn\", \"wd\", \"fd_hz\", \"zeta\", \"logdec\",\n"
    "\"whirl\", \"re\": Re(lambda), \"im\": Im(lambda)}]}\n";

#define MODES_DEFAULT 10

static void write_csv(FILE *fp, const rcb_mode *md, size_t n) {
  size_t k;
  fputs("mode,wn_rad_s,wd_rad_s,fd_hz,zeta,logdec,whirl\n", fp);
  for (k = 0; k < n; k++) {
    const double v[5] = {md[k].wn, md[k].wd, md[k].wd / CLI_HZ_TO_RAD_S, md[k].zeta,
                         md[k].logdec};
    int c;
    fprintf(fp, "%zu", k + 1);
    for (c = 0; c < 5; c++) {
      fputc(',', fp);
      cli_csv_num(fp, v[c]);
    }
    fprintf(fp, ",%s\n", cli_whirl_name(md[k].whirl));
  }
}

static void write_json(FILE *fp, double rpm, const rcb_mode *md, size_t n) {
  size_t k;
  fputs("{\"rpm\": ", fp);
  cli_json_num(fp, rpm);
  fputs(", \"modes\": [", fp);
  for (k = 0; k < n; k++) {
    fputs(k ? ",\n  {\"wn\": " : "\n  {\"wn\": ", fp);
    cli_json_num(fp, md[k].wn);
    fputs(", \"wd\": ", fp);
    cli_json_num(fp, md[k].wd);
    fputs(", \"fd_hz\": ", fp);
    cli_json_num(fp, md[k].wd / CLI_HZ_TO_RAD_S);
    fputs(", \"zeta\": ", fp);
    cli_json_num(fp, md[k].zeta);
    fputs(", \"logdec\": ", fp);
    cli_json_num(fp, md[k].logdec);
    fprintf(fp, ", \"whirl\": \"%s\", \"re\": ", cli_whirl_name(md[k].whirl));
    cli_json_num(fp, creal(md[k].lambda));
    fputs(", \"im\": ", fp);
    cli_json_num(fp, cimag(md[k].lambda));
    fputs("}", fp);
  }
  fputs("]}\n", fp);
}

static int run(const cli_args *a, const rcb_model *m, double rpm, size_t want, double zmax) {
  rcb_modes *e = NULL;
  rcb_mode *md = malloc(want * sizeof *md);
  size_t n = 0;
  cli_out o;
  int rc = 0;
  rcb_status st = md ? rcb_modes_create(&e, m, NULL) : RCB_ERR_NOMEM;
  if (!st) st = rcb_modes_set_max_zeta(e, zmax);
  if (!st) st = rcb_modes_compute(e, rpm * CLI_RPM_TO_RAD_S, want, md, &n, NULL);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "modes: %s",
                  cli_msg(e ? rcb_modes_errmsg(e) : rcb_model_errmsg(m), st));
  } else if (!(rc = cli_out_open(&o, a))) {
    if (a->json)
      write_json(o.fp, rpm, md, n);
    else
      write_csv(o.fp, md, n);
    rc = cli_out_close(&o);
  }
  rcb_modes_destroy(e);
  free(md);
  return rc;
}

int cmd_modes(int argc, char **argv) {
  cli_opt opts[] = {{"--rpm", "R", NULL}, {"--modes", "N", NULL}, {"--max-zeta", "Z", NULL}};
  cli_args a;
  rcb_model *m = NULL;
  double rpm, zmax;
  size_t want;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_modes);
  if ((rc = cli_opt_nonneg(&a, "--rpm", "rotor speed, rpm", 0.0, &rpm)) ||
      (rc = cli_opt_count(&a, "--modes", MODES_DEFAULT, &want)) ||
      (rc = cli_opt_nonneg(&a, "--max-zeta", "damping ratio", RCB_MODES_MAX_ZETA_DEFAULT, &zmax)))
    return rc;
  if ((rc = cli_load_model(&a, &m))) return rc;
  rc = run(&a, m, rpm, want, zmax);
  rcb_model_destroy(m);
  return rc;
}
