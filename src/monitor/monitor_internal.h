/*
 * The monitor object (rcb_monitor.h), private to monitor/: commissioning in
 * monitor_create.c, the allocation-free update in monitor.c, the chi-square
 * distribution in chi2.c. monitor/ comes after diagnose/ in the data flow
 * and uses the public API and the documented internal interfaces only
 * (identify/identify.h, diagnose/diagnose.h, core).
 *
 * Residual layout: point p = c * npts + i of the set-up gives the two real
 * residuals 2 p (radial: along the commissioning value e_0) and 2 p + 1
 * (tangential), each divided by its standard deviation ("whitened").
 */
#ifndef RCB_MONITOR_INTERNAL_H
#define RCB_MONITOR_INTERNAL_H

#include <stdint.h>

#include "core/rcb_internal.h"
#include "rcb/rcb_monitor.h"

#define RCB_MONITOR_NAME 128
#define RCB_MON_DEG 0.017453292519943295 /* rad per degree */
/* Points per block of the reweighted covariance (monitor_gls.c: C += B B^T
 * by BLAS dsyrk on 2 MON_SYRK_POINTS rows at a time) */
#define MON_SYRK_POINTS 128

struct mon_image; /* a commissioning image (monitor_image.c), below */

/* A candidate in the rank space (dimension k): its estimate rows and the
 * orthonormal directions it adds beyond the tracked parameters. */
typedef struct mon_cand {
  rcb_effect effect;
  char place[RCB_MONITOR_NAME];
  char desc[2 * RCB_MONITOR_NAME];
  char params[RCB_MONITOR_MAXP * RCB_MONITOR_NAME];
  size_t np;       /* its parameters */
  size_t dof;      /* directions beyond the tracked ones; 0: not scored */
  double *est;     /* np x k row-major: its parameters' step = est y */
  double *test_t;  /* nt x k row-major: the tracked step fitted jointly with it */
  double se_t[RCB_MONITOR_MAX_TRACKED]; /* and its standard errors */
  double th_now[RCB_MONITOR_MAX_TRACKED], set_now[RCB_MONITOR_MAX_TRACKED]; /* the
                        same on the reweighted path, this update */
  double *dir;     /* dof x k row-major: orthonormal, score = ||dir y||^2 */
  double se[RCB_MONITOR_MAXP]; /* standard errors, parameter units */
  size_t col;        /* its first column in G */
  double score_now;  /* this update's score */
  double size_now[RCB_MONITOR_MAXP], se_now[RCB_MONITOR_MAXP]; /* this update's
                        estimate and standard error */
  double neutral[RCB_MONITOR_MAXP]; /* the parameters' values the columns are at */
  double lo[RCB_MONITOR_MAXP], hi[RCB_MONITOR_MAXP]; /* the catalogue's plausible range */
  int implausible;   /* this update: some parameter's 95 % interval outside [lo, hi] */
  const struct rcb_fit_dz *dz; /* np: its derivative matrices (batched candidates
                        with opts.relinearise; NULL otherwise) */
  struct rcb_fit_adj *adj; /* its joint step's columns by one adjoint sweep
                        (tracked then its own derivative matrices; settable,
                        with dz, not on the low-rank path): rcb_mon_adj_init */
  double *pole;      /* with adj, n x (1 + nt + np): its one-pole model, the
                        coefficient per point (Re, Im) then the baseline's
                        columns of its joint step, Q G (monitor.c, pole_fill) */
  int pole_ready;    /* 1: pole and pole_dx filled; 0: not yet (a create from
                        an image fills them at the first update that needs
                        them); -1: no model (the sweep failed) */
  double pole_dx[RCB_MONITOR_MAX_TRACKED + RCB_MONITOR_MAXP]; /* with pole: the
                        joint step (parameter units) the sweep's change beyond the
                        linear one at MON_POLE_STEP standard errors makes, over
                        MON_POLE_STEP^2 */
  size_t *ep;        /* per entry of dz: row's and column's place in the
                        low-rank P; NULL: not on the low-rank path */
  int settable;      /* its parameters are the baseline model's own, at their
                        neutral values (rcb_model_set_param on mon->model):
                        the joint step can be re-linearised */
  char pname[RCB_MONITOR_MAXP][RCB_MONITOR_NAME]; /* their names (settable) */
  double r0[RCB_MONITOR_MAXP * RCB_MONITOR_MAXP]; /* the upper triangle of its block
                        of R at create (row-major): s = r0 x for parameter steps x,
                        so that est = r0^-1 dir */
  double xd[RCB_MONITOR_MAXP]; /* the reweighted path: this update's s, its
                        orthonormal components beyond the tracked columns in the
                        update's own noise, on the re-linearised y (the drift
                        test's input; dir y on the other path) */
} mon_cand;

/* Most DOFs of P for the low-rank re-evaluation (monitor_lowrank.c). */
#define MON_LOWRANK_MAXP 32
#define MON_LOWRANK_CAND 8 /* most DOFs one candidate adds to P */

/* The re-linearisation's evaluations by the Woodbury identity
 * (monitor_lowrank.c): P the DOFs the tracked parameters touch. */
typedef struct mon_lowrank {
  size_t np, nin;      /* |P|, distinct inputs of the set-up */
  size_t npt;          /* the tracked parameters' DOFs: the first npt of P; the
                          rest are the settable candidates' */
  size_t *act, *loc;   /* work (MON_LOWRANK_MAXP each): the places in P of an
                          evaluation's DOFs, and each place's local index */
  size_t *pdof;        /* P: matrix rows */
  struct rcb_fit_dz *dz; /* nt: the tracked parameters' derivative matrices */
  size_t *ep;          /* per derivative entry: its row's and column's place in P */
  size_t *ch_in;       /* nch: each channel's input */
  rcb_complex *a;      /* npt x np: H0_{o,P} in the channel's kind, per point */
  rcb_complex *b;      /* npts x nin x np: H0_{P,i} (receptance) */
  rcb_complex *hpp;    /* npts x np x np, column-major: H0_PP (receptance) */
  rcb_complex *dZ, *M, *X; /* work: np x np, np x np, np x nin */
  rcb_complex *dm;     /* npt: the change of the model values */
  int *ipiv;           /* np */
  const double *w;     /* the set-up's frequencies, rad/s (npts; its own copy's) */
  double speed;        /* rotor speed, rad/s (negative: synchronous) */
} mon_lowrank;

/* Workspace of the small QRs in the rank space (k x p, p <= nt + MAXP). */
typedef struct mon_small {
  double *A, *R, *Ri, *tau, *work;
  size_t lwork;
} mon_small;

struct rcb_monitor {
  rcb_allocator user;  /* the caller's hooks */
  rcb_allocator alloc; /* the same, counting live bytes into held */
  size_t held;
  char errmsg[RCB_ERRMSG_MAX];

  /* set-up */
  size_t nch, npts, npt, n; /* channels, points per channel, npt = nch * npts, n = 2 npt */
  rcb_complex *e0;     /* commissioning values, npt */
  double *h0abs;       /* |baseline model|, npt */
  rcb_complex *u;      /* unit direction of e_0 per point (radial frame) */
  double *winv;        /* 2 per point: 1 / sd of the radial, tangential residual */
  double *sd_new_rad;  /* radial sd of one new measurement per point (floor %) */
  double e0norm2;      /* sum |e_0|^2 */
  double *e0abs;       /* |e_0|, npt */
  double floor2;       /* sum of sd_new_rad^2 (the noise floor's square) */

  /* settings */
  double alpha, cusum_k, cusum_h, threshold;
  size_t top, relin;

  /* tracked parameters */
  size_t nt;
  char tname[RCB_MONITOR_MAX_TRACKED][RCB_MONITOR_NAME];
  double tlo[RCB_MONITOR_MAX_TRACKED], thi[RCB_MONITOR_MAX_TRACKED];
  double t0[RCB_MONITOR_MAX_TRACKED];   /* baseline values */
  double tse[RCB_MONITOR_MAX_TRACKED];  /* standard errors */
  double tbv[RCB_MONITOR_MAX_TRACKED];  /* the baseline values' variances
                                           (opts.baseline_cov's diagonal, 0: exact) */
  double *test;        /* nt x k row-major: tracked step = test y */
  double *tdir;        /* nt x k row-major: orthonormal basis of the tracked columns */
  double cus_up[RCB_MONITOR_MAX_TRACKED], cus_dn[RCB_MONITOR_MAX_TRACKED];
  /* the self-starting CUSUM's reference (rcb_monitor.h): the
   * inverse-variance weighted mean of the commissioning (step 0) and of the
   * in-control updates' steps, kept as sum(step / var) (1 / parameter
   * units) and sum(1 / var) (1 / parameter units^2); ref_started: the
   * commissioning's pseudo-observation is in (or a reset dropped it) */
  double ref_sum[RCB_MONITOR_MAX_TRACKED], ref_w[RCB_MONITOR_MAX_TRACKED];
  int ref_started, ref_frozen[RCB_MONITOR_MAX_TRACKED];
  /* the baseline's error in the CUSUM (rcb_monitor.h, sequential detector;
   * monitor.c, rcb_mon_curvature): opts.baseline_cov (nt x nt row-major,
   * parameter units^2), bM[(a * MAX + i) * MAX + j] the error of tracked a's
   * step per unit error of i's baseline value per unit change of j (1 /
   * parameter j's units), bq the normal quantile the allowance is raised by
   * (-), bcurv 1 when opts.baseline_cov was given; bref[a * MAX + j]: the
   * sum of step j / var over a's reference (as ref_sum) */
  double bcov[RCB_MONITOR_MAX_TRACKED * RCB_MONITOR_MAX_TRACKED];
  double bM[RCB_MONITOR_MAX_TRACKED * RCB_MONITOR_MAX_TRACKED * RCB_MONITOR_MAX_TRACKED];
  double bq;
  int bcurv;
  double bref[RCB_MONITOR_MAX_TRACKED * RCB_MONITOR_MAX_TRACKED];

  /* rank space */
  size_t k;            /* rank of all columns */
  double *Q;           /* n x k row-major (residual i: Q + k i), orthonormal columns */
  double *G;           /* Q^T J, k x ncol column-major (tracked columns first) */
  size_t ncol;
  mon_cand *cand;
  size_t ncand;

  /* re-linearisation: the baseline model (owned copy) and a fit of the
   * tracked parameters on the commissioning values, its residuals at the
   * baseline (model minus e_0, the fit's Re/Im layout) */
  rcb_model *model;
  rcb_meas *setup;
  rcb_fit *fit;
  double *rbase;       /* n */
  double *rmx;         /* with opts.relinearise: n x (1 + nt + MAXP) then k x (1 +
                          nt + MAXP), column-major: the joint Gauss-Newton step's
                          evaluations and their projections (monitor.c, joint_gn) */
  double *tres;        /* nt x n row-major (with opts.relinearise): Q test^T, the
                          tracked estimator applied to the whitened residuals, so
                          the first re-evaluation needs no pass over Q */
  mon_lowrank *lr;     /* the evaluations without a sweep, NULL: by sweeps */
  struct rcb_fit_dz *cdz; /* the batched candidates' derivative matrices, ncdz
                          (kept with opts.relinearise) */
  struct rcb_fit_dz *tdz; /* nt: the tracked parameters' (with a candidate's adj) */
  double *rat;         /* with tdz: n x (1 + nt + the most np of a candidate
                          with adj), the joint step's one-pole model's
                          coefficient per point, then its columns' correction
                          D or, for a candidate without c->pole, the baseline's
                          columns (monitor.c, pole_step, pole_correct) */
  size_t ncdz;

  /* noise of the reweighted path */
  int reweight, have_sd0;
  double beta_a, beta_s, navg_inv; /* beta_a, beta_s: times nscale */
  double nscale;       /* opts.noise_scale (1: as declared), applied to the declared
                          noise at create and to the sd an update passes */
  double phase_var;    /* variance of the phase turn, rad^2 (phase_deg^2 / 3) */
  double *var0;        /* 2 per point: radial, tangential variance of one
                          measurement at the commissioning values */
  double *sd0;         /* opts.sd copied (have_sd0), npt */
  double *C, *z, *z0, *Atw, *b1; /* k x k, k, k, k x ncol (U^-T G: every column in
                          this update's metric, the tracked ones first), k x 2
                          MON_SYRK_POINTS */
  double *Cfix;        /* NULL, or (1 + nch) x k x k (upper triangles): with
                          opts.reweight on eq. 19 noise without a phase term and
                          without sd, the parts of C that depend on the set-up only
                          (monitor_gls.c, rcb_mon_pass): the commissioning's share,
                          then each channel's additive noise per unit variance */
  double *achan;       /* nch: eq. 19 additive amplitude of this update */
  double *Jx;          /* k x (nt + MAXP), column-major: the joint columns of the
                          tracked parameters and the best candidate at the
                          current estimate (monitor.c, joint_relin); between the
                          re-linearised tracked step and rcb_mon_gls its first nt
                          columns are the tracked columns at that step (jt set) */
  int jt;              /* Jx holds the tracked columns at this update's step */
  mon_small sw;

  /* update workspace */
  double *r, *rm;      /* n each */
  double *y, *ym;      /* k each */
  double *y0;          /* k: y before the re-linearised tracked step, the change
                          from the baseline the candidates are scored on */
  double *pscore;      /* ncand: log p-value of each candidate's score */
  double *gatt;        /* ncand: a CUSUM attribution's explained part per candidate
                          (monitor_drift.c; negative: dependent, not compared) */
  size_t *order;       /* ncand */
  size_t updates;

  /* the drift test and the CUSUM alarms' attribution (monitor_drift.c):
   * the last MON_DRIFT_WINDOW updates in a ring, and the sums since
   * commissioning (or rcb_monitor_reset_cusum) that carry the commissioning
   * noise every update shares */
  size_t dcount, dhead; /* updates in the ring, the newest's slot */
  size_t dall;         /* updates in the sums */
  int dfree;           /* 1 after a reset: the common offset is free (no prior) */
  double rho;          /* the share of the commissioning noise in an update's
                          variance (-): (1/N) / (1 + 1/N) */
  double *dy;          /* MON_DRIFT_WINDOW x k: y of each update (after the
                          re-linearised tracked step) */
  double *dth;         /* MON_DRIFT_WINDOW x RCB_MONITOR_MAX_TRACKED: that step */
  double *ds;          /* MON_DRIFT_WINDOW x ncand x RCB_MONITOR_MAXP: each
                          candidate's s = dir y (on the reweighted path xd: the
                          same in the update's own noise) */
  double *dysum;       /* k: sum of y over dall updates */
  double *dssum;       /* ncand x RCB_MONITOR_MAXP: sum of each candidate's s */
  double dthsum[RCB_MONITOR_MAX_TRACKED]; /* sum of the steps */
  double *dY;          /* k: work, the accumulated change */

  uint64_t img_fp;     /* the commissioning image's fingerprint of the inputs
                          (monitor_image.c) */
};

/* Updates the drift test looks back over, and the onsets it tries within
 * them (1 .. MON_DRIFT_WINDOW updates ago, monitor_drift.c). */
#define MON_DRIFT_WINDOW 32
#define MON_DRIFT_NONSET 10

#define rcb_mon_fail(mon, st, ...) rcb_fail((mon), (st), __VA_ARGS__)

/* chi2.c: log P(X > x) of chi-square(dof), finite where the tail underflows. */
double rcb_mon_chi2_logsf(double x, double dof);

/* monitor_create.c: allocation through the monitor's counting hooks. */
/* Eq. 19's additive amplitude of one channel's n values v (monitor_create.c):
 * beta_s / 100 x their rms, the channel's units (beta_s, %). */
double rcb_mon_eq19_amp(double beta_s, const rcb_complex *v, size_t n);
void *rcb_mon_alloc(rcb_monitor *mon, size_t count, size_t size);
struct rcb_diag_cand_desc; /* diagnose/diagnose.h */
/* Candidate i of the catalogue as the monitor fits it (monitor_create.c):
 * the diagnosis' description, with a swap of two probes made linear. */
void rcb_mon_cand_desc(const rcb_diag *d, size_t i, struct rcb_diag_cand_desc *c);

/* The candidates kept for the monitor and their first columns in J. */
typedef struct col_plan {
  size_t *cand;   /* catalogue index of each kept candidate */
  size_t *col;    /* its first column */
  int *own;       /* 1: its model has other DOFs (its own sweep) */
  double *neutral; /* ncol: each candidate column's parameter value in its model */
  size_t ncand, ncol;
} col_plan;

/* monitor.c: the tracked parameters of mon->model back at their baseline
 * values and candidate c's (if any) at their neutral ones. */
void rcb_mon_model_restore(rcb_monitor *mon, const mon_cand *c);

/* monitor_lowrank.c: set up the low-rank re-evaluation where it applies
 * and reproduces a sweep (an error only for memory), after the rank space
 * (it marks the candidates it takes: c->ep); the change of every point's
 * model value (SI, channel-major) for tracked steps theta and, with c
 * (c->ep set), candidate c's parameters at neutral + s; free. */
/* The prepared adjoint sweeps of the joint steps that are not on the
 * low-rank path (monitor.c; after rcb_mon_lowrank_init). */
rcb_status rcb_mon_adj_init(rcb_monitor *mon, int lazy);
rcb_status rcb_mon_lowrank_init(rcb_monitor *mon, const struct mon_image *im);
rcb_status rcb_mon_lowrank_change(rcb_monitor *mon, const double *theta, const mon_cand *c,
                                  const double *s, rcb_complex *dm);
void rcb_mon_lowrank_free(rcb_monitor *mon, mon_lowrank *lr);

/* monitor.c: with opts.baseline_cov, the curvature of the tracked steps in
 * the baseline (mon->bM, by model re-evaluations at create: nt (nt + 3) / 2
 * of them); called last in create. */
rcb_status rcb_mon_curvature(rcb_monitor *mon);

/* monitor_rank.c: the QR of the whitened columns J (n x ncol; the basis
 * made explicit in mon->Q), then the rank space; J's block becomes mon->Q. */
rcb_status rcb_mon_factor(rcb_monitor *mon, rcb_diag *d, const double *J, size_t ncol);
/* With im (a commissioning image, J NULL): G from it, Q already in place. */
rcb_status rcb_mon_rank_space(rcb_monitor *mon, rcb_diag *d, const col_plan *pl, double *J,
                              const struct mon_image *im);

/* monitor_create.c's pieces used by the update */
void rcb_mon_whiten(const rcb_monitor *mon, const rcb_complex *d, double *r);
/* Thin QR of A (k x p, column-major, overwritten by its Q) with R and R^-1
 * (p x p); *ok = 0 for a dependent column. No allocation. */
rcb_status rcb_mon_small_qr(rcb_monitor *mon, mon_small *w, size_t k, size_t p, int *ok);
/* monitor_gls.c: what create prepares for the update's one pass over Q
 * (mon->tres, mon->Cfix; after the rank space), and that pass: y = Q^T r
 * (mon->r), with proj ym = Q^T rm (mon->rm), with gls the covariance C
 * (upper triangle) of the reweighted path. */
rcb_status rcb_mon_pass_init(rcb_monitor *mon);
void rcb_mon_pass(rcb_monitor *mon, const rcb_complex *v, const double *sd, int gls, int proj);
/* monitor_gls.c: the statistics in the update's own covariance (mon->C from
 * rcb_mon_pass), on y (the change the re-linearised tracked step leaves):
 * the tracked step dtheta beyond the re-linearised one and its standard
 * errors, T, and every candidate's score and estimates. */
rcb_status rcb_mon_gls(rcb_monitor *mon, double *dtheta, double *se, double *T);
/* Its pieces, for the joint re-linearisation of monitor.c (after
 * rcb_mon_pass and rcb_mon_gls, whose Cholesky factor U stays in mon->C): X (k x m,
 * column-major) <- U^-T X (0 or LAPACK's info); with w->A = Qa (k x p) and
 * w->Ri from rcb_mon_small_qr, qz = Qa^T z and the sum of squares of its
 * entries first .. p; rows first .. first + q of Ri qz and their standard
 * errors. */
int rcb_mon_gls_solve(const rcb_monitor *mon, double *X, size_t m);
double rcb_mon_gls_explained(const mon_small *w, const double *z, size_t k, size_t first,
                             size_t p, double *qz);
void rcb_mon_gls_step(const mon_small *w, const double *qz, size_t p, size_t first, size_t q,
                      double *x, double *se);

/* monitor_drift.c: the window GLR of a drift growing linearly from an
 * onset m updates ago (m <= count, on the grid of onsets), on dof components of s (component i of
 * lag j at ring[((head + w - j) % w) * ld + i]), with the commissioning's
 * shared noise (a common offset, share rho of the variance; free: no prior)
 * taken out through sall (the sums of s over nall updates). Returns the
 * largest GLR, its m and the drift rate per update of each component. */
double rcb_mon_drift_glr(const double *ring, size_t ld, size_t w, size_t head, size_t count,
                         size_t dof, const double *sall, size_t nall, double rho, int free_off,
                         size_t *mbest, double *rate);
/* The update's part: push this update (y, the re-linearised step theta),
 * the drift test into res, and the attribution of every CUSUM alarm. */
void rcb_mon_drift_update(rcb_monitor *mon, const double *theta, int gls,
                          rcb_monitor_result *res);
void rcb_mon_drift_reset(rcb_monitor *mon);
/* The one naming rule's BIC change of a score with dof degrees of freedom. */
double rcb_mon_bic(const rcb_monitor *mon, double score, size_t dof);
/* The BIC half of rcb_monitor_named's rule (r->ntop >= 2). */
int rcb_mon_bic_apart(const rcb_monitor *mon, const rcb_monitor_result *r);
/* *p: the upper-tail probability of the test that candidate a adds to
 * candidate c's fit in this update (gls: the reweighted metric), 1 when
 * a's columns lie in the span of c's and the tracked ones. Uses mon->sw. */
rcb_status rcb_mon_adds(rcb_monitor *mon, int gls, const mon_cand *a, const mon_cand *c,
                        double *p);

/* monitor_image.c: the commissioning image (rcb_monitor_image_save). Byte
 * offsets of its sections once checked (rcb_mon_image_open: every
 * dimension, the fingerprint, the checksum, every value finite). */
typedef struct mon_image {
  const unsigned char *p;
  size_t k;          /* rank */
  int lr;            /* the low-rank path was taken */
  size_t lnp, lnin;  /* its |P| and inputs */
  size_t g, a, ep;   /* offsets of G, the low-rank blocks, the candidates' flags
                        (Q at the head's end) */
} mon_image;
uint64_t rcb_mon_image_fingerprint(const rcb_monitor *mon, const rcb_diag *d,
                                   const struct col_plan *pl, unsigned effects);
rcb_status rcb_mon_image_open(rcb_monitor *mon, const void *buf, size_t size, uint64_t fp,
                              size_t ncol, size_t ncand, mon_image *im);
/* n doubles of the image from byte offset at into x. */
void rcb_mon_image_doubles(const mon_image *im, size_t at, double *x, size_t n);
/* The low-rank blocks and the check's outcome into lr (after its layout). */
rcb_status rcb_mon_image_lowrank(rcb_monitor *mon, const mon_image *im, mon_lowrank *lr);

/* Little-endian fields and FNV-1a 64 fingerprints of the saved forms (the
 * state, monitor_state.c; the commissioning image, monitor_image.c), in one
 * place: 8 bytes, least significant first, whatever the host. */
#define RCB_MON_FNV_OFFSET 0xcbf29ce484222325ull
#define RCB_MON_FNV_PRIME 0x100000001b3ull
void rcb_mon_put_u64(unsigned char *p, uint64_t v);
uint64_t rcb_mon_get_u64(const unsigned char *p);
void rcb_mon_put_f64(unsigned char *p, double x);
double rcb_mon_get_f64(const unsigned char *p);
uint64_t rcb_mon_fnv_bytes(uint64_t h, const void *data, size_t n);
uint64_t rcb_mon_fnv_u64(uint64_t h, uint64_t v);
uint64_t rcb_mon_fnv_f64(uint64_t h, double x);
uint64_t rcb_mon_fnv_str(uint64_t h, const char *s);

#endif
