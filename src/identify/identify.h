/*
 * The internal interface of identify/ that other folders may use (the
 * diagnosis): what the public rcb_identify.h does not offer, on the same
 * opaque rcb_fit. fit_internal.h (the fit object's fields) is private to
 * identify/. Not installed.
 */
#ifndef RCB_IDENTIFY_INTERNAL_API_H
#define RCB_IDENTIFY_INTERNAL_API_H

#include "core/rcb_internal.h"

/* Model sweeps (one model solve at every point the fit uses) done by f
 * since its creation, by runs, residuals and Jacobians alike (the
 * diagnosis counts its work with it). */
size_t rcb_fit_sweeps(const rcb_fit *f);

/* Resolve the residual layout (band, weights, noise model) and size the
 * workspaces, as rcb_fit_run and the building blocks do first: RCB_ERR_ARG
 * with a message when no point is left, RCB_ERR_NOMEM. */
rcb_status rcb_fit_prepare(rcb_fit *f);

/* Evaluate the model with solver s instead of RCB_SOLVER_AUTO (the FRF
 * workspace made anew, before any run): a caller that needs every byte
 * through its allocator hooks (the monitor) asks for RCB_SOLVER_BANDED,
 * as KLU allocates its factors itself (rcb_analysis.h). */
rcb_status rcb_fit_set_solver(rcb_fit *f, rcb_solver_kind s);
/* The solver f's sweeps use (the one RCB_SOLVER_AUTO chose, or the one set);
 * RCB_SOLVER_AUTO when f is NULL. */
rcb_solver_kind rcb_fit_get_solver(const rcb_fit *f);

/* Whether f's Jacobian goes by the adjoint (one transposed re-solve of the
 * outputs per point, rcb_frf_solve_adjoint) rather than the direct re-solve
 * (one per parameter and input): the adjoint needs fewer solves per point. */
int rcb_fit_adjoint_cheaper(const rcb_fit *f);

/* The paper's error % of the model values of f's last evaluation (as
 * rcb_fit_error, without another sweep). */
double rcb_fit_error_pct(const rcb_fit *f);

/* The channel (measurement channel index) of each residual of f's layout
 * (rcb_fit_prepare or any evaluation first): ch[j] for j < nres, rows of
 * rcb_fit_jacobian and rcb_fit_residuals (the plan of issue #23 sums each
 * candidate channel's rows). RCB_ERR_STATE before a layout exists. */
rcb_status rcb_fit_residual_channels(const rcb_fit *f, size_t *ch);
/* The whole layout of f's residuals (after rcb_fit_prepare or any
 * evaluation): for residual j < nres, its channel ch[j], point pt[j], part
 * part[j] (0: Re or the scale's single value, 1: Im, complex scale only)
 * and the square root of its weight sqrtw[j] (1 / sd on the scale with the
 * noise model or known sds); any pointer may be NULL. The localisation of
 * the misfit (diagnose/locate.c) weights its equivalent loads by them.
 * RCB_ERR_STATE before a layout exists. */
rcb_status rcb_fit_residual_layout(const rcb_fit *f, size_t *ch, size_t *pt, unsigned char *part,
                                   double *sqrtw);
/* One parameter's derivatives at a model: dM, dC, dG, dK over their
 * non-zero entries (DOF row, column; the units of M, C, G, K per unit of
 * the parameter) and dF/dp at unit speed (NULL when the force does not
 * depend on it). */
typedef struct rcb_fit_dz_entry {
  size_t row, col;
  double m, c, g, k;
} rcb_fit_dz_entry;
typedef struct rcb_fit_dz {
  rcb_fit_dz_entry *e;
  size_t ne;
  rcb_complex *dF;
} rcb_fit_dz;

/* The derivatives of fit c's parameters at its current model, dz[0 .. np)
 * allocated from a (rcb_fit_dz_free). No residual layout needed. */
rcb_status rcb_fit_dz_get(rcb_fit *c, const rcb_allocator *a, rcb_fit_dz *dz);
void rcb_fit_dz_free(const rcb_allocator *a, rcb_fit_dz *dz, size_t n);
/* Columns d r / d p (parameter units, nres x ndz column-major) of f's
 * residuals for parameters dz[0 .. ndz) of models equal to f's at its
 * current point, with the same DOFs (the score test of candidates at their
 * neutral values): eq. 9 by the adjoint, one factorisation per point for
 * all of them (fit_score.c). One sweep. */
rcb_status rcb_fit_jacobian_dz(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, double *J);
/* The same sweep prepared once (the monitor's joint step, whose update
 * allocates nothing): create copies the array dz (its entries stay the
 * caller's, alive until destroy) and allocates the sweep's workspace from
 * f's allocator; run gives rcb_fit_jacobian_dz's columns at f's current
 * point without an allocation (rcb_fit_last_residuals then gives that
 * sweep's residuals). */
typedef struct rcb_fit_adj rcb_fit_adj;
rcb_status rcb_fit_adj_create(rcb_fit *f, const rcb_fit_dz *dz, size_t ndz, rcb_fit_adj **out);
rcb_status rcb_fit_adj_run(rcb_fit *f, rcb_fit_adj *a, double *J);
void rcb_fit_adj_destroy(rcb_fit *f, rcb_fit_adj *a);

/* The weighted residuals (nres values) of the model values of f's last
 * sweep, rcb_fit_jacobian_dz's included, without another: what
 * rcb_fit_residuals would give at the same point. RCB_ERR_STATE before a
 * sweep. */
rcb_status rcb_fit_last_residuals(rcb_fit *f, double *r);
/* The adequacy test's whiteness statistic (rcb_fit_adequacy.white_z) of the
 * residuals r of fit f (rcb_fit_residual_count values, as rcb_fit_residuals
 * orders them; identify/adequacy.c). */
double rcb_fit_white_z(const rcb_fit *f, const double *r);

/* The residuals r (nres) of f from the model values of src's last sweep,
 * without a sweep of f's own: f and src fit the same model (at the same
 * point) to the same measurement with the same settings, f's measurement
 * chain may be edited (a sign, a swap: each of its channels reads a pair
 * of output and input some channel of src reads, with the same kind),
 * src's is not swapped. Afterwards f's model values are those of the
 * residuals (rcb_fit_error_pct). RCB_ERR_STATE when src cannot serve (then
 * rcb_fit_residuals), nothing changed. The diagnosis scores a sign or a
 * swap of the probes this way. */
rcb_status rcb_fit_residuals_from(rcb_fit *f, const rcb_fit *src, double *r);

/* Whether a parameter name belongs to the measurement chain rather than the
 * model (sensor.<response>.gain or .phase, rcb_identify.h): such a
 * parameter has no dZ/dp (rcb_fit_dz_get refuses it), and its column comes
 * from the fit's own Jacobian (rcb_fit_jacobian, or rcb_fit_chain_jacobian
 * without a sweep). 0: not a chain
 * parameter, RCB_CHAIN_GAIN or RCB_CHAIN_PHASE. Syntactic only: whether the
 * response is measured is checked by rcb_fit_add_param. */
#define RCB_CHAIN_GAIN 1
#define RCB_CHAIN_PHASE 2
int rcb_fit_param_is_chain(const char *name);
/* The response of chain parameter name ("sensor.DB.y.gain" -> "DB.y") into
 * r (cut to size); "" when name is not a chain parameter. */
void rcb_fit_chain_response(const char *name, char *r, size_t size);

/* Columns d r / d p (parameter units, nres x n column-major) of the chain
 * parameters names[0 .. n) (sensor.<response>.gain or .phase of a measured
 * response; they need not be parameters of f) at f's last evaluation, as
 * if they were added to f at the sensors' current values: the same columns
 * as rcb_fit_jacobian of a fit of those parameters on f's model, without
 * a sweep (a sensor parameter scales the model's values, it has no dZ/dp;
 * the score test of the sensor gains). RCB_ERR_STATE before an evaluation,
 * RCB_ERR_ARG for a name that is not a measured sensor's. */
rcb_status rcb_fit_chain_jacobian(rcb_fit *f, const char *const *names, size_t n, double *J);

/* The column d r / d s (nres values) of a swap of the probes of measured
 * responses a and b by a fraction s (issue #34, the monitor's linear
 * swap): each of the two reads (1 - s) its own response + s the other's,
 * at the same reference and kind (0: as wired, 1: exchanged, as
 * rcb_fit_swap_sensors), times its chain's factor, at f's last evaluation
 * and s = 0; exact, the reading is linear in s. RCB_ERR_STATE before an
 * evaluation or with either probe swapped already, RCB_ERR_ARG when a
 * channel of one has no channel of the other with its reference. */
rcb_status rcb_fit_swap_column(rcb_fit *f, const char *a, const char *b, double *J);

/* The sensors of f's measurement chain: one per distinct measured response,
 * in order of first appearance among the channels; the response name
 * (owned by the measurement), NULL past the end. */
size_t rcb_fit_sensor_count(const rcb_fit *f);
const char *rcb_fit_sensor_response(const rcb_fit *f, size_t k);
/* Move chain parameter name, already added to f, to value v (its units,
 * within its bounds): where a chain parameter lives between fits, as a
 * model parameter lives in the model (the diagnosis keeps a candidate's
 * fitted gain from its screen to its polish). RCB_ERR_ARG when name is not
 * a chain parameter of f or v is outside its bounds. */
rcb_status rcb_fit_set_chain_value(rcb_fit *f, const char *name, double v);

#endif /* RCB_IDENTIFY_INTERNAL_API_H */
