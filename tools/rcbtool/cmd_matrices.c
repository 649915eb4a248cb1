/* rcbtool matrices: global M, C, G, K at a rotor speed. */
#include <stdlib.h>

#include "cli.h"

const char cli_help_matrices[] =
    "usage: rcbtool matrices MODEL.ini [--rpm R] [--json] [-o FILE]\n"
    "\n"
    "Print the global matrices of M q'' + (C + Omega G) q' + K q = f after\n"
    "constraint elimination: M (kg), C (N s/m), G (multiplied by Omega), K (N/m).\n"
    "  --rpm R   rotor speed in rpm (default 0); selects the coefficients of\n"
    "            speed-dependent bearings\n"
    "\n"
    "CSV: matrix,row,col,value with one line per nonzero entry (0-based rows).\n"
    "JSON: {\"rpm\", \"ndof\", \"M\", \"C\", \"G\", \"K\" (row-major nested lists,\n"
    "\"%.17g\"), \"nodes\": [{\"node\", \"shaft\", \"z\", \"dof\": [4]}]}\n";

static void json_matrix(FILE *fp, const char *name, const double *A, size_t n) {
  size_t r;
  fprintf(fp, ",\n\"%s\": [", name);
  for (r = 0; r < n; r++) {
    fputs(r ? ",\n  " : "\n  ", fp);
    cli_json_nums(fp, A + r, n, n); /* row r of a column-major matrix */
  }
  fputs("]", fp);
}

static void csv_matrix(FILE *fp, const char *name, const double *A, size_t n) {
  size_t r, c;
  for (r = 0; r < n; r++)
    for (c = 0; c < n; c++)
      if (A[r + n * c] != 0.0) {
        fprintf(fp, "%s,%zu,%zu,", name, r, c);
        cli_csv_num(fp, A[r + n * c]);
        fputc('\n', fp);
      }
}

static void write_out(FILE *fp, const cli_args *a, const rcb_model *m, double rpm,
                      double *const mats[4]) {
  static const char *const names[4] = {"M", "C", "G", "K"};
  size_t n = rcb_model_dof_count(m);
  int k;
  if (!a->json) {
    fputs("matrix,row,col,value\n", fp);
    for (k = 0; k < 4; k++) csv_matrix(fp, names[k], mats[k], n);
    return;
  }
  fputs("{\"rpm\": ", fp);
  cli_json_num(fp, rpm);
  fprintf(fp, ", \"ndof\": %zu", n);
  for (k = 0; k < 4; k++) json_matrix(fp, names[k], mats[k], n);
  fputs(",\n\"nodes\": ", fp);
  cli_json_nodes(fp, m);
  fputs("}\n", fp);
}

static int run(const cli_args *a, rcb_model *m, double rpm) {
  size_t n = rcb_model_dof_count(m);
  double *buf = calloc(4 * n * n, sizeof *buf);
  double *mats[4];
  rcb_status st;
  cli_out o;
  int rc, k;
  if (!buf) return cli_fail(CLI_EXIT_NUMERIC, "out of memory for %zu x %zu matrices", n, n);
  for (k = 0; k < 4; k++) mats[k] = buf + (size_t)k * n * n;
  st = rcb_model_matrices(m, rpm * CLI_RPM_TO_RAD_S, mats[0], mats[1], mats[2], mats[3]);
  if (st) {
    rc = cli_fail(cli_status_exit(st), "matrices: %s", cli_msg(rcb_model_errmsg(m), st));
  } else if (!(rc = cli_out_open(&o, a))) {
    write_out(o.fp, a, m, rpm, mats);
    rc = cli_out_close(&o);
  }
  free(buf);
  return rc;
}

int cmd_matrices(int argc, char **argv) {
  cli_opt opts[] = {{"--rpm", "R", NULL}};
  cli_args a;
  rcb_model *m = NULL;
  double rpm;
  int rc = cli_parse(argc, argv, opts, sizeof opts / sizeof opts[0], &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_matrices);
  if ((rc = cli_opt_nonneg(&a, "--rpm", "rotor speed, rpm", 0.0, &rpm))) return rc;
  if ((rc = cli_load_model(&a, &m))) return rc;
  rc = run(&a, m, rpm);
  rcb_model_destroy(m);
  return rc;
}
