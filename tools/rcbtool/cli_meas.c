/* Commands that take a model and a measurement (fit, compare, diagnose):
 * both positional, and the measurement read by its extension. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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
  cli_plan_input(*meas, "measurement"); /* checked with the rest by cli_parse */
  if ((rc = cli_parse(nargs, *args, opts, nopts, a))) return rc;
  if (a->help) return (rc = cli_print_help(help)) ? rc : -1;
  if (!*meas) return cli_usage(a->cmd, "missing the measurement file: expected %s", expected);
  if (strcmp(a->model, "-") == 0 && strcmp(*meas, "-") == 0)
    return cli_usage(a->cmd, "the model and the measurement cannot both come from standard "
                     "input ('-'); give one of them as a file");
  return cli_guard_outputs(a, *meas);
}

int cli_guard_outputs(const cli_args *a, const char *meas) {
  static const char *const plot_files[] = {"_compare.json", "_overlay.png",
                                           "_residual_map.png"};
  const char *plot = cli_opt_value(a, "--plot"), *hist = cli_opt_value(a, "--history");
  size_t i;
  int rc = 0;
  /* before any work: the files --plot PREFIX writes join the run's plan */
  cli_plan_input(meas, "measurement");
  for (i = 0; plot && i < sizeof plot_files / sizeof plot_files[0]; i++) {
    char *name = malloc(strlen(plot) + strlen(plot_files[i]) + 1);
    if (!name) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    strcpy(name, plot);
    strcat(name, plot_files[i]);
    cli_plan_output(name, "--plot", CLI_IO_MKDIR);
    free(name);
  }
  if ((rc = cli_plan_check())) return rc;
  return hist ? cli_history_check(hist) : 0;
}

/* A measurement on standard input goes to a temporary file (on the signal
 * handler's list, removed after reading); UFF when its first field is the
 * "-1" delimiter, else CSV. */
static int stdin_to_file(char *path, size_t size, int *slot, int *is_uff) {
  const char *dir = getenv("TMPDIR"), *p;
  size_t len = 0;
  char *text;
  FILE *fp;
  int fd, ok, e;
  *slot = -1;
  if (!(text = cli_read_stdin(&len))) return CLI_EXIT_INPUT;
  for (p = text; p < text + len && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n'); p++) {
  }
  *is_uff = p + 1 < text + len && p[0] == '-' && p[1] == '1';
  snprintf(path, size, "%s/rcbtool-stdin-XXXXXX", dir && *dir ? dir : "/tmp");
  fp = (fd = cli_mkstemp(path, slot)) >= 0 ? fdopen(fd, "wb") : NULL;
  if (!fp) {
    if (fd >= 0) {
      close(fd);
      remove(path);
      cli_tmp_release(*slot);
    }
    free(text);
    return cli_fail(CLI_EXIT_IO, "cannot copy the measurement from standard input to a "
                    "temporary file in %s (set TMPDIR)", dir && *dir ? dir : "/tmp");
  }
  errno = 0;
  ok = fwrite(text, 1, len, fp) == len;
  e = errno;
  if (fclose(fp) != 0 && ok) {
    ok = 0;
    e = errno;
  }
  free(text);
  if (!ok) {
    remove(path);
    cli_tmp_release(*slot);
    return cli_fail(cli_errno_exit(e ? e : EIO), "cannot write a temporary copy of standard "
                    "input in %s: %s (set TMPDIR)", dir && *dir ? dir : "/tmp",
                    strerror(e ? e : EIO));
  }
  return 0;
}

static int meas_read(const cli_args *a, const char *path, const rcb_model *m, int is_uff,
                     rcb_meas **out);
static int cli_meas_speed_and_warnings(const cli_args *a, const rcb_model *m, rcb_meas *ms,
                                       const char *path);

int cli_meas_read(const cli_args *a, const char *path, const rcb_model *m,
                     rcb_meas **out) {
  int is_uff = 0, rc, slot = -1, from_stdin = strcmp(path, "-") == 0;
  char tmp[4200];
  *out = NULL;
  if (from_stdin) {
    if ((rc = stdin_to_file(tmp, sizeof tmp, &slot, &is_uff))) return rc;
    path = tmp;
  } else if ((rc = cli_meas_format(a->cmd, path, &is_uff))) {
    return rc;
  }
  cli_plan_input(path, "measurement");
  rc = meas_read(a, path, m, is_uff, out);
  if (from_stdin) {
    if (rc) fputs("rcbtool: (the measurement came from standard input)\n", stderr);
    remove(tmp);
    cli_tmp_release(slot);
  }
  return rc;
}

static int meas_read(const cli_args *a, const char *path, const rcb_model *m, int is_uff,
                     rcb_meas **out) {
  cli_uff_map mp;
  rcb_meas *ms = NULL;
  rcb_status st;
  int rc;
  if ((rc = cli_uff_map_parse(a, "--map", m, &mp))) {
    cli_uff_map_free(&mp);
    return rc;
  }
  if (rcb_meas_create(&ms, NULL)) {
    cli_uff_map_free(&mp);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  /* CSV too: stations written as node numbers ("2.x/11.x_re", issue #35) */
  st = is_uff ? rcb_meas_read_uff(ms, path, mp.n, mp.nodes)
              : rcb_meas_read_csv_map(ms, path, mp.n, mp.nodes);
  cli_uff_map_free(&mp);
  if (st) {
    size_t w; /* what was skipped, and the map entry that would read it */
    for (w = 0; w < rcb_meas_warning_count(ms); w++)
      fprintf(stderr, "rcbtool: warning: %s\n", rcb_meas_warning(ms, w));
  }
  if (st) {
    const char *msg = cli_msg(rcb_meas_errmsg(ms), st);
    rc = cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "%s", msg);
    if (!strstr(msg, path)) (void)cli_fail(rc, "(while reading measurement '%s')", path);
    rcb_meas_destroy(ms);
    return rc;
  }
  if ((rc = cli_meas_speed_and_warnings(a, m, ms, path))) {
    rcb_meas_destroy(ms);
    return rc;
  }
  *out = ms;
  return 0;
}


/* The rotor speed of an FRF test (issue #17): --rpm, else what the file
 * states, else the model's [test] rpm; a mismatch or a speed nobody stated
 * is said on stderr. */
static int test_speed(const cli_args *a, const rcb_model *m, rcb_meas *ms, const char *path) {
  double rpm = 0.0, model_w = 0.0;
  int have_model = m && rcb_model_get_test_speed(m, &model_w) == RCB_OK, rc;
  double file_rpm = rcb_meas_speed(ms) * 30.0 / CLI_PI;
  if (cli_opt_value(a, "--rpm")) {
    if (rcb_meas_get_type(ms) != RCB_MEAS_FRF)
      return cli_usage(a->cmd, "--rpm applies to FRF measurements ('%s' holds unbalance "
                       "responses, whose speeds are their abscissa)", path);
    if ((rc = cli_opt_nonneg(a, "--rpm", "rpm", 0.0, &rpm))) return rc;
    if (rcb_meas_speed_given(ms) && rcb_meas_speed(ms) >= 0.0 && fabs(file_rpm - rpm) > 1e-9 * rpm)
      fprintf(stderr, "rcbtool: note: --rpm %g replaces the speed '%s' states (%g rpm)\n", rpm,
              path, file_rpm);
    return rcb_meas_set_speed(ms, rpm * CLI_RPM_TO_RAD_S) ? cli_fail(CLI_EXIT_INPUT, "%s",
                                                                     rcb_meas_errmsg(ms))
                                                          : 0;
  }
  if (rcb_meas_get_type(ms) != RCB_MEAS_FRF || !have_model) return 0;
  rpm = model_w * 30.0 / CLI_PI;
  if (!rcb_meas_speed_given(ms)) {
    fprintf(stderr, "rcbtool: note: '%s' does not state the rotor speed; using the model's "
            "[test] rpm = %g\n", path, rpm);
    return rcb_meas_set_speed(ms, model_w) ? cli_fail(CLI_EXIT_INPUT, "%s", rcb_meas_errmsg(ms))
                                           : 0;
  }
  if (rcb_meas_speed(ms) >= 0.0 && fabs(file_rpm - rpm) > 1e-6 * (rpm > 1.0 ? rpm : 1.0))
    fprintf(stderr, "rcbtool: warning: '%s' states %g rpm, the model's [test] rpm is %g; "
            "comparing at the file's %g rpm (--rpm R to choose)\n", path, file_rpm, rpm,
            file_rpm);
  return 0;
}

static int cli_meas_speed_and_warnings(const cli_args *a, const rcb_model *m, rcb_meas *ms,
                                       const char *path) {
  size_t w;
  int rc = test_speed(a, m, ms, path);
  if (rc) return rc;
  for (w = 0; w < rcb_meas_warning_count(ms); w++)
    fprintf(stderr, "rcbtool: warning: %s\n", rcb_meas_warning(ms, w));
  return 0;
}

int cli_meas_need_phase(const cli_args *a, const rcb_meas *ms, const char *path,
                        const char *what) {
  size_t n = rcb_meas_magnitude_only_count(ms), c;
  rcb_meas_channel_info ci;
  if (n == 0) return 0;
  for (c = 0; rcb_meas_channel(ms, c, &ci) == RCB_OK && !ci.magnitude_only; c++) continue;
  return cli_usage(a->cmd, "'%s' holds magnitudes only (%zu of %zu channels, e.g. %s%s%s: a "
                   "'mag' or 'dB' column without phase): %s needs the phase; %s", path, n,
                   rcb_meas_channel_count(ms), ci.response, ci.reference ? "/" : "",
                   ci.reference ? ci.reference : "", what,
                   strstr(what, "scale") ? "fit on --scale log10, linear or db (the magnitudes "
                                           "alone)"
                                         : "give a file with phase (re/im or mag/phase_deg)");
}
