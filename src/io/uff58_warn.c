/*
 * Warnings of a UFF dataset 58 read (issue #17): what reads without error but
 * is most likely not what the file means.
 *  - A node number with no entry in the node map becomes model node "#N": an
 *    off-by-one map then compares the wrong nodes (42 % error on the
 *    walkthrough) with no other sign. Each such node is named once.
 *  - An FRF whose z axis is not of type 19 (rotor speed, rpm) does not state
 *    the test speed: many writers put it only in the ID (text) lines, which
 *    no reader can parse reliably; it reads as 0 rpm, and a spinning rotor
 *    compared at 0 rpm shows ~100 % error.
 * Kept apart from uff58_read.c (the record parser) so each stays small.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/meas_internal.h"

/* Node number of a "#N.dir" channel name; 0 when the name is a station. */
static int hash_node(const char *name, long *node) {
  char *end;
  if (!name || name[0] != '#') return 0;
  *node = strtol(name + 1, &end, 10);
  return end != name + 1 && *end == '.';
}

/* Has node @p nd already been named by an earlier channel (c < upto, or the
 * response of channel upto when @p in_ref)? */
static int seen(const rcb_meas *ms, size_t upto, int in_ref, long nd) {
  size_t c;
  long o;
  for (c = 0; c <= upto && c < ms->nch; c++) {
    if ((c < upto || in_ref) && hash_node(ms->ch[c].resp, &o) && o == nd) return 1;
    if (c < upto && hash_node(ms->ch[c].ref, &o) && o == nd) return 1;
  }
  return 0;
}

static rcb_status warn_unmapped(rcb_meas *ms, const char *path, size_t nmap) {
  size_t c;
  int k;
  long nd;
  rcb_status st = RCB_OK;
  for (c = 0; c < ms->nch && !st; c++)
    for (k = 0; k < 2 && !st; k++) {
      const char *name = k ? (ms->type == RCB_MEAS_FRF ? ms->ch[c].ref : NULL) : ms->ch[c].resp;
      if (!hash_node(name, &nd) || seen(ms, c, k, nd)) continue;
      if (nmap)
        st = rcb_meas_warn(ms, "%s: UFF node %ld is not in the node map (%zu entries); read "
                           "as model node #%ld, which is right only if the file numbers "
                           "the model's nodes; else add NODE=STATION to the map",
                           path, nd, nmap, nd);
      else
        st = rcb_meas_warn(ms, "%s: no node map; UFF node %ld read as model node #%ld, "
                           "which is right only if the file numbers the model's nodes; "
                           "else give the map (NODE=STATION)", path, nd, nd);
    }
  return st;
}

rcb_status rcb_uff_read_warnings(rcb_meas *ms, const char *path, size_t nmap, long ztype) {
  rcb_status st = warn_unmapped(ms, path, nmap);
  ms->speed_given = ms->type == RCB_MEAS_FRF && ztype == 19;
  if (!st && ms->type == RCB_MEAS_FRF && ztype != 19)
    st = rcb_meas_warn(ms, "%s: the FRF records' z axis has data type %ld, not 19 (rotor "
                       "speed, rpm): the file does not state the test speed (a speed written "
                       "only in the ID lines is not read), so it reads as 0 rpm; state it "
                       "(rcbtool --rpm R, the model's [test] rpm, rcb_meas_set_speed)",
                       path, ztype);
  if (!st && ms->type == RCB_MEAS_FRF && ztype != 19) ms->speed_warning = ms->n_warnings;
  return st;
}

/* UFF function types (dataset 58 record 6, field 1; I-DEAS/UC-SDRL). */
void rcb_uff_function_text(long func_type, long abscissa, char *buf, size_t size) {
  static const char *const names[] = {
      "general or unknown", "time response", "auto spectrum", "cross spectrum",
      "frequency response function", "transmissibility", "coherence", "auto correlation",
      "cross correlation", "power spectral density", "energy spectral density",
      "probability density function", "spectrum", "cumulative frequency distribution",
      "peaks valley", "stress/cycles", "strain/cycles", "orbit", "mode indicator function",
      "force pattern", "partial power", "partial coherence", "eigenvalue", "eigenvector",
      "shock response spectrum", "finite impulse response filter", "multiple coherence",
      "order function"};
  const char *name = func_type >= 0 && func_type < (long)(sizeof names / sizeof names[0])
                         ? names[func_type] : "not a UFF function type";
  const char *verb = "no rcbtool command reads it";
  if (func_type == 1 && abscissa == 17)
    verb = "a time record: rcbtool estimate and order read it";
  else if (func_type == 1)
    verb = "with abscissa 18/19 an unbalance response: rcbtool convert, compare, fit, "
           "diagnose read it";
  else if (func_type == 4)
    verb = "an FRF: rcbtool convert, compare, fit, diagnose read it";
  snprintf(buf, size, "function type %ld (%s; %s)", func_type, name, verb);
}
