/*
 * Finalize a model: mesh the shafts into nodes and elements, put every
 * station on its node, tie the DOFs that the Kramer and rigid couplings
 * eliminate, number the independent DOFs along the train, and build the
 * station table. Then the queries that read the result.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"
#include "model/model_util.h"

/* Relative tolerance for a station to sit on a node (fraction of the shaft length). */
#define RCB_NODE_TOL 1e-9

static rcb_status mesh_shafts(rcb_model *m) {
  size_t s, g, e, nn, ne = 0;
  for (s = 0; s < m->n_shafts; s++) {
    rcb_shaft_t *sh = &m->shafts[s];
    if (sh->nseg == 0)
      return rcb_model_fail(m, RCB_ERR_MODEL,
                            "shaft '%s' has no segment (add 'segment = length outer_d "
                            "inner_d elements')",
                            sh->name);
    for (g = 0; g < sh->nseg; g++) ne += (size_t)sh->seg[g].nel;
  }
  nn = ne + m->n_shafts;
  if (rcb_grow(&m->alloc, (void **)&m->nodes, &m->cap_nodes, nn, sizeof *m->nodes) ||
      rcb_grow(&m->alloc, (void **)&m->elements, &m->cap_elements, ne, sizeof *m->elements))
    return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory meshing the shafts");
  m->n_nodes = 0;
  for (s = 0; s < m->n_shafts; s++) {
    rcb_shaft_t *sh = &m->shafts[s];
    double z = sh->z0;
    size_t first_el = m->n_elements;
    sh->first_node = m->n_nodes;
    m->nodes[m->n_nodes].shaft = s;
    m->nodes[m->n_nodes++].z = z;
    for (g = 0; g < sh->nseg; g++) {
      const rcb_segment_t *sg = &sh->seg[g];
      double le = sg->L / sg->nel;
      double zs = z;
      for (e = 0; e < (size_t)sg->nel; e++) {
        rcb_element_t *el = &m->elements[m->n_elements++];
        el->shaft = s;
        el->k = m->n_elements - 1 - first_el;
        el->node0 = m->n_nodes - 1;
        el->L = le;
        el->od = sg->od;
        el->id = sg->id;
        m->nodes[m->n_nodes].shaft = s;
        m->nodes[m->n_nodes++].z = rcb_segment_node_z(zs, sg->L, e, sg->nel);
      }
      z = zs + sg->L;
    }
    sh->nnodes = m->n_nodes - sh->first_node;
  }
  return RCB_OK;
}

static rcb_status resolve(rcb_model *m, const char *kind, const char *name, rcb_place_t *at) {
  const rcb_shaft_t *sh = &m->shafts[at->shaft];
  size_t i, best = sh->first_node;
  double zlast = m->nodes[sh->first_node + sh->nnodes - 1].z;
  double tol = RCB_NODE_TOL * (zlast - sh->z0) + 1e-12;
  for (i = sh->first_node; i < sh->first_node + sh->nnodes; i++)
    if (fabs(m->nodes[i].z - at->z) < fabs(m->nodes[best].z - at->z)) best = i;
  if (fabs(m->nodes[best].z - at->z) <= tol) {
    at->node = best;
    return RCB_OK;
  }
  if (at->z < sh->z0 - tol || at->z > zlast + tol)
    return rcb_model_fail(m, RCB_ERR_MODEL,
                          "%s '%s': z = %g m is outside shaft '%s' (%g to %g m); positions "
                          "are absolute axial coordinates",
                          kind, name, at->z, sh->name, sh->z0, zlast);
  {
    size_t lo = best, hi = best;
    if (m->nodes[best].z < at->z)
      hi = best + 1;
    else
      lo = best - 1;
    return rcb_model_fail(m, RCB_ERR_MODEL,
                          "%s '%s': z = %g m is not on a node of shaft '%s' (nearest nodes at "
                          "%g m and %g m); move it to a node, or split the segment there",
                          kind, name, at->z, sh->name, m->nodes[lo].z, m->nodes[hi].z);
  }
}

static rcb_status resolve_all(rcb_model *m) {
  size_t i;
  rcb_status st;
  for (i = 0; i < m->n_disks; i++)
    if ((st = resolve(m, "disk", m->disks[i].name, &m->disks[i].at))) return st;
  for (i = 0; i < m->n_bearings; i++)
    if ((st = resolve(m, "bearing", m->bearings[i].name, &m->bearings[i].at))) return st;
  for (i = 0; i < m->n_couplings; i++) {
    if ((st = resolve(m, "coupling", m->couplings[i].name, &m->couplings[i].at[0]))) return st;
    if ((st = resolve(m, "coupling", m->couplings[i].name, &m->couplings[i].at[1]))) return st;
  }
  for (i = 0; i < m->n_unbalances; i++)
    if ((st = resolve(m, "unbalance", m->unbalances[i].name, &m->unbalances[i].at))) return st;
  for (i = 0; i < m->n_probes; i++)
    if ((st = resolve(m, "station", m->probes[i].name, &m->probes[i].at))) return st;
  return RCB_OK;
}

/* Union-find over the full DOFs; the root of a set is its smallest DOF, so
 * tied DOFs take the number of the one met first along the train. */
static size_t uf_find(size_t *parent, size_t d) {
  while (parent[d] != d) {
    parent[d] = parent[parent[d]];
    d = parent[d];
  }
  return d;
}

static void uf_union(size_t *parent, size_t a, size_t b) {
  a = uf_find(parent, a);
  b = uf_find(parent, b);
  if (a < b)
    parent[b] = a;
  else if (b < a)
    parent[a] = b;
}

/* Widen the band to hold every pair of the na DOFs a and nb DOFs b. */
static void widen_dofs(rcb_model *m, const long *a, int na, const long *b, int nb) {
  int i, j;
  for (i = 0; i < na; i++)
    for (j = 0; j < nb; j++) {
      long d = a[i] - b[j];
      size_t w = (size_t)(d < 0 ? -d : d);
      if (w > m->bandwidth) m->bandwidth = w;
    }
}

static void widen(rcb_model *m, size_t na, size_t nb) {
  widen_dofs(m, m->nodes[na].dof, 4, m->nodes[nb].dof, 4);
}

/* Pedestals of the bearings at node i get the two rows right after the
 * node's own, so the band stays narrow (two rows wider at most). Virtual
 * node numbers n_nodes + k in bearing order. */
static size_t number_pedestals(rcb_model *m, size_t node, size_t next) {
  size_t b;
  for (b = 0; b < m->n_bearings; b++) {
    rcb_bearing_t *br = &m->bearings[b];
    if (!br->has_ped || br->at.node != node) continue;
    br->ped_dof[0] = (long)next++;
    br->ped_dof[1] = (long)next++;
  }
  return next;
}


static rcb_status number_dofs(rcb_model *m) {
  size_t nfull = 4 * m->n_nodes, d, i, next = 0;
  size_t *parent = rcb_alloc(&m->alloc, nfull * sizeof *parent);
  long *idx = rcb_alloc(&m->alloc, nfull * sizeof *idx);
  if (!parent || !idx) {
    rcb_free(&m->alloc, parent);
    rcb_free(&m->alloc, idx);
    return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory numbering DOFs");
  }
  for (d = 0; d < nfull; d++) parent[d] = d;
  for (i = 0; i < m->n_couplings; i++) {
    const rcb_coupling_t *c = &m->couplings[i];
    int ntied = rcb_coupling_tied(c->type);
    int k;
    for (k = 0; k < ntied; k++)
      uf_union(parent, 4 * c->at[0].node + (size_t)k, 4 * c->at[1].node + (size_t)k);
  }
  for (d = 0; d < nfull; d++) {
    size_t r = uf_find(parent, d);
    idx[d] = (r == d) ? (long)next++ : idx[r];
    if (d % 4 == 3) next = number_pedestals(m, d / 4, next);
  }
  for (i = 0; i < m->n_nodes; i++)
    for (d = 0; d < 4; d++) m->nodes[i].dof[d] = idx[4 * i + d];
  m->ndof = next;
  rcb_free(&m->alloc, parent);
  rcb_free(&m->alloc, idx);

  m->bandwidth = 3;
  for (i = 0; i < m->n_elements; i++) widen(m, m->elements[i].node0, m->elements[i].node0 + 1);
  for (i = 0; i < m->n_couplings; i++)
    widen(m, m->couplings[i].at[0].node, m->couplings[i].at[1].node);
  for (i = 0; i < m->n_bearings; i++)
    if (m->bearings[i].has_ped)
      widen_dofs(m, m->nodes[m->bearings[i].at.node].dof, 2, m->bearings[i].ped_dof, 2);
  return RCB_OK;
}

static rcb_status add_station(rcb_model *m, const char *name, const char *suffix,
                              rcb_station_kind kind, size_t index, size_t node) {
  rcb_station_t *s;
  if (rcb_grow(&m->alloc, (void **)&m->stations, &m->cap_stations, m->n_stations + 1,
               sizeof *m->stations))
    return rcb_model_fail(m, RCB_ERR_NOMEM, "out of memory building the station table");
  s = &m->stations[m->n_stations++];
  snprintf(s->name, sizeof s->name, "%s%s%s", name, suffix ? "." : "", suffix ? suffix : "");
  s->kind = kind;
  s->index = index;
  s->node = node;
  return RCB_OK;
}

static rcb_status build_stations(rcb_model *m) {
  size_t i;
  rcb_status st = RCB_OK;
  m->n_stations = 0;
  for (i = 0; i < m->n_disks && !st; i++)
    st = add_station(m, m->disks[i].name, NULL, RCB_STATION_DISK, i, m->disks[i].at.node);
  for (i = 0; i < m->n_bearings && !st; i++) {
    rcb_bearing_t *b = &m->bearings[i];
    st = add_station(m, b->name, NULL, RCB_STATION_BEARING, i, b->at.node);
    if (!st && b->has_ped) {
      b->ped_node = m->n_nodes + m->n_peds++;
      st = add_station(m, b->name, "ped", RCB_STATION_PEDESTAL, i, b->ped_node);
    }
  }
  for (i = 0; i < m->n_couplings && !st; i++) {
    const rcb_coupling_t *c = &m->couplings[i];
    st = add_station(m, c->name, NULL, RCB_STATION_COUPLING, i, c->at[0].node);
    if (!st)
      st = add_station(m, c->name, m->shafts[c->at[0].shaft].name, RCB_STATION_COUPLING, i,
                       c->at[0].node);
    if (!st)
      st = add_station(m, c->name, m->shafts[c->at[1].shaft].name, RCB_STATION_COUPLING, i,
                       c->at[1].node);
  }
  for (i = 0; i < m->n_unbalances && !st; i++)
    st = add_station(m, m->unbalances[i].name, NULL, RCB_STATION_UNBALANCE, i,
                     m->unbalances[i].at.node);
  for (i = 0; i < m->n_probes && !st; i++)
    st = add_station(m, m->probes[i].name, NULL, RCB_STATION_PROBE, i, m->probes[i].at.node);
  return st;
}

/* Every UFF map entry names an existing station or node. */
static rcb_status check_uffmap(rcb_model *m) {
  size_t i, k;
  for (i = 0; i < m->n_uffmap; i++) {
    const char *st = m->uffmap[i].station;
    int ok = 0;
    if (st[0] == '#') {
      char *end;
      long n = strtol(st + 1, &end, 10);
      ok = !*end && end != st + 1 && n >= 0 && (size_t)n < m->n_nodes;
    }
    for (k = 0; k < m->n_stations && !ok; k++) ok = strcmp(m->stations[k].name, st) == 0;
    if (!ok)
      return rcb_model_fail(m, RCB_ERR_NOT_FOUND,
                            "uff map: node %ld maps to '%s', which is not a station of the "
                            "model (see 'rcbtool check' for the station table)",
                            m->uffmap[i].node, st);
  }
  return RCB_OK;
}

rcb_status rcb_model_finalize(rcb_model *m) {
  rcb_status st;
  if (!m) return RCB_ERR_ARG;
  if (m->finalized) return RCB_OK;
  if (m->n_shafts == 0)
    return rcb_model_fail(m, RCB_ERR_MODEL, "the model has no shaft (add a [shaft NAME])");
  m->n_nodes = 0;
  m->n_elements = 0;
  m->n_peds = 0;
  if ((st = rcb_model_check_magnitudes(m)) || (st = mesh_shafts(m)) || (st = resolve_all(m)) || (st = number_dofs(m)) ||
      (st = build_stations(m)) || (st = check_uffmap(m)) ||
      (st = rcb_model_collect_warnings(m)))
    return st;
  m->finalized = 1;
  m->errmsg[0] = '\0';
  return RCB_OK;
}

/* ---- queries ---- */

size_t rcb_model_node_count(const rcb_model *m) { return m && m->finalized ? m->n_nodes : 0; }
size_t rcb_model_dof_count(const rcb_model *m) { return m && m->finalized ? m->ndof : 0; }
size_t rcb_model_element_count(const rcb_model *m) {
  return m && m->finalized ? m->n_elements : 0;
}
size_t rcb_model_station_count(const rcb_model *m) {
  return m && m->finalized ? m->n_stations : 0;
}

/* The bearing whose pedestal is virtual node `node` (>= n_nodes), or NULL. */
static const rcb_bearing_t *pedestal_of(const rcb_model *m, size_t node) {
  size_t b;
  if (node < m->n_nodes) return NULL;
  for (b = 0; b < m->n_bearings; b++)
    if (m->bearings[b].has_ped && m->bearings[b].ped_node == node) return &m->bearings[b];
  return NULL;
}

rcb_status rcb_model_node_info(const rcb_model *m, size_t node, rcb_node_info *out) {
  const rcb_bearing_t *b;
  int k;
  if (!m || !out || !m->finalized) return RCB_ERR_ARG;
  if ((b = pedestal_of(m, node)) != NULL) { /* a pedestal: x, y only (-1: none) */
    out->shaft = m->shafts[b->at.shaft].name;
    out->z = b->at.z;
    out->dof[0] = b->ped_dof[0];
    out->dof[1] = b->ped_dof[1];
    out->dof[2] = out->dof[3] = -1;
    return RCB_OK;
  }
  if (node >= m->n_nodes) return RCB_ERR_ARG;
  out->shaft = m->shafts[m->nodes[node].shaft].name;
  out->z = m->nodes[node].z;
  for (k = 0; k < 4; k++) out->dof[k] = m->nodes[node].dof[k];
  return RCB_OK;
}

rcb_status rcb_model_station_info(const rcb_model *m, size_t i, rcb_station_info *out) {
  if (!m || !out || !m->finalized || i >= m->n_stations) return RCB_ERR_ARG;
  out->name = m->stations[i].name;
  out->kind = m->stations[i].kind;
  out->node = m->stations[i].node;
  return RCB_OK;
}

rcb_status rcb_model_find_dof(const rcb_model *m, const char *spec, rcb_dof *out) {
  static const char *const dirs[4] = {"x", "y", "rx", "ry"};
  const char *dot;
  char station[2 * RCB_NAME_MAX + 2];
  size_t len, i;
  int d;
  rcb_model *mm = (rcb_model *)m; /* only the error buffer is written */
  if (!m || !spec || !out) return RCB_ERR_ARG;
  if (!m->finalized) return RCB_ERR_STATE;
  dot = strrchr(spec, '.');
  if (!dot)
    return rcb_model_fail(mm, RCB_ERR_ARG,
                          "channel '%s': expected STATION.DIR with DIR one of x, y, rx, ry",
                          spec);
  for (d = 0; d < 4; d++)
    if (strcmp(dot + 1, dirs[d]) == 0) break;
  if (d == 4)
    return rcb_model_fail(mm, RCB_ERR_ARG,
                          "channel '%s': direction '%s' unknown, expected x, y, rx or ry", spec,
                          dot + 1);
  len = (size_t)(dot - spec);
  if (len == 0 || len >= sizeof station)
    return rcb_model_fail(mm, RCB_ERR_ARG, "channel '%s': station name missing or too long",
                          spec);
  memcpy(station, spec, len);
  station[len] = '\0';
  out->dir = (rcb_dir)d;
  if (station[0] == '#') {
    char *end;
    long n = strtol(station + 1, &end, 10);
    if (*end || end == station + 1 || n < 0 || (size_t)n >= m->n_nodes)
      return rcb_model_fail(mm, RCB_ERR_NOT_FOUND,
                            "channel '%s': node '%s' does not exist (nodes #0 to #%zu)", spec,
                            station + 1, m->n_nodes - 1);
    out->node = (size_t)n;
    return RCB_OK;
  }
  for (i = 0; i < m->n_stations; i++)
    if (strcmp(m->stations[i].name, station) == 0) {
      out->node = m->stations[i].node;
      if (m->stations[i].kind == RCB_STATION_PEDESTAL && d > 1)
        return rcb_model_fail(mm, RCB_ERR_ARG,
                              "channel '%s': a pedestal moves in x and y only", spec);
      return RCB_OK;
    }
  return rcb_model_fail(mm, RCB_ERR_NOT_FOUND,
                        "channel '%s': no station named '%s' (see 'rcbtool check' for the "
                        "station table)",
                        spec, station);
}

rcb_status rcb_model_dof_index(const rcb_model *m, rcb_dof dof, size_t *index) {
  const rcb_bearing_t *b;
  if (!m || !index || !m->finalized || (int)dof.dir < 0 || (int)dof.dir > 3)
    return RCB_ERR_ARG;
  if ((b = pedestal_of(m, dof.node)) != NULL) {
    if ((int)dof.dir > 1) return RCB_ERR_ARG;
    *index = (size_t)b->ped_dof[dof.dir];
    return RCB_OK;
  }
  if (dof.node >= m->n_nodes) return RCB_ERR_ARG;
  *index = (size_t)m->nodes[dof.node].dof[dof.dir];
  return RCB_OK;
}
