/* rcbtool monitor --state FILE (issue #24): the series' state between runs.
 * The file holds, little-endian whatever the host, after the magic
 * "RCBTOOL-MONSTATE" and a format version: the settings' options as given
 * when the state was made, the commissioning files' names and the set-up
 * the monitor was created from (grid, speed, channels, averaged values),
 * the library's own state (rcb_monitor_save), and every update so far
 * (its file's name, the FNV-1a 64 hash of its bytes and the whole result),
 * then the CRC-32 of all that (rcb_monitor_crc32). The log and the plot of
 * the series are rebuilt from it; it is replaced by write, fsync, rename. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cmd_monitor.h"

#define ST_MAGIC "RCBTOOL-MONSTATE"
#define ST_VERSION 5u

/* A growing or consumed byte buffer: one codec writes and reads. bad: 1
 * truncated or damaged, 2 not a state, 3 another version, 4 CRC, 5 a field
 * no rcbtool writes (named in what). */
typedef struct st_buf {
  unsigned char *p;
  size_t n, cap, pos;
  int reading, bad;
  char what[160];
} st_buf;

/* A field read that no rcbtool writes: the first one named. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void st_bad(st_buf *b, const char *fmt, ...) {
  va_list ap;
  if (b->bad) return;
  b->bad = 5;
  va_start(ap, fmt);
  vsnprintf(b->what, sizeof b->what, fmt, ap);
  va_end(ap);
}

static void io_bytes(st_buf *b, void *x, size_t n) {
  if (b->bad || !n) return;
  if (!x) {
    b->bad = 1;
    return;
  }
  if (b->reading) {
    if (n > b->n - b->pos) {
      b->bad = 1;
      return;
    }
    memcpy(x, b->p + b->pos, n);
    b->pos += n;
    return;
  }
  if (b->n + n > b->cap) {
    size_t cap = 2 * (b->n + n) + 4096;
    unsigned char *q = realloc(b->p, cap);
    if (!q) {
      b->bad = 1;
      return;
    }
    b->p = q, b->cap = cap;
  }
  memcpy(b->p + b->n, x, n);
  b->n += n;
}

static void io_u64(st_buf *b, uint64_t *v) {
  unsigned char c[8];
  int i;
  if (!b->reading)
    for (i = 0; i < 8; i++) c[i] = (unsigned char)(*v >> (8 * i));
  io_bytes(b, c, 8);
  if (b->reading && !b->bad)
    for (*v = 0, i = 7; i >= 0; i--) *v = (*v << 8) | c[i];
}
/* Read: range-checked before the cast (a 32-bit size_t, an int). */
static void io_size(st_buf *b, size_t *v) {
  uint64_t u = *v;
  io_u64(b, &u);
  if (!b->reading || b->bad) return;
  if (u > SIZE_MAX) st_bad(b, "a count of %llu (more than this host's size_t)",
                           (unsigned long long)u);
  else *v = (size_t)u;
}
static void io_int(st_buf *b, int *v) {
  uint64_t u = (uint64_t)(int64_t)*v;
  io_u64(b, &u);
  if (!b->reading || b->bad) return;
  if ((int64_t)u < INT_MIN || (int64_t)u > INT_MAX)
    st_bad(b, "an integer of %lld (more than an int)", (long long)(int64_t)u);
  else *v = (int)(int64_t)u;
}
static void io_f64(st_buf *b, double *x) {
  uint64_t u;
  memcpy(&u, x, sizeof u);
  io_u64(b, &u);
  if (b->reading) memcpy(x, &u, sizeof u);
}
static void io_f64s(st_buf *b, double *x, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) io_f64(b, x + i);
}
/* A string: a flag (NULL or not), its length, its bytes. */
static void put_str(st_buf *b, const char *s) {
  size_t n = s ? strlen(s) : 0;
  int has = s != NULL;
  io_int(b, &has);
  io_size(b, &n);
  if (has) io_bytes(b, (void *)(uintptr_t)s, n);
}
/* Read as a malloc'd copy (NULL for a NULL string or on failure). */
static void get_str(st_buf *b, char **s) {
  size_t n = 0;
  int has = 0;
  *s = NULL;
  io_int(b, &has);
  io_size(b, &n);
  if (!b->bad && (has < 0 || has > 1 || (!has && n)))
    st_bad(b, "a name's flag %d and length %zu", has, n);
  if (b->bad || !has) return;
  if (n > b->n - b->pos || !(*s = malloc(n + 1))) {
    b->bad = 1;
    return;
  }
  io_bytes(b, *s, n);
  (*s)[n] = '\0';
}
static void io_str(st_buf *b, char **s) {
  if (b->reading)
    get_str(b, s);
  else
    put_str(b, *s);
}

/* An update's record read: what rcbtool writes (the library's result): update
 * k + 1 of the series, flags 0 or 1 (a CUSUM's and the attribution's -1, 0
 * or 1), counts of parameters within RCB_MONITOR_MAXP, effects in the
 * catalogue. The indices into the monitor's candidates are checked against
 * the monitor (mon_saved_check). */
static int flag(int v, int lo) { return v >= lo && v <= 1; }
static void check_result(st_buf *b, const rcb_monitor_result *r, size_t k) {
  size_t i;
  if (r->update != k + 1)
    st_bad(b, "update %zu: numbered %zu", k + 1, r->update);
  else if (!flag(r->alarm, 0) || !flag(r->cusum_alarm, 0) || !flag(r->drift_alarm, 0))
    st_bad(b, "update %zu: alarm flags %d, %d, %d", k + 1, r->alarm, r->cusum_alarm,
           r->drift_alarm);
  else if (r->drift_dof > RCB_MONITOR_MAXP)
    st_bad(b, "update %zu: the drift's degrees of freedom %zu", k + 1, r->drift_dof);
  else if (!isnan(r->apart_p) && !(r->apart_p >= 0 && r->apart_p <= 1))
    st_bad(b, "update %zu: the naming test's p-value %g", k + 1, r->apart_p);
  for (i = 0; !b->bad && i < r->ntop; i++) {
    const rcb_monitor_candidate *c = &r->top[i];
    if (c->np < 1 || c->np > RCB_MONITOR_MAXP || c->dof > RCB_MONITOR_MAXP ||
        (int)c->effect < 0 || (int)c->effect >= RCB_EFFECT_COUNT || !flag(c->implausible, 0))
      st_bad(b, "update %zu: candidate %zu: effect %d with %zu parameters (%zu degrees of "
             "freedom)", k + 1, i + 1, (int)c->effect, c->np, c->dof);
  }
  for (i = 0; !b->bad && i < r->ntracked; i++) {
    const rcb_monitor_tracked *t = &r->tracked[i];
    if (!flag(t->cusum_alarm, -1) || !flag(t->out_of_range, 0) || !flag(t->named, -1) ||
        t->rival_dof > RCB_MONITOR_MAXP || t->rival2_dof > RCB_MONITOR_MAXP ||
        (t->rivals_open && t->named == 1))
      st_bad(b, "update %zu: tracked parameter %zu's flags (CUSUM %d, range %d, named %d) or "
             "rivals' parameters (%zu, %zu)", k + 1, i + 1, t->cusum_alarm, t->out_of_range,
             t->named, t->rival_dof, t->rival2_dof);
  }
}

static void io_result(st_buf *b, rcb_monitor_result *r) {
  size_t k;
  int eff;
  io_size(b, &r->update);
  io_f64(b, &r->error_pct), io_f64(b, &r->change_pct), io_f64(b, &r->floor_pct);
  io_f64(b, &r->T), io_size(b, &r->dof), io_f64(b, &r->threshold), io_f64(b, &r->p_value);
  io_int(b, &r->alarm), io_int(b, &r->cusum_alarm);
  io_size(b, &r->ntop);
  if (r->ntop > RCB_MONITOR_TOP) st_bad(b, "update %zu: %zu candidates ranked", r->update, r->ntop);
  for (k = 0; !b->bad && k < r->ntop; k++) {
    rcb_monitor_candidate *c = &r->top[k];
    eff = (int)c->effect;
    io_size(b, &c->index), io_int(b, &eff), io_size(b, &c->np);
    c->effect = (rcb_effect)eff;
    io_f64s(b, c->size, RCB_MONITOR_MAXP), io_f64s(b, c->ci_lo, RCB_MONITOR_MAXP);
    io_f64s(b, c->ci_hi, RCB_MONITOR_MAXP);
    io_f64(b, &c->score), io_size(b, &c->dof), io_f64(b, &c->p_value);
    io_int(b, &c->implausible);
  }
  io_size(b, &r->ntracked);
  if (r->ntracked < 1 || r->ntracked > RCB_MONITOR_MAX_TRACKED)
    st_bad(b, "update %zu: %zu tracked parameters", r->update, r->ntracked);
  for (k = 0; !b->bad && k < r->ntracked; k++) {
    rcb_monitor_tracked *t = &r->tracked[k];
    io_f64(b, &t->value), io_f64(b, &t->ci_lo), io_f64(b, &t->ci_hi), io_f64(b, &t->stderr_);
    io_f64(b, &t->z), io_f64(b, &t->u), io_f64(b, &t->cusum_up), io_f64(b, &t->cusum_down);
    io_int(b, &t->cusum_alarm), io_int(b, &t->out_of_range);
    io_f64(b, &t->abs_stderr), io_f64(b, &t->change), io_f64(b, &t->change_lo);
    io_f64(b, &t->change_hi);
    io_int(b, &t->named), io_size(b, &t->rival), io_size(b, &t->rival_dof);
    io_f64s(b, t->rival_rate, RCB_MONITOR_MAXP);
    io_f64(b, &t->cusum_allow); /* version 3 */
    io_size(b, &t->rival2), io_size(b, &t->rival2_dof); /* version 4 */
    io_size(b, &t->rivals_open);                          /* version 5 */
  }
  io_f64(b, &r->drift_glr), io_size(b, &r->drift_dof), io_f64(b, &r->drift_p);
  io_int(b, &r->drift_alarm), io_size(b, &r->drift_index), io_size(b, &r->drift_onset);
  io_f64s(b, r->drift_rate, RCB_MONITOR_MAXP);
  io_f64(b, &r->apart_p); /* version 5 */
}

/* The set-up: written from @p ms, read into a new *ms. */
static void io_setup(st_buf *b, rcb_meas **ms) {
  size_t n = 0, nch = 0, c;
  int type = 0;
  const int rd = b->reading;
  double speed = 0, *grid = NULL;
  if (!rd) {
    n = rcb_meas_point_count(*ms), nch = rcb_meas_channel_count(*ms);
    type = (int)rcb_meas_get_type(*ms), speed = rcb_meas_speed(*ms);
    grid = (double *)rcb_meas_grid(*ms);
  }
  io_int(b, &type), io_size(b, &n), io_f64(b, &speed), io_size(b, &nch);
  if (rd) {
    if (b->bad || n == 0 || n > (b->n - b->pos) / 8 || !(grid = malloc(n * sizeof *grid)) ||
        rcb_meas_create(ms, NULL)) {
      b->bad = 1;
      free(grid);
      return;
    }
    io_f64s(b, grid, n);
    if (!b->bad && rcb_meas_set_grid(*ms, (rcb_meas_type)type, n, grid, speed))
      st_bad(b, "the set-up's grid: %s", rcb_meas_errmsg(*ms));
    free(grid);
  } else {
    io_f64s(b, grid, n);
  }
  for (c = 0; !b->bad && c < nch; c++) {
    rcb_meas_channel_info ci;
    char *resp = NULL, *ref = NULL;
    int kind = 0;
    rcb_complex *v = NULL;
    if (!rd) {
      rcb_meas_channel(*ms, c, &ci);
      resp = (char *)ci.response, ref = (char *)ci.reference, kind = (int)ci.kind;
      v = (rcb_complex *)ci.data;
      put_str(b, resp), put_str(b, ref), io_int(b, &kind);
      io_f64s(b, (double *)(void *)v, 2 * n);
      continue;
    }
    get_str(b, &resp), get_str(b, &ref), io_int(b, &kind);
    if (!b->bad && !(v = malloc(n * sizeof *v))) b->bad = 1;
    if (!b->bad) io_f64s(b, (double *)(void *)v, 2 * n);
    if (!b->bad && !resp) st_bad(b, "the set-up's channel %zu: no response name", c + 1);
    if (!b->bad && rcb_meas_add_channel(*ms, resp, ref, (rcb_frf_kind)kind, v))
      st_bad(b, "the set-up's channel %zu: %s", c + 1, rcb_meas_errmsg(*ms));
    free(resp);
    free(ref);
    free(v);
  }
}

/* The whole file but its CRC. */
static void io_state(st_buf *b, mon_saved *sv) {
  size_t k;
  char magic[16];
  uint64_t ver = ST_VERSION;
  memcpy(magic, ST_MAGIC, 16);
  io_bytes(b, magic, 16);
  if (b->reading && memcmp(magic, ST_MAGIC, 16) != 0) b->bad = 2;
  io_u64(b, &ver);
  if (!b->bad && ver != ST_VERSION) b->bad = 3;
  io_size(b, &sv->nopts);
  if (b->reading && !b->bad && (sv->nopts > 64 || !(sv->opts = calloc(sv->nopts + 1, sizeof(char *)))))
    b->bad = 1;
  for (k = 0; !b->bad && k < sv->nopts; k++) io_str(b, &sv->opts[k]);
  io_size(b, &sv->ncomm);
  if (b->reading && !b->bad &&
      (sv->ncomm > b->n / 16 || !(sv->comm = calloc(sv->ncomm + 1, sizeof(char *)))))
    b->bad = 1;
  for (k = 0; !b->bad && k < sv->ncomm; k++) io_str(b, &sv->comm[k]);
  if (!b->bad) io_setup(b, &sv->setup);
  io_size(b, &sv->nblob);
  if (b->reading && !b->bad &&
      (sv->nblob > b->n - b->pos || !(sv->blob = malloc(sv->nblob ? sv->nblob : 1))))
    b->bad = 1;
  if (!b->bad) io_bytes(b, sv->blob, sv->nblob);
  io_size(b, &sv->nrec);
  if (b->reading && !b->bad &&
      (sv->nrec > b->n / 64 || !(sv->rec = calloc(sv->nrec + 1, sizeof *sv->rec)) ||
       !(sv->recfile = calloc(sv->nrec + 1, sizeof(char *)))))
    b->bad = 1;
  for (k = 0; !b->bad && k < sv->nrec; k++) {
    io_str(b, &sv->recfile[k]);
    io_u64(b, &sv->rec[k].hash);
    io_result(b, &sv->rec[k].r);
    if (b->reading && !b->bad) check_result(b, &sv->rec[k].r, k);
  }
}

void mon_saved_free(mon_saved *sv) {
  size_t k;
  for (k = 0; sv->opts && k < sv->nopts; k++) free(sv->opts[k]);
  for (k = 0; sv->comm && k < sv->ncomm; k++) free(sv->comm[k]);
  for (k = 0; sv->recfile && k < sv->nrec; k++) free(sv->recfile[k]);
  free(sv->opts), free(sv->comm), free(sv->recfile), free(sv->rec), free(sv->blob);
  rcb_meas_destroy(sv->setup);
  memset(sv, 0, sizeof *sv);
}

int mon_saved_parse(const char *cmd, const char *path, const unsigned char *p, size_t n,
                    mon_saved *sv) {
  st_buf b;
  memset(sv, 0, sizeof *sv);
  memset(&b, 0, sizeof b);
  b.p = (unsigned char *)(uintptr_t)p, b.n = n, b.reading = 1; /* only read */
  if (b.n < 20 || memcmp(b.p, ST_MAGIC, 16) != 0) {
    b.bad = 2;
  } else {
    const unsigned char *e = b.p + b.n - 4;
    unsigned long crc = (unsigned long)e[0] | (unsigned long)e[1] << 8 |
                        (unsigned long)e[2] << 16 | (unsigned long)e[3] << 24;
    if (crc != rcb_monitor_crc32(0, b.p, b.n - 4)) b.bad = 4;
    b.n -= 4;
  }
  if (!b.bad) io_state(&b, sv);
  if (!b.bad && b.pos != b.n) st_bad(&b, "%zu bytes after the last update", b.n - b.pos);
  if (!b.bad) return 0;
  mon_saved_free(sv);
  if (b.bad == 5)
    return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': %s: not a state rcbtool writes "
                    "(damaged, or made by something else); replay the series to rebuild it",
                    cmd, path, b.what);
  return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': %s", cmd, path,
                  b.bad == 2 ? "not a monitor state (written by rcbtool monitor --state); give "
                               "the state file of the series or a new file name"
                  : b.bad == 3 ? "written by another version of rcbtool's state format; "
                                 "replay the series without it to make a new state"
                  : b.bad == 4 ? "its CRC-32 does not match: the file was changed or damaged; "
                                 "replay the series to rebuild it"
                               : "truncated or damaged: replay the series to rebuild it");
}

int mon_saved_read(const char *cmd, const char *path, mon_saved *sv) {
  FILE *fp = fopen(path, "rb");
  unsigned char *p = NULL;
  long len;
  int rc;
  memset(sv, 0, sizeof *sv);
  if (!fp) return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': cannot read it: %s", cmd, path,
                           strerror(errno));
  if (fseek(fp, 0, SEEK_END) != 0 || (len = ftell(fp)) < 0 || fseek(fp, 0, SEEK_SET) != 0 ||
      !(p = malloc((size_t)len + 1)) || fread(p, 1, (size_t)len, fp) != (size_t)len) {
    fclose(fp);
    free(p);
    return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': cannot read it", cmd, path);
  }
  fclose(fp);
  rc = mon_saved_parse(cmd, path, p, (size_t)len, sv);
  free(p);
  return rc;
}

int mon_saved_check(const char *cmd, const char *path, const mon_saved *sv,
                    const rcb_monitor *mon) {
  size_t k, i, nt = 0, nc = rcb_monitor_candidate_count(mon);
  rcb_monitor_rank(mon, NULL, &nt);
  if (sv->nrec != rcb_monitor_update_count(mon))
    return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': %zu updates' records, the monitor's "
                    "state %zu updates: not a state rcbtool writes (damaged, or made by "
                    "something else); replay the series to rebuild it", cmd, path, sv->nrec,
                    rcb_monitor_update_count(mon));
  for (k = 0; k < sv->nrec; k++) {
    const rcb_monitor_result *r = &sv->rec[k].r;
    int bad = r->ntracked != nt || (r->drift_dof && r->drift_index >= nc);
    for (i = 0; !bad && i < r->ntop; i++) {
      rcb_monitor_candidate_info ci;
      bad = rcb_monitor_candidate_info_get(mon, r->top[i].index, &ci) != RCB_OK ||
            ci.effect != r->top[i].effect || ci.np != r->top[i].np;
    }
    for (i = 0; !bad && i < r->ntracked; i++)
      bad = (r->tracked[i].rival_dof && r->tracked[i].rival >= nc) ||
            (r->tracked[i].rival2_dof && r->tracked[i].rival2 >= nc);
    if (bad)
      return cli_fail(CLI_EXIT_INPUT, "%s: --state '%s': update %zu: its tracked parameters "
                      "or candidates are not the monitor's (%zu tracked, %zu candidates): not "
                      "a state rcbtool writes (damaged, or made by something else); replay "
                      "the series to rebuild it", cmd, path, k + 1, nt, nc);
  }
  return 0;
}

/* The mode a plain fopen would have given (0666 & ~umask). */
static void plain_mode(int fd) {
  mode_t mask = umask(0);
  umask(mask);
  (void)fchmod(fd, (mode_t)(0666 & ~mask));
}

int mon_saved_write(const char *cmd, const char *path, mon_saved *sv, cli_tmpfile *t) {
  st_buf b;
  FILE *fp;
  unsigned char c[4];
  unsigned long crc;
  int rc, i, bad;
  memset(&b, 0, sizeof b);
  io_state(&b, sv);
  if (b.bad) {
    free(b.p);
    return cli_fail(CLI_EXIT_NUMERIC, "%s: out of memory (state)", cmd);
  }
  crc = rcb_monitor_crc32(0, b.p, b.n);
  for (i = 0; i < 4; i++) c[i] = (unsigned char)(crc >> (8 * i));
  if ((rc = cli_tmpfile_open(t, path))) {
    free(b.p);
    return rc;
  }
  if (!(fp = fopen(t->write_path, "wb"))) {
    free(b.p);
    cli_tmpfile_close(t, 0);
    return cli_fail(CLI_EXIT_IO, "%s: cannot write the state '%s'", cmd, path);
  }
  plain_mode(fileno(fp));
  bad = fwrite(b.p, 1, b.n, fp) != b.n || fwrite(c, 1, 4, fp) != 4 || fflush(fp) != 0 ||
        fsync(fileno(fp)) != 0;
  if (fclose(fp) != 0) bad = 1;
  free(b.p);
  if (bad) {
    cli_tmpfile_close(t, 0);
    return cli_fail(CLI_EXIT_IO, "%s: cannot write the state '%s'", cmd, path);
  }
  return 0; /* renamed by the caller with the other outputs */
}

uint64_t mon_file_hash(const char *path, int *ok) {
  uint64_t h = 0xcbf29ce484222325ull;
  unsigned char buf[65536];
  size_t n, i;
  FILE *fp = fopen(path, "rb");
  *ok = fp != NULL;
  if (!fp) return 0;
  while ((n = fread(buf, 1, sizeof buf, fp)) > 0)
    for (i = 0; i < n; i++) h = (h ^ buf[i]) * 0x100000001b3ull;
  if (ferror(fp)) *ok = 0;
  fclose(fp);
  return h;
}
