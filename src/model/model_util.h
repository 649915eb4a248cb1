/* Helpers shared by the model builder, the finalizer and the INI loader. */
#ifndef RCB_MODEL_UTIL_H
#define RCB_MODEL_UTIL_H

#include "core/rcb_internal.h"

/* Write the model's error message, return st: the core helper (rcb_fail,
 * core/rcb_internal.h) on the model. */
#define rcb_model_fail(m, st, ...) rcb_fail((m), (st), __VA_ARGS__)

/* Check a numeric input: finite always; sign > 0 requires v > 0, sign == 0
 * requires v >= 0, sign < 0 accepts any finite value. */
rcb_status rcb_model_check_value(rcb_model *m, const char *kind, const char *name,
                                 const char *what, double v, int sign);

/* RCB_ERR_STATE (with a message) unless m is not yet finalized: structural
 * changes (what: "disk", ...) come before rcb_model_finalize. */
rcb_status rcb_model_check_editable(rcb_model *m, const char *what);

/* Check a bearing table (n rows, speeds strictly increasing when n > 1) and,
 * with b not NULL, store a copy of it in b in place of b's rows (b's old rows
 * are freed only on success). */
rcb_status rcb_model_bearing_rows(rcb_model *m, rcb_bearing_t *b, const char *name, size_t n,
                                  const double *speeds, const rcb_bearing_coefs *c);

/* Axial position (m) of node e + 1 of a segment of length L (m) and nel
 * elements starting at zs (m): from the segment start, so rounding does not
 * accumulate. The mesh (finalize) and the node lookup of an unfinalized
 * model (rcb_model_add_disk_at) share it, so both give the same double. */
static inline double rcb_segment_node_z(double zs, double L, size_t e, int nel) {
  return zs + L * (double)(e + 1) / (double)nel;
}

/* element_params.c: whether name has the shape of an element parameter,
 * "shaft.S.e<k>.KEY" or "shaft.S.e<a>-<b>.KEY" (three dots; names have
 * none), and its storage: *n slots (one, or one per element of the span)
 * at *slot, *slot + 2, ... (RCB_ERR_NOT_FOUND with a message when S, k or
 * KEY does not exist). */
int rcb_element_param_shape(const char *name);
rcb_status rcb_element_param_slot(rcb_model *m, const char *name, double **slot, size_t *n);

#endif
