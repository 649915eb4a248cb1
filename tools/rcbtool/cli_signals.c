/* Reading a signal file by its extension (rcbtool estimate and order): CSV,
 * UFF dataset 58 time records (with --map), WAV (with --wav-names, --wav-units
 * and --wav-scale: WAV carries no names nor units). */
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static int ext_is(const char *path, const char *const *ext, size_t n) {
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  size_t i;
  if (!dot || (slash && dot < slash)) return 0;
  for (i = 0; i < n; i++)
    if (strcmp(dot, ext[i]) == 0) return 1;
  return 0;
}

/* Split option @p opt's comma list into *items (count *n); *buf owns the text. */
static int list(const cli_args *a, const char *opt, char **buf, char ***items, size_t *n) {
  const char *v = cli_opt_value(a, opt), *q;
  char *p;
  size_t k = 1;
  *buf = NULL;
  *items = NULL;
  *n = 0;
  if (!v) return 0;
  for (q = v; *q; q++) k += *q == ',';
  *buf = malloc(strlen(v) + 1);
  *items = malloc(k * sizeof **items);
  if (!*buf || !*items) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(*buf, v);
  for (p = *buf; p; (*n)++) {
    char *c = strchr(p, ',');
    if (c) *c = '\0';
    (*items)[*n] = p;
    p = c ? c + 1 : NULL;
  }
  return 0;
}

static int read_wav(const cli_args *a, const char *path, rcb_signals *s) {
  char *b[3] = {NULL, NULL, NULL}, **it[3] = {NULL, NULL, NULL};
  static const char *const opt[3] = {"--wav-names", "--wav-units", "--wav-scale"};
  size_t n[3] = {0, 0, 0}, k;
  double *scale = NULL;
  int rc = 0;
  rcb_status st;
  for (k = 0; k < 3 && !rc; k++) rc = list(a, opt[k], &b[k], &it[k], &n[k]);
  if (!rc && (n[0] == 0 || n[1] != n[0] || (n[2] && n[2] != n[0])))
    rc = cli_usage(a->cmd, "a WAV file needs --wav-names and --wav-units with one item per "
                   "channel (and optionally --wav-scale, the full scale in that unit)");
  if (!rc && !(scale = malloc(n[0] * sizeof *scale))) rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (k = 0; !rc && k < n[0]; k++) {
    char *end;
    scale[k] = n[2] ? strtod(it[2][k], &end) : 1.0;
    if (n[2] && (end == it[2][k] || *end))
      rc = cli_usage(a->cmd, "--wav-scale item '%s' is not a number", it[2][k]);
  }
  if (!rc) {
    st = rcb_signals_read_wav(s, path, n[0], (const char *const *)it[0],
                              (const char *const *)it[1], scale);
    if (st) rc = cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "%s",
                          cli_msg(rcb_signals_errmsg(s), st));
  }
  for (k = 0; k < 3; k++) {
    free(b[k]);
    free(it[k]);
  }
  free(scale);
  return rc;
}

/* --units CH=UNIT,...: the unit of channels whose label is missing or unknown. */
static int unit_overrides(const cli_args *a, rcb_signals *s) {
  char *buf, **it;
  size_t n, k;
  int rc = list(a, "--units", &buf, &it, &n);
  for (k = 0; !rc && k < n; k++) {
    char *eq = strrchr(it[k], '=');
    rcb_status st;
    if (!eq || eq == it[k] || !eq[1]) {
      rc = cli_usage(a->cmd, "--units item '%s': expected CH=UNIT (e.g. DA.x=mm)", it[k]);
      break;
    }
    *eq = '\0';
    if ((st = rcb_signals_set_unit(s, it[k], eq + 1)))
      rc = cli_usage(a->cmd, "--units: %s", cli_msg(rcb_signals_errmsg(s), st));
  }
  free(buf);
  free(it);
  return rc;
}

/* The reader's warnings (what was skipped, a truncated file read as allowed). */
static void warnings(const rcb_signals *s) {
  size_t w;
  for (w = 0; w < rcb_signals_warning_count(s); w++) cli_warn("%s", rcb_signals_warning(s, w));
}

static int read_file(const cli_args *a, const char *path, rcb_signals *s);

int cli_signals_read_path(const cli_args *a, const char *path, rcb_signals *s) {
  int rc;
  rcb_signals_set_allow_truncated(s, cli_opt_value(a, "--allow-truncated") != NULL);
  if ((rc = unit_overrides(a, s))) return rc;
  if (!(rc = read_file(a, path, s)) || rc == CLI_EXIT_INPUT) warnings(s); /* also why nothing was read */
  return rc;
}

int cli_signals_read(const cli_args *a, rcb_signals *s) {
  return cli_signals_read_path(a, a->model, s);
}

static int read_file(const cli_args *a, const char *path, rcb_signals *s) {
  static const char *const csv[] = {".csv", ".CSV"}, *const uff[] = {".uff", ".unv", ".uf", ".UFF", ".UNV"};
  static const char *const wav[] = {".wav", ".WAV"};
  rcb_status st;
  cli_uff_map mp;
  int rc;
  if (ext_is(path, wav, 2)) return read_wav(a, path, s);
  if (ext_is(path, csv, 2)) {
    st = rcb_signals_read_csv(s, path);
  } else if (ext_is(path, uff, 5)) {
    if ((rc = cli_uff_map_parse(a, "--map", NULL, &mp))) {
      cli_uff_map_free(&mp);
      return rc;
    }
    st = rcb_signals_read_uff(s, path, mp.n, mp.nodes);
    cli_uff_map_free(&mp);
  } else {
    return cli_usage(a->cmd, "'%s': unknown signal file type; expected .csv, .uff/.unv (UFF58 "
                     "time records) or .wav", path);
  }
  if (st)
    return cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "%s",
                    cli_msg(rcb_signals_errmsg(s), st));
  return 0;
}

int cli_signals_find(const cli_args *a, const rcb_signals *s, const char *name, size_t *idx) {
  size_t i, n = rcb_signals_channel_count(s), at = 0;
  char list[600];
  list[0] = '\0';
  if (rcb_signals_find(s, name, idx) == RCB_OK) return 0;
  for (i = 0; i < n && at + 80 < sizeof list; i++) {
    const char *ch = NULL;
    rcb_signals_channel(s, i, &ch, NULL, NULL);
    at += (size_t)snprintf(list + at, sizeof list - at, "%s'%s'", i ? ", " : "", ch);
  }
  if (i < n) snprintf(list + at, sizeof list - at, ", ...");
  return cli_fail(CLI_EXIT_INPUT, "%s: no channel '%s' in the file; it holds %s", a->model, name,
                  list);
}

int cli_signals_model_channel(const cli_args *a, const char *name, const char *model) {
  static const char *const dirs[] = {"x", "y", "rx", "ry"};
  const char *dot = strrchr(model, '.');
  size_t k;
  for (k = 0; dot && dot > model && k < 4; k++)
    if (strcmp(dot + 1, dirs[k]) == 0) return 0;
  if (model != name)
    return cli_usage(a->cmd, "'%s=%s': '%s' is not a model channel: expected STATION.DIR with "
                     "DIR x, y, rx or ry", name, model, model);
  /* a UFF name "#N.d" or a scalar "#N": the map entry that names it */
  if (name[0] == '#')
    return cli_usage(a->cmd, "channel '%s' keeps its file name, which is not a model channel "
                     "(STATION.DIR with DIR x, y, rx or ry) as the FRFs written need: name the "
                     "one it stands for, --outputs '%s=STATION.DIR' or --map %s%s=STATION.DIR "
                     "(e.g. %s%s=DA.x)", name, name, name + 1, strchr(name, '.') ? "" : ".s",
                     name + 1, strchr(name, '.') ? "" : ".s");
  return cli_usage(a->cmd, "channel '%s' is not a model channel (STATION.DIR with DIR x, y, rx "
                   "or ry) as the FRFs written need: name the one it stands for, "
                   "'%s=STATION.DIR' (e.g. '%s=DA.x'), or map it with --map NODE.DIR=STATION.DIR",
                   name, name, name);
}
