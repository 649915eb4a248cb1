/*
 * The internal interface of io/ that other folders may use (identify/,
 * compare/): a measurement's channels resolved to model DOFs. The
 * measurement object itself is reached through the public rcb_measure.h;
 * meas_internal.h is private to io/. Not installed.
 */
#ifndef RCB_IO_H
#define RCB_IO_H

#include <stdint.h>

#include "core/rcb_internal.h"

/* A measurement's channels as the outputs and inputs of an rcb_frf: the
 * distinct response DOFs outs[0 .. nout) and reference DOFs ins[0 .. nin),
 * in order of first appearance, and per channel the index of its response
 * (ch_out) and reference (ch_in; FRF measurements only) among them. The
 * four arrays are the caller's, rcb_meas_channel_count entries each. */
typedef struct rcb_meas_dofs {
  size_t *ch_out, *ch_in;
  rcb_dof *outs, *ins;
  size_t nout, nin;
} rcb_meas_dofs;

/* Resolve every channel of ms against model m (station names, as
 * rcb_model_find_dof) into d (nout, nin set here). An unknown station, or an
 * FRF channel without a reference: RCB_ERR_NOT_FOUND and a message naming
 * the channel (1-based) in errmsg (RCB_ERRMSG_MAX bytes, may be NULL). The
 * one resolver of the fit and the comparison (io/channels.c). */
rcb_status rcb_meas_resolve_dofs(const rcb_meas *ms, const rcb_model *m, rcb_meas_dofs *d,
                                 char *errmsg);

/* The paper's eq. 19 noise (io/noise.c), for rcb_meas_add_noise and for
 * the adequacy test's calibration (identify/adequacy.c): one generator,
 * xoshiro256** seeded through splitmix64 (the same numbers on every
 * platform), one draw. */
typedef struct rcb_rng {
  uint64_t s[4];
} rcb_rng;
void rcb_rng_seed(rcb_rng *r, uint64_t seed);
/* The additive amplitude of a channel of n values f: ||f||_2 / n beta_s/100
 * (the measurement's units). */
double rcb_noise_level(const rcb_complex *f, size_t n, double beta_s);
/* One noisy value: fs (1 + beta_a/100 r1) + level r2 e^{i phi}; r1, r2
 * uniform in [-1, 1], phi in [0, 2 pi), drawn in that order; with phase > 0
 * (rad) then turned by e^{i phase r3}, r3 uniform in [-1, 1] drawn last. */
rcb_complex rcb_noise_draw(rcb_rng *r, rcb_complex fs, double beta_a, double level,
                           double phase);

#endif /* RCB_IO_H */
