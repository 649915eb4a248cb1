/* The UFF node map of every verb that reads or writes measurements or
 * signals (--map): node entries NODE=STATION ("10=DA": node 10's x, y, rx, ry
 * are DA's) and direction entries NODE.DIR=STATION.DIR ("1.z=DA.x",
 * "3.s=DB.y": one channel of the file, in any direction, is a model channel;
 * issue #35), added to the model's [uff] map; and the numbers given to
 * stations when writing UFF. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

void cli_uff_map_free(cli_uff_map *mp) {
  size_t i;
  for (i = 0; i < mp->nowned; i++) free(mp->owned[i]);
  free(mp->buf);
  free(mp->nodes);
  free(mp->owned);
  memset(mp, 0, sizeof *mp);
}

static const char *const file_dirs[] = {"x", "y", "z", "rx", "ry", "rz", "s"};
static const char *const model_dirs[] = {"x", "y", "rx", "ry"};

static int in(const char *s, const char *const *list, size_t n) {
  size_t i;
  for (i = 0; i < n; i++)
    if (strcmp(s, list[i]) == 0) return 1;
  return 0;
}

/* "STATION.DIR" of a direction entry, split at its last '.'. */
static int map_target(const cli_args *a, const char *opt, const char *item, char *rhs,
                      rcb_uff_node *out) {
  char *dot = strrchr(rhs, '.');
  if (!dot || dot == rhs || !dot[1])
    return cli_usage(a->cmd, "option %s: item '%s': a file direction maps to a model channel: "
                     "expected NODE.DIR=STATION.DIR (e.g. 1.z=DA.x)", opt, item);
  *dot = '\0';
  if (!in(dot + 1, model_dirs, 4))
    return cli_usage(a->cmd, "option %s: item '%s': model direction '%s': expected x, y, rx or "
                     "ry (the model's channels)", opt, item, dot + 1);
  out->station = rhs;
  out->model_dir = dot + 1;
  return 0;
}

/* One "NODE=STATION" or "NODE.DIR=STATION.DIR" item (split in place). */
static int map_item(const cli_args *a, const char *opt, char *item, rcb_uff_node *out) {
  char *eq = strchr(item, '='), *end, *dot;
  char shown[200];
  long node;
  memset(out, 0, sizeof *out);
  snprintf(shown, sizeof shown, "%s", item);
  if (!eq || eq == item || eq[1] == '\0')
    return cli_usage(a->cmd, "option %s: item '%s': expected NODE=STATION (e.g. 10=DA) or "
                     "NODE.DIR=STATION.DIR (e.g. 1.z=DA.x, 3.s=DB.y for a scalar channel)",
                     opt, shown);
  *eq = '\0';
  if ((dot = strchr(item, '.')) != NULL) *dot = '\0';
  errno = 0;
  node = strtol(item, &end, 10);
  if (end == item || *end || errno || node < 0)
    return cli_usage(a->cmd, "option %s: item '%s': the UFF node must be a whole number >= 0",
                     opt, shown);
  out->node = node;
  if (!dot) {
    out->station = eq + 1;
    return 0;
  }
  if (!in(dot + 1, file_dirs, 7))
    return cli_usage(a->cmd, "option %s: item '%s': file direction '%s': expected x, y, z, rx, "
                     "ry, rz (UFF 1 to 6) or s (scalar, UFF 0)", opt, shown, dot + 1);
  out->dir = dot + 1;
  return map_target(a, opt, shown, eq + 1, out);
}

/* The model's own [uff] map (station names stay owned by the model). */
static int map_from_model(const rcb_model *m, cli_uff_map *mp) {
  size_t i, n = rcb_model_uff_node_count(m);
  if (n == 0) return 0;
  mp->nodes = calloc(n, sizeof *mp->nodes);
  if (!mp->nodes) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  for (i = 0; i < n; i++) rcb_model_uff_node(m, i, &mp->nodes[i].node, &mp->nodes[i].station);
  mp->n = n;
  return 0;
}

/* The option adds to the model's [uff] map (issue #17: a --map of one node
 * used to drop the model's whole map): the model's entries whose node and
 * station no node entry of the option gives follow the option's (mp->nodes
 * has room). */
static void add_model_entries(const rcb_model *m, cli_uff_map *mp) {
  size_t i, j, nopt = mp->n, n = rcb_model_uff_node_count(m);
  for (i = 0; i < n; i++) {
    rcb_uff_node e;
    int clash = 0;
    memset(&e, 0, sizeof e);
    if (rcb_model_uff_node(m, i, &e.node, &e.station)) continue;
    for (j = 0; j < nopt && !clash; j++)
      clash = !mp->nodes[j].dir &&
              (mp->nodes[j].node == e.node || strcmp(mp->nodes[j].station, e.station) == 0);
    if (!clash) mp->nodes[mp->n++] = e;
  }
}

/* Entry i against the earlier ones: a node or station given by two node
 * entries, a node and direction or a model channel by two direction entries. */
static int map_clash(const cli_args *a, const char *opt, const cli_uff_map *mp, size_t i) {
  const rcb_uff_node *e = &mp->nodes[i];
  size_t j;
  for (j = 0; j < i; j++) {
    const rcb_uff_node *o = &mp->nodes[j];
    if (!e->dir && !o->dir && (o->node == e->node || strcmp(o->station, e->station) == 0))
      return cli_usage(a->cmd, "option %s: node %ld or station '%s' appears twice", opt,
                       e->node, e->station);
    if (e->dir && o->dir && o->node == e->node && strcmp(o->dir, e->dir) == 0)
      return cli_usage(a->cmd, "option %s: %ld.%s appears twice", opt, e->node, e->dir);
    if (e->dir && o->dir && strcmp(o->station, e->station) == 0 &&
        strcmp(o->model_dir, e->model_dir) == 0)
      return cli_usage(a->cmd, "option %s: %ld.%s and %ld.%s both map to %s.%s; a model channel "
                       "takes one file channel", opt, o->node, o->dir, e->node, e->dir,
                       e->station, e->model_dir);
  }
  return 0;
}

int cli_uff_map_parse(const cli_args *a, const char *opt, const rcb_model *m,
                      cli_uff_map *mp) {
  const char *list = cli_opt_value(a, opt);
  size_t n = 1, i;
  char *p;
  int rc;
  memset(mp, 0, sizeof *mp);
  if (!list) return m ? map_from_model(m, mp) : 0;
  mp->buf = malloc(strlen(list) + 1);
  if (!mp->buf) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(mp->buf, list);
  for (p = mp->buf; *p; p++) n += (*p == ',');
  mp->nodes = calloc(n + (m ? rcb_model_uff_node_count(m) : 0), sizeof *mp->nodes);
  if (!mp->nodes) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  p = mp->buf;
  for (i = 0; i < n; i++) {
    char *comma = strchr(p, ',');
    if (comma) *comma = '\0';
    if ((rc = map_item(a, opt, p, &mp->nodes[i])) || (rc = map_clash(a, opt, mp, i))) return rc;
    mp->n++;
    if (comma) p = comma + 1;
  }
  if (m) add_model_entries(m, mp);
  return 0;
}

/* A node entry of station st (its first len characters). */
static int map_has_station(const cli_uff_map *mp, const char *st, size_t len) {
  size_t i;
  for (i = 0; i < mp->n; i++)
    if (!mp->nodes[i].dir && strlen(mp->nodes[i].station) == len &&
        strncmp(mp->nodes[i].station, st, len) == 0)
      return 1;
  return 0;
}

/* A direction entry that writes channel ch ("1.z=DA.x" writes DA.x). */
static int map_has_channel(const cli_uff_map *mp, const char *ch, size_t len) {
  size_t i;
  for (i = 0; i < mp->n; i++)
    if (mp->nodes[i].dir && strlen(mp->nodes[i].station) == len &&
        strncmp(mp->nodes[i].station, ch, len) == 0 && ch[len] == '.' &&
        strcmp(mp->nodes[i].model_dir, ch + len + 1) == 0)
      return 1;
  return 0;
}

static int map_has_node(const cli_uff_map *mp, long node) {
  size_t i;
  for (i = 0; i < mp->n; i++)
    if (mp->nodes[i].node == node) return 1;
  return 0;
}

/* Add station (first len chars of ch) with the next free node number. */
static int map_add(cli_uff_map *mp, const char *ch, size_t len, long *next) {
  rcb_uff_node *nn = realloc(mp->nodes, (mp->n + 1) * sizeof *nn);
  char **no;
  char *s;
  if (!nn) return -1;
  mp->nodes = nn;
  no = realloc(mp->owned, (mp->nowned + 1) * sizeof *no);
  if (!no) return -1;
  mp->owned = no;
  s = malloc(len + 1);
  if (!s) return -1;
  memcpy(s, ch, len);
  s[len] = '\0';
  mp->owned[mp->nowned++] = s;
  while (map_has_node(mp, *next)) ++*next;
  memset(&mp->nodes[mp->n], 0, sizeof mp->nodes[mp->n]);
  mp->nodes[mp->n].node = (*next)++;
  mp->nodes[mp->n].station = s;
  mp->n++;
  return 0;
}

/* Station part of channel "STATION.DIR" (length in *len). */
static void station_part(const char *ch, size_t *len) {
  const char *dot = strrchr(ch, '.');
  *len = dot ? (size_t)(dot - ch) : strlen(ch);
}

static int automap_one(cli_uff_map *mp, const char *ch, long *next, int *added) {
  size_t len;
  if (!ch) return 0;
  station_part(ch, &len);
  if ((ch[0] == '#' && len > 1) || map_has_station(mp, ch, len) ||
      map_has_channel(mp, ch, len))
    return 0;
  if (map_add(mp, ch, len, next)) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  *added = 1;
  return 0;
}

int cli_uff_automap(const char *cmd, const rcb_meas *ms, cli_uff_map *mp) {
  size_t c, i, base = mp->n;
  long next = 1;
  int added = 0, rc;
  for (c = 0; c < rcb_meas_channel_count(ms); c++) {
    rcb_meas_channel_info info;
    rcb_meas_channel(ms, c, &info);
    if ((rc = automap_one(mp, info.response, &next, &added)) ||
        (rc = automap_one(mp, info.reference, &next, &added)))
      return rc;
  }
  if (added) {
    fprintf(stderr, "rcbtool: %s: UFF node numbers given to stations: ", cmd);
    for (i = base; i < mp->n; i++)
      fprintf(stderr, "%s%ld=%s", i > base ? "," : "", mp->nodes[i].node, mp->nodes[i].station);
    fputs(" (pass --map with these when reading the file back)\n", stderr);
  }
  return 0;
}
