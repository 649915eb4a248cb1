/*
 * UFF dataset 58 writer (ASCII 58 and binary 58b), the counterpart of
 * uff58_read.c (record layout described there). One record per channel:
 * function type 4 (FRF) or 1 (unbalance response, reference node 0), double
 * complex data (type 6), abscissa in Hz (type 18) for FRFs and in rpm (type
 * 19) for unbalance responses (a run-up grid in whole rpm stays exact in the
 * E13.6 fields, which the same grid in Hz does not), ordinate 8/11/12 over 13
 * by kind, labelled as translations (m) or rotations (rad) and forces (N) or
 * moments (N m) by direction, rotor speed of an FRF test as the z value
 * (type 19, rpm).
 * ASCII values are 4E20.12 and the abscissa E13.6 fields (13 columns, as the
 * format's E13.5); binary data is IEEE little-endian doubles, an uneven
 * abscissa interleaved as doubles (as pyuff writes and reads it). The file is
 * written atomically.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/meas_internal.h"

/* UFF node number of a station: the map, else "#N". */
static int node_of(const rcb_uff_node *map, size_t nmap, const char *st, size_t len,
                   long *node) {
  size_t i;
  char *end;
  for (i = 0; i < nmap; i++) /* node entries: a direction entry names one channel */
    if (map[i].station && !map[i].dir && strlen(map[i].station) == len &&
        strncmp(map[i].station, st, len) == 0) {
      *node = map[i].node;
      return 0;
    }
  if (st[0] == '#' && len > 1) {
    *node = strtol(st + 1, &end, 10);
    if (end == st + len) return 0;
  }
  return -1;
}

typedef struct uff_dof {
  long node, dir;
  char ent[11]; /* entity name: the station when it fits, else NONE */
} uff_dof;

static rcb_status dof_of(rcb_meas *ms, const char *path, const char *ch, size_t nmap,
                         const rcb_uff_node *map, uff_dof *d) {
  static const long code[] = {1, 2, 4, 5};
  size_t len;
  int dir = rcb_meas_channel_dir(ch, &len);
  size_t i;
  if (dir < 0)
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: channel '%s': unknown direction", path, ch);
  for (i = 0; i < nmap; i++) /* "1.z=DA.x" writes DA.x back as node 1, direction z */
    if (map[i].dir && map[i].model_dir && map[i].station &&
        strlen(map[i].station) == len && strncmp(map[i].station, ch, len) == 0 &&
        strcmp(map[i].model_dir, ch + len + 1) == 0) {
      long k; /* the map is checked: its dir is one of the seven names */
      for (k = 0; k < 6 && strcmp(rcb_uff_dir_name(k), map[i].dir) != 0; k++) continue;
      d->node = map[i].node;
      d->dir = k;
      strcpy(d->ent, "NONE");
      if (len <= 10 && !memchr(ch, ' ', len)) snprintf(d->ent, sizeof d->ent, "%.*s", (int)len, ch);
      return RCB_OK;
    }
  if (node_of(map, nmap, ch, len, &d->node))
    return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: channel %s: station '%.*s' has no UFF node "
                         "number; add it to the node map (e.g. 1=%.*s) or use #N", path, ch,
                         (int)len, ch, (int)len, ch);
  d->dir = code[dir];
  if (len <= 10 && !memchr(ch, ' ', len))
    snprintf(d->ent, sizeof d->ent, "%.*s", (int)len, ch);
  else
    strcpy(d->ent, "NONE");
  return RCB_OK;
}

/* Value as the reader will see it after "%13.6E". */
static double as_e13(double v) {
  char b[32];
  snprintf(b, sizeof b, "%13.6E", v);
  return strtod(b, NULL);
}

/* Even spacing when min + i inc (as written) reproduces the grid. */
static int even_grid(const double *hz, size_t n, int binary, double *x0, double *dx) {
  size_t i;
  double tol = (binary ? 1e-13 : 1e-9) * fabs(hz[n - 1]);
  *x0 = as_e13(hz[0]);
  *dx = n > 1 ? as_e13((hz[n - 1] - hz[0]) / (double)(n - 1)) : 0.0;
  for (i = 0; i < n; i++)
    if (fabs(*x0 + (double)i * *dx - hz[i]) > tol) return 0;
  return 1;
}

static void put_le(FILE *fp, double v) {
  unsigned char b[8];
  uint64_t u;
  int i;
  memcpy(&u, &v, 8);
  for (i = 0; i < 8; i++) b[i] = (unsigned char)(u >> (8 * i));
  fwrite(b, 1, 8, fp);
}

typedef struct uff_out {
  FILE *fp;
  int binary, even, frf;
  size_t n;
  const double *hz; /* abscissa in Hz (FRF) or rpm (unbalance) */
  double x0, dx;    /* Hz or rpm, as written */
  double zrpm;      /* z value: rotor speed, rpm */
} uff_out;

static void write_header(const uff_out *o, const rcb_meas_ch *c, size_t idx, const uff_dof *rd,
                         const uff_dof *fd) {
  static const long ord_type[] = {8, 11, 12};
  static const char *const ord_lab[2][3] = {
      {"Displacement", "Velocity", "Acceleration"},
      {"Rotation", "Angular velocity", "Angular acceleration"}};
  static const char *const ord_unit[2][3] = {{"m", "m/s", "m/s^2"}, {"rad", "rad/s", "rad/s^2"}};
  int rot = rd->dir == 4 || rd->dir == 5, mom = o->frf && (fd->dir == 4 || fd->dir == 5);
  FILE *fp = o->fp;
  size_t nbytes = o->n * (o->even ? 16 : 24);
  fprintf(fp, "%6d\n%6d", -1, 58);
  if (o->binary)
    fprintf(fp, "b%6d%6d%12d%12zu%6d%6d%12d%12d\n", 1, 2, 11, nbytes, 0, 0, 0, 0);
  else
    fprintf(fp, "%74s\n", "");
  fprintf(fp, "%-80s\n", o->frf ? "librcb FRF" : "librcb unbalance response");
  fprintf(fp, "%-80.80s\n", c->resp);
  fprintf(fp, "%-80s\n%-80s\n", "NONE", "NONE");
  fprintf(fp, "%-80.80s\n", o->frf ? c->ref : "NONE");
  fprintf(fp, "%5d%10zu%5d%10d %10s%10ld%4ld %10s%10ld%4ld\n", o->frf ? 4 : 1, idx, 0, 0,
          rd->ent, rd->node, rd->dir, o->frf ? fd->ent : "NONE", o->frf ? fd->node : 0L,
          o->frf ? fd->dir : 0L);
  fprintf(fp, "%10d%10zu%10d%13.6E%13.6E%13.6E\n", 6, o->n, o->even ? 1 : 0,
          o->even ? o->x0 : 0.0, o->even ? o->dx : 0.0, o->frf ? o->zrpm : 0.0);
  fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", o->frf ? 18 : 19, 0, 0, 0,
          o->frf ? "Frequency" : "Rotor speed", o->frf ? "Hz" : "rpm");
  fprintf(fp, "%10ld%5d%5d%5d %-20s %-20s\n", ord_type[c->kind], 0, 0, 0,
          ord_lab[rot][c->kind], ord_unit[rot][c->kind]);
  if (o->frf) {
    fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 13, 0, 0, 0, mom ? "Moment" : "Force",
            mom ? "N m" : "N");
    fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 19, 0, 0, 0, "Rotor speed", "rpm");
  } else {
    fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
    fprintf(fp, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  }
}

static void write_values(const uff_out *o, const rcb_complex *y) {
  size_t i, k = 0;
  FILE *fp = o->fp;
  for (i = 0; i < o->n; i++) {
    if (o->binary) {
      if (!o->even) put_le(fp, o->hz[i]);
      put_le(fp, creal(y[i]));
      put_le(fp, cimag(y[i]));
    } else if (o->even) {
      fprintf(fp, "%20.12E%20.12E", creal(y[i]), cimag(y[i]));
      k += 2;
      if (k == 4 || i + 1 == o->n) {
        fputc('\n', fp);
        k = 0;
      }
    } else {
      fprintf(fp, "%13.6E%20.12E%20.12E\n", o->hz[i], creal(y[i]), cimag(y[i]));
    }
  }
  fprintf(fp, "%6d\n", -1);
}

rcb_status rcb_meas_write_uff(const rcb_meas *cms, const char *path, int binary, size_t nmap,
                              const rcb_uff_node *map) {
  /* The error message is the object's only mutable state on a write. */
  rcb_meas *ms = (rcb_meas *)(uintptr_t)cms;
  rcb_atomic_file af;
  uff_dof *dofs;
  uff_out o;
  double *hz;
  size_t c, i;
  rcb_status st = RCB_OK;
  if (!ms) return RCB_ERR_ARG;
  if ((st = rcb_meas_check_map(ms, "write_uff", nmap, map))) return st;
  for (c = 0; c < ms->nch; c++)
    if (ms->ch[c].mag_only)
      return rcb_meas_fail(ms, RCB_ERR_ARG, "%s: channel %s%s%s holds magnitudes only: a "
                           "dataset 58 FRF record is complex, and no phase is known; write CSV "
                           "(a 'mag' column)", path ? path : "", ms->ch[c].resp,
                           ms->ch[c].ref[0] ? "/" : "", ms->ch[c].ref);
  if (ms->n == 0 || ms->nch == 0)
    return rcb_meas_fail(ms, RCB_ERR_STATE, "%s: nothing to write (no abscissa or no "
                         "channels)", path ? path : "");
  dofs = rcb_alloc(&ms->alloc, 2 * ms->nch * sizeof *dofs);
  hz = rcb_alloc(&ms->alloc, ms->n * sizeof *hz);
  if (!dofs || !hz) st = rcb_meas_fail(ms, RCB_ERR_NOMEM, "%s: out of memory", path);
  for (c = 0; c < ms->nch && !st; c++) {
    st = dof_of(ms, path, ms->ch[c].resp, nmap, map, &dofs[2 * c]);
    if (!st && ms->type == RCB_MEAS_FRF)
      st = dof_of(ms, path, ms->ch[c].ref, nmap, map, &dofs[2 * c + 1]);
  }
  if (!st) st = rcb_atomic_open(ms, &af, path, 1);
  if (!st) {
    memset(&o, 0, sizeof o);
    o.frf = ms->type == RCB_MEAS_FRF;
    for (i = 0; i < ms->n; i++) hz[i] = ms->x[i] * (o.frf ? 1.0 / (2.0 * RCB_PI) : 30.0 / RCB_PI);
    o.fp = af.fp;
    o.binary = binary != 0;
    o.n = ms->n;
    o.hz = hz;
    o.even = even_grid(hz, ms->n, o.binary, &o.x0, &o.dx);
    o.zrpm = ms->speed < 0.0 ? -1.0 : ms->speed * 30.0 / RCB_PI;
    for (c = 0; c < ms->nch; c++) {
      write_header(&o, &ms->ch[c], c + 1, &dofs[2 * c], &dofs[2 * c + 1]);
      write_values(&o, ms->ch[c].data);
    }
    st = rcb_atomic_commit(ms, &af, path);
  }
  rcb_free(&ms->alloc, dofs);
  rcb_free(&ms->alloc, hz);
  return st;
}
