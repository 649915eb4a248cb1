/* Commands that take a model and a measurement (fit, compare, diagnose):
 * both positional, and the measurement read by its extension. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static int takes_value(const char *arg, const cli_opt *opts, size_t nopts) {
  size_t i;
  if (strchr(arg, '=')) return 0;
  if (strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0) return 1;
  for (i = 0; i < nopts; i++)
    if (opts[i].metavar && strcmp(arg, opts[i].name) == 0) return 1;
  return 0;
}

int cli_split_meas(int argc, char **argv, const cli_opt *opts, size_t nopts, char **args,
                   int *nargs, const char **meas) {
  int k, npos = 0, only_pos = 0, n = 0;
  *meas = NULL;
  for (k = 0; k < argc; k++) {
    const char *arg = argv[k];
    int pos = k > 0 && (only_pos || arg[0] != '-' || arg[1] == '\0');
    if (k > 0 && !only_pos && strcmp(arg, "--") == 0) only_pos = 1;
    if (pos && ++npos == 2) {
      *meas = arg;
      continue;
    }
    args[n++] = argv[k];
    if (k > 0 && !pos && !only_pos && takes_value(arg, opts, nopts) && k + 1 < argc)
      args[n++] = argv[++k];
  }
  *nargs = n;
  return npos;
}

int cli_parse_meas_cmd(int argc, char **argv, cli_opt *opts, size_t nopts, const char *help,
                       const char *expected, cli_args *a, const char **meas, char ***args) {
  int nargs = 0, rc;
  *meas = NULL;
  if (!(*args = malloc(((size_t)argc + 1) * sizeof **args)))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  cli_split_meas(argc, argv, opts, nopts, *args, &nargs, meas);
  if ((rc = cli_parse(nargs, *args, opts, nopts, a))) return rc;
  if (a->help) return (rc = cli_print_help(help)) ? rc : -1;
  if (!*meas) return cli_usage(a->cmd, "missing the measurement file: expected %s", expected);
  return 0;
}

int cli_meas_read(const cli_args *a, const char *path, const rcb_model *m,
                     rcb_meas **out) {
  cli_uff_map mp;
  rcb_meas *ms = NULL;
  rcb_status st;
  int is_uff = 0, rc;
  *out = NULL;
  if ((rc = cli_meas_format(a->cmd, path, &is_uff))) return rc;
  if ((rc = cli_uff_map_parse(a, "--map", m, &mp))) {
    cli_uff_map_free(&mp);
    return rc;
  }
  if (!is_uff && cli_opt_value(a, "--map")) {
    cli_uff_map_free(&mp);
    return cli_usage(a->cmd, "--map applies to UFF measurements only ('%s' is CSV)", path);
  }
  if (rcb_meas_create(&ms, NULL)) {
    cli_uff_map_free(&mp);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  st = is_uff ? rcb_meas_read_uff(ms, path, mp.n, mp.nodes) : rcb_meas_read_csv(ms, path);
  cli_uff_map_free(&mp);
  if (st) {
    const char *msg = cli_msg(rcb_meas_errmsg(ms), st);
    rc = cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "%s", msg);
    if (!strstr(msg, path)) fprintf(stderr, "rcbtool: (while reading measurement '%s')\n", path);
    rcb_meas_destroy(ms);
    return rc;
  }
  *out = ms;
  return 0;
}

