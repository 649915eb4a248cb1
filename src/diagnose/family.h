/*
 * The families of candidate effects (issue #23): each family lives in its own
 * file, src/diagnose/family_<name>.c, and fills one small table of functions,
 * as every N_Vector kind fills N_Vector_Ops in SUNDIALS. The diagnosis
 * (diagnose.c and its stages) iterates over the list in catalogue.c and never looks inside a
 * family: adding a family is one new file, one line in that list and one in
 * src/CMakeLists.txt.
 *
 * A family either edits the model (a coupling, a bearing, a pedestal, a
 * shaft element, an added mass: the candidate's model is a clone of the base
 * model, edited, finalized, given its starting values) or the measurement
 * chain (a sensor's gain and phase, a sign, two swapped probes: the model is
 * the base model unchanged, the fit of the candidate reads the measurement
 * through the edited chain). Both sit behind the same table; a family of the
 * second kind sets DIAG_FAM_CHAIN and fills fit_setup, never edit.
 *
 * Private to diagnose/.
 */
#ifndef RCB_DIAG_FAMILY_H
#define RCB_DIAG_FAMILY_H

#include "core/rcb_internal.h"
#include "rcb/rcb_identify.h"
#include "rcb/rcb_model.h"

struct diag_cand;
struct rcb_diag;

/* Family flags. */
#define DIAG_FAM_ADDS_DOFS 1u   /* its models have DOFs the base model lacks (a pedestal):
                                   scored on their own sweep, one start, and on the
                                   frequency subset its start is a grid (refit_start) */
#define DIAG_FAM_SCORE_ALONE 2u /* its parameters have no dZ/dp (a sensor's gain): not in
                                   a batch; a chain family's columns come from the model
                                   values of the base fit's sweep (rcb_fit_chain_jacobian) */
#define DIAG_FAM_CHAIN 4u       /* it edits the measurement chain, not the model: the
                                   model of its candidates is the base model, and
                                   --apply refuses (nothing in the model to change) */
#define DIAG_FAM_PLACE_WALK 8u  /* its candidates sit at nodes of a shaft (node, shaft,
                                   variant set): the run-off path walks from the best
                                   pre-fit to the neighbouring nodes (place_search) */
#define DIAG_FAM_ONE_REFIT 16u  /* its candidates are alike from place to place (one at
                                   every shaft element): of each variant only the best
                                   scored takes a refit, and none a pre-fit of the
                                   run-off path, so that neighbours do not crowd the
                                   other effects out (refit_best, nominal_starts) */

typedef struct diag_family {
  const char *name; /* "coupling", "bearing", ...: for messages and tests */
  unsigned flags;   /* DIAG_FAM_* */
  /* Lay out the family's candidates at every place of the fitted, finalized
   * model m (rcb_diag_new_cand, rcb_diag_add_par). */
  rcb_status (*enumerate)(struct rcb_diag *d, const rcb_model *m);
  /* The structural edit of candidate c on an unfinalized clone m of the
   * base model (NULL: no structural edit). */
  rcb_status (*edit)(const struct diag_cand *c, rcb_model *m);
  /* After rcb_model_finalize: the edit's starting values (NULL: none). */
  rcb_status (*start)(const struct diag_cand *c, rcb_model *m);
  /* Before a refit (fit f of model m, parameters added): move the start
   * where the neutral start sees nothing (a pedestal: the best point of a
   * grid). NULL: the neutral start. */
  rcb_status (*refit_start)(struct rcb_diag *d, const struct diag_cand *c, rcb_model *m,
                            rcb_fit *f);
  /* On every fit of candidate c, after its parameters are added: the fixed
   * edits of the measurement chain (a sign, a swap; DIAG_FAM_CHAIN). NULL:
   * none. */
  rcb_status (*fit_setup)(const struct diag_cand *c, rcb_fit *f);
} diag_family;

/* The families, in catalogue order (catalogue.c). */
extern const diag_family rcb_diag_family_coupling;
extern const diag_family rcb_diag_family_bearing;
extern const diag_family rcb_diag_family_pedestal;
extern const diag_family rcb_diag_family_shaft;
extern const diag_family rcb_diag_family_mass;
extern const diag_family rcb_diag_family_speed;
extern const diag_family rcb_diag_family_chain;
extern const diag_family rcb_diag_family_element;

/* Helpers for the families (catalogue.c). */
/* A new candidate of family fam and effect e at place (NULL: out of memory;
 * the pointer is valid until the next call). */
struct diag_cand *rcb_diag_new_cand(struct rcb_diag *d, const diag_family *fam, int effect,
                                    const char *place);
/* One more parameter of c: its name (fmt with one %s for item), bounds
 * (parameter units) and whether it is fitted as log. */
void rcb_diag_add_par(struct diag_cand *c, const char *fmt, const char *item, double lo,
                      double hi, int logp);
/* Bounds for a parameter starting at v: four decades either way (log) when
 * positive, else linear from 0 to hi0. */
void rcb_diag_bounds(double v, double hi0, double *lo, double *hi, int *logp);
/* Whether name is among the parameters of the model as it is (fitted
 * before the candidates: not a candidate). */
int rcb_diag_is_base(const struct rcb_diag *d, const char *name);
/* Mass of the rotor train, kg: shafts, disks, coupling hubs (1 when 0). */
double rcb_diag_rotor_mass(const rcb_model *m);

#endif /* RCB_DIAG_FAMILY_H */
