/*
 * The diagnosis object, shared by catalogue.c and the family files (the
 * candidate effects of a model, family.h) and the stages of the flow that
 * diagnose.c runs in order (rcb_diag_run): baseline.c (the fit of the
 * model as it is), score.c (the score test), rank.c (which candidates are
 * refitted, and their order), prefit.c (pre-fits at the nominal model and
 * the place walk), refit.c (one candidate's refit, stage by stage),
 * locate.c and placed.c (where the misfit sits, and the candidates there),
 * words.c (the explanation); fits.c makes the fits they all run, and
 * tuning.h holds their tuning constants. A candidate is its family's edit of the
 * model (none, a coupling model change, an added disk, an added pedestal) or
 * of the measurement chain, plus the parameters the effect adds, so every
 * candidate model is made through the public edit API: clone the fitted
 * base model, edit, finalize, set parameters (rcb_model.h).
 */
#ifndef RCB_DIAG_INTERNAL_H
#define RCB_DIAG_INTERNAL_H

#include "core/rcb_internal.h"
#include "diagnose/diagnose.h" /* the interface other folders use */
#include "diagnose/family.h"

#define RCB_DIAG_NAME 128
#define RCB_DIAG_CARRY 1024

typedef struct diag_cand {
  const diag_family *fam;           /* its family: the edit, the start, the flags */
  rcb_effect effect;
  char place[RCB_DIAG_NAME];
  char desc[2 * RCB_DIAG_NAME];
  /* what the family's edit needs (family_<name>.c) */
  char target[RCB_NAME_MAX];        /* coupling, bearing, new disk or sensor name */
  char target2[RCB_NAME_MAX];       /* a second name (the other sensor of a swap) */
  int new_model;                    /* coupling: another coupling model, new_type */
  rcb_coupling_model new_type;
  double kt0, kr0, ct0, cr0;        /* its starting values */
  int new_disk;                     /* added mass: a new disk named target at node at */
  char at[RCB_DIAG_NAME];           /* its node, "#N" */
  double ped0[3];                   /* pedestal: kg, N/m, N s/m */
  double v0[4];                     /* other families' fixed values (a sensor's gain) */
  /* where its chain parameters (sensor.<r>.gain, .phase: not in any model)
   * ended in the fit whose model is kept in model: restored on every fit of
   * it after that (make_fit), as the model carries the model's parameters */
  double chain_v[RCB_DIAG_MAXP];
  int chain_kept;
  int refit_only;                   /* no neutral value: refitted, not scored */
  int late;                         /* refitted after the ranking: a leading local
                                       candidate's neighbour (neighbours.c), a span
                                       (span.c): one start, RCB_DIAG_SCREEN_ITER at most */
  char *carry;                      /* a chain candidate: the rcbtool options that read the
                                       data through its correction in the next round
                                       (rcb_diag_carry_text; owned, allocated only for
                                       chain candidates, so the catalogue of a monitor's
                                       fixed arena does not grow); NULL otherwise */
  /* a candidate at a node of a shaft (DIAG_FAM_PLACE_WALK) */
  size_t node;                      /* its node + 1 (0: other effects) */
  int variant;                      /* which parameter of the family (mass 0, inertia 1) */
  size_t shaft;                     /* and the shaft of its node */
  size_t np;
  size_t nlead;                     /* its pre-fit moves the first nlead parameters only,
                                       the refit all from there (0: all): continuation
                                       in the effect's size */
  char pname[RCB_DIAG_MAXP][RCB_DIAG_NAME];
  double lo[RCB_DIAG_MAXP], hi[RCB_DIAG_MAXP];
  double plo[RCB_DIAG_MAXP], phi[RCB_DIAG_MAXP]; /* what the part can be (the bounds
                                       unless the family says tighter, issue #33) */
  double lo_own[RCB_DIAG_MAXP];     /* > 0: the lower bound is this fraction of the
                                       parameter's value in the model the fit starts
                                       from (a ring's part of the disk's own), not lo:
                                       the fitted and the nominal base differ */
  int logp[RCB_DIAG_MAXP];
  char params[RCB_DIAG_MAXP * RCB_DIAG_NAME];
  /* results */
  double predicted;                 /* score-test reduction of F */
  double predicted_nom;             /* the same at the nominal model (far baseline) */
  int from_fit, from_nom;           /* refitted from the fitted / the nominal base */
  int prefitted;                    /* pre-fitted alone at the nominal model (far baseline) */
  double pre_F;                     /* its objective there (HUGE_VAL: failed) */
  double pre[RCB_DIAG_MAXP];        /* and its parameters, the start of the nominal refit */
  int pre_floor;                    /* its pre-fit ended at the noise floor */
  int screened;                     /* its refit was screened on the frequency subset
                                       (model: where it ended), then evaluated on all
                                       points there, and polished when near the best */
  double screen_F;                  /* the screen's objective on the subset */
  int screen_unsure, screen_floor;  /* it ended unsure; at the noise floor */
  int refitted, significant;
  rcb_claim claim;                  /* rcb_evidence_claim of its refit */
  int adequate;                     /* rcb_evidence_adequate (-1: unknown) */
  double chi2_limit;                /* the adequacy limit of its refit (NaN: unknown) */
  int polished;                     /* refitted on all points (0: evaluated where its
                                       screen ended: F and dbic upper bounds) */
  double F, err, dbic;              /* dbic: calibrated (rcb_evidence_dbic) */
  double dispersion;                /* F / its expectation with the candidate (NaN: unknown) */
  double white_z;                   /* whiteness of its residual (rcb_fit_white_z) */
  double adeq_chi2;                 /* F of its own adequacy test (at its own reference) */
  int beyond;                       /* a fitted value outside [plo, phi] (beyond_k) */
  size_t beyond_k;
  double beyond_v;
  rcb_evidence ev;                  /* what judge() decided its claim on */
  char fitted[RCB_DIAG_MAXP * (RCB_DIAG_NAME + 32)];
  rcb_model *model;                 /* refitted model (owned, finalized) */
} diag_cand;

typedef struct diag_base_par {
  char name[RCB_DIAG_NAME];
  double lo, hi;
  int logp;
  double chain_v; /* a sensor parameter: where the baseline fit left it (chain_kept) */
  int chain_kept;
} diag_base_par;

/* A correction of the measurement chain carried into every fit of the
 * diagnosis (rcb_diag_set_sensor, rcb_diag_swap_sensors; family_chain.c). */
typedef struct diag_carry {
  char a[RCB_NAME_MAX];  /* the response ("DB.y") */
  char b[RCB_NAME_MAX];  /* a swap: the other response; "" for a gain edit */
  double gain, phase;    /* a gain edit: dimensionless, rad */
} diag_carry;

struct rcb_diag {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  const rcb_model *m;
  const rcb_meas *meas;
  rcb_fit_scale scale;
  double beta_a, beta_s, band_lo, band_hi;
  double phase;                     /* the noise model's phase term, rad */
  rcb_complex *nref;                /* the noise model's reference: the fitted model's
                                       predictions as it is (nch * npts), shared by every
                                       fit after the baseline's first (issue #33) */
  int have_band;
  double *sd;                       /* known standard deviations (rcb_diag_set_sd), NULL:
                                       none; every fit weights by them */
  size_t nrefit;
  size_t nthreads;                  /* threads across candidates (parallel.c) */
  int (*progress)(void *user, size_t done, size_t total);
  void *progress_user;
  size_t progress_done;             /* steps reported: a count that only rises */
  diag_base_par *base;
  size_t nbase, cap_base;
  diag_carry *carry;                /* chain corrections carried into every fit */
  size_t ncarry, cap_carry;
  /* results */
  rcb_model *base_model;            /* the model with its own parameters fitted
                                       (owned, finalized) */
  rcb_model *nom_model;             /* a finalized copy of the model as given, when
                                       the baseline fit ran off from it (owned) */
  int far;                          /* the baseline fit ran off from the nominal model */
  double pre_best;                  /* the lowest pre-fit objective (far baseline), or HUGE_VAL */
  double best_F;                    /* the lowest objective of the refits on all points */
  size_t lead;                      /* the refit polished first (refit_best), or ncand */
  int screen_floor;                 /* a refit's screen ended at the noise floor */
  int node_crawl; /* added masses' pre-fits under the subset's limits (prefit_selected) */
  char drift[256];                  /* which parameter ran off, in words */
  double F0, err0, floor0;
  rcb_fit_adequacy adeq0;           /* the adequacy test of the model as it is */
  rcb_diag_misfit *mis;             /* per response sensor, the largest excess first */
  size_t nmis;
  size_t nres;
  rcb_diag_place *place;            /* per shaft node, the largest share first (locate.c) */
  int place_no_phase;               /* placement skipped: magnitudes only (locate.c) */
  size_t nplace;
  diag_cand *cand;
  size_t ncand, cap_cand;
  size_t *order;                    /* rank -> candidate */
  size_t cap_order;
  size_t span_tried;                /* spans fitted by the search of span.c, not kept as
                                       candidates: counted among those tried */
  rcb_diag_stats stats;             /* work done by the last run */
  int ran;
};

/* The error message of rcb_diag (core/rcb_internal.h, rcb_fail). */
#define rcb_diag_fail(d, st, ...) rcb_fail((d), (st), __VA_ARGS__)

/* Jobs across candidates (parallel.c): job(d, i, ctx) for i in [0, n) on
 * d->nthreads threads, each on its own shallow copy of d (its error message
 * and counters, merged in job order), results bit for bit those of a serial
 * run; after(d, i, ctx), when given, on the calling thread in job order (as
 * each job ends when serial, once all have ended when threaded). The first
 * failing job in job order decides the status and message. */
typedef rcb_status (*rcb_diag_job)(rcb_diag *d, size_t i, void *ctx);
typedef rcb_status (*rcb_diag_after)(rcb_diag *d, size_t i, void *ctx);
rcb_status rcb_diag_for_each(rcb_diag *d, size_t n, rcb_diag_job job, void *ctx,
                             rcb_diag_after after);

/* Before a refit of candidate c on its model m (fit f, base parameters
 * fitted): move the candidate's parameters to a better start where the
 * neutral start sees nothing (a pedestal: a scan of its mass and stiffness). */
rcb_status rcb_diag_refit_start(rcb_diag *d, const diag_cand *c, rcb_model *m, rcb_fit *f);
/* A fit of model m (not copied: m must outlive it) against the diagnosis'
 * measurement with its objective settings (scale, noise model or sd, band),
 * the base parameters when with_base holds RCB_DIAG_FIT_BASE, and candidate
 * c's parameters (c may be NULL); no intervals. rcb_diag_drop_fit destroys
 * it, counting its model sweeps in the diagnosis' figures. */
#define RCB_DIAG_FIT_BASE 1u
#define RCB_DIAG_FIT_LEAD 2u /* the candidate's first nlead parameters only (pre-fit) */
rcb_status rcb_diag_make_fit(rcb_diag *d, rcb_model *m, unsigned with_base, const diag_cand *c,
                             rcb_fit **out);
void rcb_diag_drop_fit(rcb_diag *d, rcb_fit *f);
/* The carried chain (family_chain.c): onto fit f, the corrections of
 * rcb_diag_set_sensor / rcb_diag_swap_sensors, then the base sensor
 * parameters where the baseline left them: as their start when f fits them
 * (with_base), folded into the fixed edit when it does not (the score test
 * reads the data as the baseline did). */
rcb_status rcb_diag_carry_apply(rcb_diag *d, rcb_fit *f, int with_base);
/* RCB_ERR_ARG, naming the measured responses, when name is a sensor
 * parameter whose response no channel measures; RCB_OK otherwise. */
rcb_status rcb_diag_carry_check(rcb_diag *d, const char *name);
/* Keep where the baseline fit f left the base sensor parameters. */
void rcb_diag_carry_keep(rcb_diag *d, const rcb_fit *f);
/* The rcbtool options that read the data through a chain correction of
 * kind (RCB_EFFECT_SENSOR_GAIN: fit the gain, and the phase on the complex
 * scale; _SIGN; _SWAP with r2) at response r on top of those carried, e.g.
 * "--params coupling.C.kt,sensor.DB.y.gain --sensor DA.x:sign=-1"; "" when
 * they do not fit in size. */
void rcb_diag_carry_text(const rcb_diag *d, rcb_effect kind, const char *r, const char *r2,
                         char *buf, size_t size);
/* Where the misfit of the model as it is sits, the effect class left open
 * (locate.c): fills d->place / d->nplace when the noise is known and the
 * model as it is fails the adequacy test; nothing otherwise. */
rcb_status rcb_diag_locate(rcb_diag *d);

/* Whether the model as it is fits the data to their noise, by the one rule
 * (rcb_evidence_adequate on its adequacy test: within the limit, or beyond
 * it with a white residual): 1 yes, 0 no, -1 unknown (words.c). */
int rcb_diag_base_adequate(const rcb_diag *d);

/* A finalized copy of model src with the diagnosis' allocator (caller destroys). */
rcb_status rcb_diag_copy_model(rcb_diag *d, const rcb_model *src, rcb_model **out);
/* Weights (channel-major, 0 or 1) keeping a subset of the measured
 * frequencies: one every 2.5 % in frequency, at least 150 (caller frees). */
double *rcb_diag_grid_weights(rcb_diag *d);
/* rcb_diag_grid_weights where it keeps at most half of the points, else
 * *out = NULL (all points); RCB_ERR_NOMEM with the message set. */
rcb_status rcb_diag_subset_weights(rcb_diag *d, double **out);
/* The candidate's model: a copy of the base model from (the fitted base, or
 * the nominal model), edited, finalized, the edit's starting values set
 * (caller destroys). */
rcb_status rcb_diag_candidate_model(rcb_diag *d, const diag_cand *c, const rcb_model *from,
                                    rcb_model **out);

/* ---- the stages of rcb_diag_run (diagnose.c), in the order it calls them ---- */

/* fits.c. Where the chain parameters of c (the last c->np of fit f) ended,
 * kept with the model of that fit (rcb_diag_make_fit restores them). */
void rcb_diag_keep_chain(diag_cand *c, const rcb_fit *f);
/* fits.c. F = r^T r with fit f's weights (r: d->nres values, filled), and
 * the error % of the same sweep. */
rcb_status rcb_diag_objective(rcb_diag *d, rcb_fit *f, double *r, double *F, double *err);

/* baseline.c. Fit the model as it is, on a copy: d->base_model, F0, error,
 * floor, residual count, the adequacy test and the sensors the misfit
 * concentrates on; whether the fit ran off from the nominal model (d->far,
 * then d->nom_model too). */
rcb_status rcb_diag_fit_baseline(rcb_diag *d);

/* score.c. Score every candidate at the fitted base model (nominal = 0:
 * c->predicted) or at the nominal one (c->predicted_nom; the caller swaps
 * d->base_model for d->nom_model). */
rcb_status rcb_diag_score_all(rcb_diag *d, int nominal);
/* score.c. Whether c is a fixed edit of the measurement chain (a sign, a
 * swap: no parameter), scored by what it does at the fitted base. */
int rcb_diag_fixed_chain(const diag_cand *c);

/* The candidates a step fits, in order, for rcb_diag_for_each (rank.c,
 * prefit.c). */
typedef struct diag_jobs {
  size_t *k;      /* candidate indices */
  size_t n, todo; /* jobs; refits reported to the progress callback */
  double *w;      /* the frequency subset, or NULL */
} diag_jobs;

/* rank.c. Choose the candidates to refit (and with a run-off baseline,
 * pre-fit them at the nominal model first), refit them stage by stage
 * (refit.c) on d->nthreads threads, and rank them (d->order). */
rcb_status rcb_diag_refit_best(rcb_diag *d);
/* rank.c. d->order: refitted candidates by claim then BIC change, then the
 * rest by predicted reduction. */
void rcb_diag_sort_order(rcb_diag *d);

/* prefit.c. Pre-fit the candidates j->k[0 .. j->n) alone at the nominal
 * model (the others, then added masses and inertias at nodes, then the
 * pedestals, left out on the subset once a pre-fit is at the noise floor). */
rcb_status rcb_diag_prefit_selected(rcb_diag *d, diag_jobs *j);
/* prefit.c. From the best pre-fitted added mass and inertia, pre-fit the
 * neighbouring nodes of the same shaft while their objective falls
 * (serial), unless a pre-fit already ended at the noise floor. */
rcb_status rcb_diag_place_search(rcb_diag *d, const double *w);
/* prefit.c. Whether an error err (%) is at the noise floor (%): below
 * RCB_DIAG_FLOOR_FACTOR times it. */
int rcb_diag_at_floor(double err, double floor);

/* refit.c: the steps of one candidate's refit, each a job across the
 * candidates (rank.c). 1: its first start(s), screened on the subset w (or
 * fitted on all points without w); 2: its random starts on the subset,
 * when no screen reached the noise floor; 3: evaluated on all points where
 * its screen ended; 4: polished on all points when near the best. */
rcb_status rcb_diag_refit_screen(rcb_diag *d, diag_cand *c, const double *w);
rcb_status rcb_diag_refit_restart(rcb_diag *d, diag_cand *c, const double *w);
rcb_status rcb_diag_refit_evaluate(rcb_diag *d, diag_cand *c);
rcb_status rcb_diag_refit_polish(rcb_diag *d, diag_cand *c);
/* refit.c. The screening fit on the frequency subset w (NULL: the fit on
 * all points), at most cap iterations on the subset. */
rcb_status rcb_diag_screen(rcb_fit *f, const double *w, size_t cap);
/* refit.c. The polish of a screened fit on all points from where it is,
 * one start, at most RCB_DIAG_POLISH_ITER iterations. */
rcb_status rcb_diag_polish(rcb_fit *f);
/* refit.c. A refit fitted (polished) or evaluated on all points, F and err:
 * its figures, its claim, and its model *m kept in c (*m set to NULL). */
rcb_status rcb_diag_refit_result(rcb_diag *d, diag_cand *c, rcb_model **m, rcb_fit *f,
                                 double F, double err, int polished);

/* placed.c. The model node a candidate acts at, from its node (a place
 * walk) or the station its first parameter names ("bearing.B2.kyy": B2,
 * "disk.DA.mass": DA), or an element's first node ("shaft.A.e5.stiffness",
 * a span's first element "shaft.A.e3-7.stiffness"); -1: none (a whole-shaft
 * effect, the speed, a sensor). */
long rcb_diag_cand_node(const rcb_diag *d, const diag_cand *c);
/* placed.c. Whether node (for an element, node or node + 1) is in the
 * placement's span (d->place, in_span). */
int rcb_diag_node_placed(const rcb_diag *d, long node, int element);

/* rank.c. Refit the candidates k[0 .. n) after the ranking (their from_fit,
 * from_nom marked), stage by stage as rcb_diag_refit_best does, and rank
 * again. */
rcb_status rcb_diag_refit_more(rcb_diag *d, size_t *k, size_t n);

/* placed.c. When no candidate explains the data and the equivalent loads
 * (rcb_diag_locate) place the misfit at a few nodes, refit every
 * one-parameter model candidate acting there from a grid across its
 * bounds, and rank again. */
rcb_status rcb_diag_placed_refits(rcb_diag *d);

/* neighbours.c. When the leading candidate is significant and sits at a
 * node or an element (DIAG_FAM_PLACE_WALK) where the placement points, or
 * next to it, refit the candidates of its kind at the neighbouring places
 * and in the placement's span, walking on while the lead moves, and rank
 * again: the data choose among neighbours by the one rule. */
rcb_status rcb_diag_neighbour_refits(rcb_diag *d);

/* span.c. When a shaft's stiffness or mass leads (an element, the whole
 * shaft) and nothing explains the data, search the span of its elements
 * (shaft.S.e<a>-<b>.stiffness | mass) the data point to, refit the best and
 * the spans one element from it as candidates, and rank again. */
rcb_status rcb_diag_span_refits(rcb_diag *d);

#endif
