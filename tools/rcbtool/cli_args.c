/* rcbtool: command-line option parsing and typed option values. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

/* "--name" or "--name=value": does @p arg name option @p name? */
static int names(const char *arg, const char *name) {
  size_t n = strlen(name);
  return strncmp(arg, name, n) == 0 && (arg[n] == '\0' || arg[n] == '=');
}

/* The options a command accepts, for the "unknown option" message. */
static void list_options(const cli_args *a, char *buf, size_t size) {
  size_t i, len = 0;
  buf[0] = '\0';
  for (i = 0; i < a->nopts && len < size; i++) {
    int k = snprintf(buf + len, size - len, "%s%s", a->opts[i].name,
                     a->opts[i].metavar ? " " : "");
    if (k > 0) len += (size_t)k;
    if (a->opts[i].metavar && len < size) {
      k = snprintf(buf + len, size - len, "%s", a->opts[i].metavar);
      if (k > 0) len += (size_t)k;
    }
    if (len < size) {
      k = snprintf(buf + len, size - len, ", ");
      if (k > 0) len += (size_t)k;
    }
  }
  if (len < size) snprintf(buf + len, size - len, "-o FILE, --json, --progress, --max-output MB, --help");
}

/* Take the value of option @p name: after '=' or the next argument. */
static int take_value(const cli_args *a, int argc, char **argv, int *k, const char *name,
                      const char *metavar, const char **value) {
  const char *eq = strchr(argv[*k], '=');
  if (eq) {
    *value = eq + 1;
  } else if (*k + 1 < argc) {
    *value = argv[++*k];
  } else {
    return cli_usage(a->cmd, "option %s expects a value (%s)", name, metavar);
  }
  if (**value == '\0')
    return cli_usage(a->cmd, "option %s expects a value (%s), got an empty string", name,
                     metavar);
  return 0;
}

/* -o/--output, --json, --progress, --help: 1 if @p argv[*k] was one of them. */
static int parse_common(cli_args *a, int argc, char **argv, int *k, int *rc) {
  const char *arg = argv[*k];
  *rc = 0;
  if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
    a->help = 1;
  } else if (strcmp(arg, "--json") == 0) {
    a->json = 1;
  } else if (strcmp(arg, "--progress") == 0) {
    a->progress = 1;
  } else if (names(arg, "--max-output")) {
    const char *v = NULL;
    char *end;
    if (a->max_output_mb > 0) *rc = cli_usage(a->cmd, "option --max-output given twice");
    if (!*rc) *rc = take_value(a, argc, argv, k, "--max-output", "MB", &v);
    if (!*rc) {
      a->max_output_mb = strtod(v, &end);
      if (*end || !(a->max_output_mb > 0) || !isfinite(a->max_output_mb))
        *rc = cli_usage(a->cmd, "option --max-output expects a size in MB > 0, got '%s'", v);
    }
  } else if (strcmp(arg, "-o") == 0 || names(arg, "--output")) {
    if (a->output) *rc = cli_usage(a->cmd, "option -o/--output given twice");
    if (!*rc) *rc = take_value(a, argc, argv, k, "-o", "FILE", &a->output);
  } else {
    return 0;
  }
  return 1;
}

/* A command option: 1 if recognised (value stored or error in *rc). */
static int parse_own(cli_args *a, int argc, char **argv, int *k, int *rc) {
  size_t i;
  const char *arg = argv[*k];
  *rc = 0;
  for (i = 0; i < a->nopts; i++) {
    cli_opt *o = &a->opts[i];
    if (!names(arg, o->name)) continue;
    if (o->value) {
      *rc = cli_usage(a->cmd, "option %s given twice", o->name);
    } else if (o->metavar) {
      *rc = take_value(a, argc, argv, k, o->name, o->metavar, &o->value);
    } else if (strchr(arg, '=')) {
      *rc = cli_usage(a->cmd, "option %s takes no value", o->name);
    } else {
      o->value = "";
    }
    return 1;
  }
  return 0;
}

/* The first positional argument is the model (or the signals file, ...: what
 * the usage line names); a command may take several files (@p max). */
static int positional(cli_args *a, const char *arg, size_t max) {
  if (a->nfiles >= max) {
    if (max > 1)
      return cli_usage(a->cmd, "unexpected argument '%s': at most %zu %s files", arg, max,
                       cli_plan_positional());
    return cli_usage(a->cmd, "unexpected argument '%s' (the %s file is already '%s')", arg,
                     cli_plan_positional(), a->model);
  }
  a->files[a->nfiles++] = arg;
  if (!a->model) a->model = arg;
  return 0;
}

int cli_parse(int argc, char **argv, cli_opt *opts, size_t nopts, cli_args *a) {
  return cli_parse_files(argc, argv, opts, nopts, 1, a);
}

int cli_parse_files(int argc, char **argv, cli_opt *opts, size_t nopts, size_t max_files,
                    cli_args *a) {
  int k, rc = 0, only_positional = 0;
  size_t i;
  memset(a, 0, sizeof *a);
  a->cmd = argv[0];
  a->opts = opts;
  a->nopts = nopts;
  for (i = 0; i < nopts; i++) opts[i].value = NULL;
  for (k = 1; k < argc && !rc; k++) {
    const char *arg = argv[k];
    if (only_positional || arg[0] != '-' || arg[1] == '\0') {
      rc = positional(a, arg, max_files < CLI_FILES_MAX ? max_files : CLI_FILES_MAX);
    } else if (strcmp(arg, "--") == 0) {
      only_positional = 1;
    } else if (!parse_common(a, argc, argv, &k, &rc) && !parse_own(a, argc, argv, &k, &rc)) {
      char known[512];
      list_options(a, known, sizeof known);
      rc = cli_usage(a->cmd, "unknown option '%s'; expected one of: %s", arg, known);
    }
  }
  if (!rc && !a->help && !a->model)
    rc = cli_usage(a->cmd, "missing the model file: expected 'rcbtool %s MODEL.ini [options]'",
                   a->cmd);
  if (!rc && !a->help) rc = cli_plan_args(a); /* before any work: the run's files */
  return rc;
}

const char *cli_opt_value(const cli_args *a, const char *name) {
  size_t i;
  for (i = 0; i < a->nopts; i++)
    if (strcmp(a->opts[i].name, name) == 0) return a->opts[i].value;
  return NULL;
}

int cli_opt_double(const cli_args *a, const char *name, const char *unit, double def,
                   double *out) {
  const char *s = cli_opt_value(a, name);
  char *end;
  double v;
  if (!s) {
    *out = def;
    return 0;
  }
  errno = 0;
  v = strtod(s, &end);
  if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v))
    return cli_usage(a->cmd, "option %s expects a finite number (%s), got '%s'", name, unit,
                     s);
  *out = v;
  return 0;
}

int cli_noise_opt(const cli_args *a, const char *opt, double *x, double *y, double *ph) {
  const char *s = cli_opt_value(a, opt), *t = s ? strchr(s, ',') : NULL, *u;
  char *e1, *e2, *e3 = NULL;
  if (!s) return 0;
  if (!t) return cli_usage(a->cmd, "option %s expects BETA_A,BETA_S[,PHASE_DEG]: two or three "
                           "numbers separated by ',' (e.g. 10,1 or 10,1,2)", opt);
  u = strchr(t + 1, ',');
  *x = strtod(s, &e1);
  *y = strtod(t + 1, &e2);
  *ph = u ? strtod(u + 1, &e3) : 0.0;
  if (e1 != t || (u ? e2 != u || *e3 : *e2 != 0) || !(*x >= 0) || !(*y >= 0) ||
      !isfinite(*x) || !isfinite(*y) || !(*ph >= 0 && *ph < 90))
    return cli_usage(a->cmd, "option %s expects BETA_A,BETA_S[,PHASE_DEG]: BETA_A, BETA_S >= 0 "
                     "(%%), PHASE_DEG a phase noise 0 <= P < 90 (degrees), got '%s'", opt, s);
  return 0;
}

int cli_opt_nonneg(const cli_args *a, const char *name, const char *unit, double def,
                   double *out) {
  int rc = cli_opt_double(a, name, unit, def, out);
  if (!rc && *out < 0.0)
    return cli_usage(a->cmd, "option %s expects a value >= 0 (%s), got %g", name, unit, *out);
  return rc;
}

int cli_opt_count(const cli_args *a, const char *name, size_t def, size_t *out) {
  const char *s = cli_opt_value(a, name);
  char *end;
  long v;
  if (!s) {
    *out = def;
    return 0;
  }
  errno = 0;
  v = strtol(s, &end, 10);
  if (end == s || *end != '\0' || errno == ERANGE || v < 1 || v > 100000000L)
    return cli_usage(a->cmd, "option %s expects a whole number >= 1, got '%s'", name, s);
  *out = (size_t)v;
  return 0;
}

int cli_opt_require(const cli_args *a, const char *name, const char *what) {
  if (cli_opt_value(a, name)) return 0;
  return cli_usage(a->cmd, "option %s is required: %s", name, what);
}

int cli_opt_choice(const cli_args *a, const char *name, const char *const *choices, size_t n,
                   int def, int *out) {
  const char *s = cli_opt_value(a, name);
  char list[256] = "";
  size_t i;
  if (!s) {
    *out = def;
    return 0;
  }
  for (i = 0; i < n; i++) {
    if (strcmp(s, choices[i]) == 0) {
      *out = (int)i;
      return 0;
    }
    if (strlen(list) + strlen(choices[i]) + 4 < sizeof list) {
      if (i) strcat(list, " | ");
      strcat(list, choices[i]);
    }
  }
  return cli_usage(a->cmd, "option %s expects one of %s, got '%s'", name, list, s);
}
