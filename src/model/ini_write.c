/*
 * The model as INI text (the format the loader reads, see
 * examples/paper_system.ini), e.g. to save a fitted model. Every value is
 * written in the shortest %.Ng (at most %.17g) that reads back to the same
 * double, so the reloaded model has bit-identical inputs; positions are
 * written as absolute "SHAFT z", so nothing depends on other sections.
 *
 * No allocation: the text goes straight into the caller's buffer through
 * snprintf, and the length is counted whether or not it fits (two-call
 * sizing, like kissfft's lenmem).
 */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

/* Values per line of a tabulated bearing list; longer lists continue on
 * indented lines (inih reads at most about 200 characters per line). */
#define VALUES_PER_LINE 4
/* Column of the unit comments. */
#define COMMENT_COL 30

typedef struct wbuf {
  char *buf;   /* may be NULL */
  size_t size; /* bytes available in buf */
  size_t len;  /* bytes the whole text needs so far, without the NUL */
} wbuf;

static void wr(wbuf *w, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void wr(wbuf *w, const char *fmt, ...) {
  va_list ap;
  char *dst = NULL;
  size_t room = 0;
  int n;
  if (w->buf && w->len < w->size) {
    dst = w->buf + w->len;
    room = w->size - w->len;
  }
  va_start(ap, fmt);
  n = vsnprintf(dst, room, fmt, ap);
  va_end(ap);
  if (n > 0) w->len += (size_t)n;
}

/* Shortest %.Ng text (N = 1..17) that strtod reads back to v exactly,
 * fixed notation on a tie: 500, 2.05e+11, 0.043115, never 204999999999.99997. */
static const char *num(char out[32], double v) {
  char t[32];
  size_t best = 0;
  int prec;
  out[0] = '\0';
  for (prec = 1; prec <= 17; prec++) {
    size_t len;
    snprintf(t, sizeof t, "%.*g", prec, v);
    if (strtod(t, NULL) != v) continue;
    len = strlen(t);
    if (!best || len < best || (len == best && strchr(out, 'e') && !strchr(t, 'e'))) {
      memcpy(out, t, len + 1);
      best = len;
    }
  }
  if (!best) snprintf(out, 32, "%.17g", v); /* NaN: cannot happen, values are checked */
  return out;
}

/* "key = value" with a unit comment aligned at COMMENT_COL. */
static void kv(wbuf *w, const char *key, const char *value, const char *comment) {
  char line[256];
  snprintf(line, sizeof line, "%s = %s", key, value);
  /* long names and 17-digit values: keep well inside inih's line limit */
  if (comment && strlen(line) + strlen(comment) < 150)
    wr(w, "%-*s ; %s\n", COMMENT_COL - 2, line, comment);
  else
    wr(w, "%s\n", line);
}

static void kv_num(wbuf *w, const char *key, double v, const char *comment) {
  char b[32];
  kv(w, key, num(b, v), comment);
}

/* "SHAFT z" of a place. */
static const char *place_txt(const rcb_model *m, const rcb_place_t *at, char *buf, size_t size) {
  char b[32];
  snprintf(buf, size, "%s %s", m->shafts[at->shaft].name, num(b, at->z));
  return buf;
}

/* The phase in degrees that the loader (deg * RCB_PI / 180.0) turns back
 * into exactly phase (rad), when one of the nearest doubles does. */
static double phase_deg(double phase) {
  double d0 = phase * 180.0 / RCB_PI, up = d0, down = d0;
  int k;
  if (d0 * RCB_PI / 180.0 == phase) return d0;
  for (k = 0; k < 8; k++) {
    up = nextafter(up, HUGE_VAL);
    down = nextafter(down, -HUGE_VAL);
    if (up * RCB_PI / 180.0 == phase) return up;
    if (down * RCB_PI / 180.0 == phase) return down;
  }
  return d0;
}

/* A name must survive "[kind NAME]", "KEY = NAME" and "NAME z, NAME z". */
static int ini_safe(const char *name) {
  const char *p;
  if (!name[0]) return 0;
  for (p = name; *p; p++)
    if ((!isgraph((unsigned char)*p) && (unsigned char)*p < 0x80) || strchr("[];,=:#", *p))
      return 0; /* bytes >= 0x80 (UTF-8 names) pass, as the builder lets them */
  return 1;
}

static rcb_status check_names(const rcb_model *m) {
  rcb_model *mm = (rcb_model *)m; /* only the error buffer is written */
  size_t i;
#define RCB_CHECK_NAMES_(arr, kind)                                                          \
  for (i = 0; i < m->n_##arr; i++)                                                          \
    if (!ini_safe(m->arr[i].name))                                                          \
      return rcb_model_fail(mm, RCB_ERR_MODEL,                                              \
                            kind " '%s': the name cannot be written as INI; expected a "   \
                                 "name without spaces, control characters or any of "      \
                                 "[ ] ; , = : #",                                            \
                            m->arr[i].name);
  RCB_CHECK_NAMES_(materials, "material")
  RCB_CHECK_NAMES_(shafts, "shaft")
  RCB_CHECK_NAMES_(disks, "disk")
  RCB_CHECK_NAMES_(bearings, "bearing")
  RCB_CHECK_NAMES_(couplings, "coupling")
  RCB_CHECK_NAMES_(unbalances, "unbalance")
  RCB_CHECK_NAMES_(probes, "station")
#undef RCB_CHECK_NAMES_
  return RCB_OK;
}

/* ---- sections ---- */

static void write_materials(wbuf *w, const rcb_model *m) {
  size_t i;
  for (i = 0; i < m->n_materials; i++) {
    const rcb_material_t *mat = &m->materials[i];
    wr(w, "[material %s]\n", mat->name);
    kv_num(w, "density", mat->rho, "kg/m^3");
    kv_num(w, "young", mat->E, "Pa");
    kv_num(w, "poisson", mat->nu, "-");
    wr(w, "\n");
  }
}

/* "element_stiffness = k f k f ..." (which 0) or element_mass (1): the
 * elements whose factor is not 1, VALUES_PER_LINE pairs per line, each line
 * with its key (the key may be repeated). */
static void write_element_factors(wbuf *w, const rcb_shaft_t *s, int which) {
  const char *key = which ? "element_mass" : "element_stiffness";
  char b[32];
  size_t k, on_line = 0, lines = 0;
  for (k = 0; k < s->nef; k++) {
    double f = s->ef[2 * k + (size_t)which];
    if (f == 1.0) continue;
    if (on_line == 0) wr(w, "%s =", key);
    wr(w, " %zu %s", k + 1, num(b, f));
    if (++on_line == VALUES_PER_LINE) {
      wr(w, lines++ ? "\n" : " ; element k (from 1 along the shaft), factor\n");
      on_line = 0;
    }
  }
  if (on_line) wr(w, lines ? "\n" : " ; element k (from 1 along the shaft), factor\n");
}

static void write_shafts(wbuf *w, const rcb_model *m) {
  char a[32], b[32], c[32], line[128];
  size_t i, g;
  for (i = 0; i < m->n_shafts; i++) {
    const rcb_shaft_t *s = &m->shafts[i];
    wr(w, "[shaft %s]\n", s->name);
    kv(w, "material", m->materials[s->material].name, NULL);
    kv_num(w, "start", s->z0, "m, z of the first node");
    kv_num(w, "shear_factor", s->kappa, "- (Timoshenko kappa)");
    kv_num(w, "damping_mass", s->qz_m, "qz_m, 1/s (C = qz_m M + qz_k K)");
    kv_num(w, "damping_stiffness", s->qz_k, "qz_k, s");
    if (s->sf[0] != 1.0) kv_num(w, "stiffness_factor", s->sf[0], "- on E and G of the shaft");
    if (s->sf[1] != 1.0) kv_num(w, "mass_factor", s->sf[1], "- on the density of the shaft");
    for (g = 0; g < s->nseg; g++) {
      const rcb_segment_t *sg = &s->seg[g];
      snprintf(line, sizeof line, "%s %s %s %d", num(a, sg->L), num(b, sg->od), num(c, sg->id),
               sg->nel);
      kv(w, "segment", line, g == 0 ? "length m, outer d m, inner d m, elements" : NULL);
    }
    write_element_factors(w, s, 0);
    write_element_factors(w, s, 1);
    wr(w, "\n");
  }
}

static void write_disks(wbuf *w, const rcb_model *m) {
  char at[2 * RCB_NAME_MAX];
  size_t i;
  for (i = 0; i < m->n_disks; i++) {
    const rcb_disk_t *d = &m->disks[i];
    wr(w, "[disk %s]\n", d->name);
    kv(w, "at", place_txt(m, &d->at, at, sizeof at), "shaft, z m");
    kv_num(w, "mass", d->m, "kg");
    kv_num(w, "Id", d->Id, "kg m^2 (diametral)");
    kv_num(w, "Ip", d->Ip, "kg m^2 (polar)");
    wr(w, "\n");
  }
}

/* Row r of a bearing table: the speed (k < 0, rad/s) or coefficient k in
 * rcb_bearing_coefs order. */
static double table_value(const rcb_bearing_t *b, int k, size_t r) {
  return k < 0 ? b->speeds[r] : (&b->c[r].kxx)[k];
}

/* "key = v0 v1 v2 v3 ; unit" then indented continuation lines. */
static void write_list(wbuf *w, const char *key, const rcb_bearing_t *b, int k, size_t n,
                       const char *unit) {
  char buf[32];
  size_t i;
  int col;
  wr(w, "%s =", key);
  col = (int)strlen(key) + 2;
  for (i = 0; i < n; i++) {
    if (i > 0 && i % VALUES_PER_LINE == 0) {
      if (i == VALUES_PER_LINE) wr(w, " ; %s", unit);
      wr(w, "\n   ");
      col = 3;
    }
    num(buf, table_value(b, k, i));
    wr(w, " %s", buf);
    col += 1 + (int)strlen(buf);
  }
  if (n <= VALUES_PER_LINE) wr(w, "%*s ; %s", col < COMMENT_COL - 2 ? COMMENT_COL - 2 - col : 0,
                               "", unit);
  wr(w, "\n");
}

static void write_bearings(wbuf *w, const rcb_model *m) {
  static const char *const keys[8] = {"kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy"};
  char at[2 * RCB_NAME_MAX];
  size_t i, r;
  int k;
  for (i = 0; i < m->n_bearings; i++) {
    const rcb_bearing_t *b = &m->bearings[i];
    wr(w, "[bearing %s]\n", b->name);
    kv(w, "at", place_txt(m, &b->at, at, sizeof at), "shaft, z m");
    if (b->n > 1) write_list(w, "speed", b, -1, b->n, "rad/s");
    for (k = 0; k < 8; k++) {
      int constant = 1;
      for (r = 1; r < b->n; r++) constant &= table_value(b, k, r) == table_value(b, k, 0);
      write_list(w, keys[k], b, k, constant ? 1 : b->n, k < 4 ? "N/m" : "N s/m");
    }
    if (b->has_ped) {
      kv_num(w, "pedestal_mass", b->ped_m, "kg (pedestal under the bearing)");
      kv_num(w, "pedestal_kxx", b->ped_k[0], "N/m, pedestal to ground");
      kv_num(w, "pedestal_kyy", b->ped_k[1], "N/m");
      kv_num(w, "pedestal_cxx", b->ped_c[0], "N s/m");
      kv_num(w, "pedestal_cyy", b->ped_c[1], "N s/m");
    }
    wr(w, "\n");
  }
}

static void write_coupling(wbuf *w, const rcb_model *m, const rcb_coupling_t *c) {
  static const char *const units[4] = {"N/m", "N m/rad", "N s/m", "N m s/rad"};
  const double v[4] = {c->p.kt, c->p.kr, c->p.ct, c->p.cr};
  const rcb_coupling_params *p = &c->p;
  char a[2 * RCB_NAME_MAX], b[2 * RCB_NAME_MAX], both[4 * RCB_NAME_MAX + 4];
  int k;
  wr(w, "[coupling %s]\n", c->name);
  kv(w, "model", rcb_coupling_model_name(c->type), NULL);
  snprintf(both, sizeof both, "%s, %s", place_txt(m, &c->at[0], a, sizeof a),
           place_txt(m, &c->at[1], b, sizeof b));
  kv(w, "between", both, "station a, station b (shaft, z m)");
  for (k = 0; k < 4; k++)
    if (rcb_coupling_uses(c->type) & (1u << k))
      kv_num(w, rcb_coupling_coef_key(k), v[k], units[k]);
  if (p->mass[0] != 0 || p->Id[0] != 0 || p->Ip[0] != 0 || p->mass[1] != 0 || p->Id[1] != 0 ||
      p->Ip[1] != 0) {
    if (p->mass[1] != p->mass[0] || p->Id[1] != p->Id[0] || p->Ip[1] != p->Ip[0]) {
      char m1[32], i1[32], p1[32];
      wr(w,
         "; NOTE: the hub at station b differs (mass %s kg, Id %s kg m^2, Ip %s kg m^2);\n"
         "; the INI format has one hub for both stations: station a's is written\n",
         num(m1, p->mass[1]), num(i1, p->Id[1]), num(p1, p->Ip[1]));
    }
    kv_num(w, "hub_mass", p->mass[0], "kg, at each station");
    kv_num(w, "hub_Id", p->Id[0], "kg m^2, at each station");
    kv_num(w, "hub_Ip", p->Ip[0], "kg m^2, at each station");
  }
  wr(w, "\n");
}

static void write_rest(wbuf *w, const rcb_model *m) {
  char at[2 * RCB_NAME_MAX];
  size_t i;
  for (i = 0; i < m->n_couplings; i++) write_coupling(w, m, &m->couplings[i]);
  for (i = 0; i < m->n_unbalances; i++) {
    const rcb_unbalance_t *u = &m->unbalances[i];
    wr(w, "[unbalance %s]\n", u->name);
    kv(w, "at", place_txt(m, &u->at, at, sizeof at), "shaft, z m");
    kv_num(w, "amount", u->amount, "kg m");
    kv_num(w, "phase_deg", phase_deg(u->phase), "degrees from +x towards +y");
    wr(w, "\n");
  }
  for (i = 0; i < m->n_probes; i++) {
    wr(w, "[station %s]\n", m->probes[i].name);
    kv(w, "at", place_txt(m, &m->probes[i].at, at, sizeof at), "shaft, z m");
    wr(w, "\n");
  }
  if (m->n_uffmap) {
    wr(w, "[uff]\n; UFF node number -> station, for measurement files\nmap = ");
    for (i = 0; i < m->n_uffmap; i++)
      wr(w, "%s%ld %s", i ? ", " : "", m->uffmap[i].node, m->uffmap[i].station);
    wr(w, "\n");
  }
  if (m->has_test_speed) {
    wr(w, "\n[test]\n");
    kv_num(w, "rpm", m->test_speed * 30.0 / RCB_PI, "rotor speed of the measurements");
  }
}

rcb_status rcb_model_write_ini(const rcb_model *m, char *buf, size_t size, size_t *needed) {
  rcb_model *mm = (rcb_model *)m; /* only the error buffer is written */
  wbuf w;
  rcb_status st;
  if (!m) return RCB_ERR_ARG;
  if (needed) *needed = 0;
  if (buf && size > 0) buf[0] = '\0';
  if (!buf) size = 0;
  if ((st = check_names(m))) return st;
  w.buf = buf;
  w.size = size;
  w.len = 0;
  wr(&w, "; librcb model (rcb_model_write_ini). SI units: m, kg, N/m, N s/m, N m/rad, Pa, s.\n"
         "; Positions are absolute axial coordinates z (m).\n\n");
  if (m->speed_factor != 1.0) {
    wr(&w, "[model]\n");
    kv_num(&w, "speed_factor", m->speed_factor, "real / stated rotor speed");
    wr(&w, "\n");
  }
  write_materials(&w, m);
  write_shafts(&w, m);
  write_disks(&w, m);
  write_bearings(&w, m);
  write_rest(&w, m);
  if (needed) *needed = w.len + 1;
  if (w.len + 1 > size) {
    if (buf && size > 0) buf[0] = '\0'; /* no partial text that looks like a model */
    return rcb_model_fail(mm, RCB_ERR_WORKSPACE,
                          "rcb_model_write_ini: the text needs %zu bytes (with the NUL), the "
                          "buffer has %zu; call again with a buffer of that size",
                          w.len + 1, size);
  }
  return RCB_OK;
}
