/*
 * NLopt backend of the fitter: minimises the objective of eq. 12,
 * F(x) = r^T W r, in the fit's internal coordinates x (x = ln p for log
 * parameters, x = p / s otherwise), with the parameter bounds mapped to x.
 *
 * Algorithm names: NLopt's own ("LN_BOBYQA", "NLOPT_LD_LBFGS", any case) or
 * the short aliases below. "GLOBAL+LOCAL" combines two: for G_MLSL / G_MLSL_LDS
 * LOCAL is the sub-optimiser of every local search (default LN_BOBYQA); for a
 * GN_ method LOCAL polishes the global optimum (default: no polish).
 *
 * Evaluation budget (maxeval), from the fit's max_iter:
 *   LD_ (gradient):       2 max_iter objective calls (an iteration is one
 *                         gradient plus, now and then, a line-search step);
 *   LN_ (derivative-free): (np + 1) max_iter calls (an iteration of a
 *                         derivative-free method buys about what one gradient
 *                         costs by differences: np + 1 model evaluations);
 *   GN_ / G_MLSL global:  10 (np + 1) max_iter calls, no ftol/xtol test (a
 *                         global search has no meaningful local step); a GN_
 *                         stage followed by a polish gets 2 (np + 1) max_iter
 *                         (it only has to find the right basin); the polish
 *                         and each MLSL local search use the LN_/LD_ rules
 *                         with ftol_rel and xtol_rel.
 * Global methods need finite bounds on every parameter.
 *
 * Results: iterations = objective calls (all stages); model evaluations are
 * counted by rcb_fit_objective (one per call, a Jacobian included). The
 * progress callback sees every call; a nonzero return stops the run
 * (RCB_ERR_STATE). The best point seen (the start included) is left in the
 * model, whatever the outcome. converged = NLopt result > 0 other than
 * MAXEVAL/MAXTIME_REACHED (so MLSL and a global method without polish never
 * report convergence). ROUNDOFF_LIMITED (and FAILURE of a gradient method
 * after some progress: its line search stalled) is a success that did not converge;
 * INVALID_ARGS -> RCB_ERR_ARG, OUT_OF_MEMORY -> RCB_ERR_NOMEM, FAILURE ->
 * RCB_ERR_STATE, each with a message naming the NLopt result.
 *
 * NLopt allocates its own optimiser object with malloc: it takes no
 * allocator hooks. Everything else goes through the fit's allocator.
 */
#include <math.h>
#include <string.h>

#include "identify/fit_internal.h"
#include "rcb/rcb_config.h"

#if RCB_WITH_NLOPT

#include <nlopt.h>

/* Short aliases, compared case-insensitively with '_' and '-' alike. */
typedef struct nl_alias {
  const char *alias;
  nlopt_algorithm alg;
} nl_alias;

static const nl_alias nl_aliases[] = {
    {"bobyqa", NLOPT_LN_BOBYQA},   {"sbplx", NLOPT_LN_SBPLX},
    {"subplex", NLOPT_LN_SBPLX},   {"cobyla", NLOPT_LN_COBYLA},
    {"neldermead", NLOPT_LN_NELDERMEAD}, {"lbfgs", NLOPT_LD_LBFGS},
    {"mma", NLOPT_LD_MMA},         {"slsqp", NLOPT_LD_SLSQP},
    {"direct-l", NLOPT_GN_DIRECT_L}, {"directl", NLOPT_GN_DIRECT_L},
    {"crs2", NLOPT_GN_CRS2_LM},    {"isres", NLOPT_GN_ISRES},
    {"mlsl", NLOPT_G_MLSL_LDS},
};

/* The NLopt algorithms this backend accepts (bound constraints only). */
static const nlopt_algorithm nl_accepted[] = {
    NLOPT_LN_BOBYQA, NLOPT_LN_SBPLX,  NLOPT_LN_COBYLA,   NLOPT_LN_NELDERMEAD,
    NLOPT_LD_LBFGS,  NLOPT_LD_MMA,    NLOPT_LD_SLSQP,    NLOPT_GN_DIRECT_L,
    NLOPT_GN_CRS2_LM, NLOPT_GN_ISRES, NLOPT_G_MLSL_LDS,  NLOPT_G_MLSL,
};

#define NL_NAMES_HELP                                                              \
  "accepted: LN_BOBYQA (bobyqa), LN_SBPLX (sbplx), LN_COBYLA (cobyla), "           \
  "LN_NELDERMEAD (neldermead), LD_LBFGS (lbfgs), LD_MMA (mma), LD_SLSQP (slsqp), " \
  "GN_DIRECT_L (direct-l), GN_CRS2_LM (crs2), GN_ISRES (isres), G_MLSL_LDS (mlsl), " \
  "G_MLSL; any case, optional NLOPT_ prefix; GLOBAL+LOCAL (e.g. mlsl+lbfgs, "      \
  "direct-l+bobyqa) picks the MLSL sub-optimiser or a local polish"

static int nl_lower(int c) { return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c; }
static int nl_upper(int c) { return (c >= 'a' && c <= 'z') ? c - 'a' + 'A' : c; }

/* Case-insensitive equality with '_' == '-'. */
static int nl_alias_eq(const char *a, const char *b) {
  for (; *a && *b; a++, b++) {
    int ca = nl_lower((unsigned char)*a), cb = nl_lower((unsigned char)*b);
    if (ca == '_') ca = '-';
    if (cb == '_') cb = '-';
    if (ca != cb) return 0;
  }
  return *a == *b;
}

/* One algorithm name of length n (not NUL-terminated) -> algorithm, or -1. */
static int nl_lookup(const char *s, size_t n) {
  char buf[64];
  size_t i, k = 0;
  while (n > 0 && (*s == ' ' || *s == '\t')) s++, n--;
  while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t')) n--;
  if (n == 0 || n >= sizeof buf) return -1;
  memcpy(buf, s, n);
  buf[n] = '\0';
  for (i = 0; i < sizeof nl_aliases / sizeof nl_aliases[0]; i++)
    if (nl_alias_eq(buf, nl_aliases[i].alias)) return (int)nl_aliases[i].alg;
  /* NLopt's own spelling: upper case, '_', no "NLOPT_" prefix */
  for (i = 0; i < n; i++) buf[i] = (char)(buf[i] == '-' ? '_' : nl_upper((unsigned char)buf[i]));
  if (strncmp(buf, "NLOPT_", 6) == 0) k = 6;
  {
    int a = (int)nlopt_algorithm_from_string(buf + k);
    for (i = 0; i < sizeof nl_accepted / sizeof nl_accepted[0]; i++)
      if (a >= 0 && a == (int)nl_accepted[i]) return a;
  }
  return -1;
}

static int nl_is_local(nlopt_algorithm a) {
  const char *s = nlopt_algorithm_to_string(a);
  return s[0] == 'L';
}
static int nl_is_mlsl(nlopt_algorithm a) { return a == NLOPT_G_MLSL_LDS || a == NLOPT_G_MLSL; }
static int nl_uses_grad(nlopt_algorithm a) {
  const char *s = nlopt_algorithm_to_string(a);
  return s[1] == 'D';
}

/* Parse "MAIN" or "MAIN+LOCAL"; local = -1 when absent. */
static rcb_status nl_parse(rcb_fit *f, nlopt_algorithm *main_alg, int *local) {
  const char *name = f->algorithm, *plus = strchr(name, '+');
  size_t n = plus ? (size_t)(plus - name) : strlen(name);
  int a = nl_lookup(name, n), b = -1;
  if (a < 0 && n == 0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "fit: no NLopt algorithm named (method nlopt:NAME); " NL_NAMES_HELP);
  if (a < 0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                         "fit: unknown NLopt algorithm \"%.*s\"; " NL_NAMES_HELP, (int)n, name);
  if (plus) {
    b = nl_lookup(plus + 1, strlen(plus + 1));
    if (b < 0 || !nl_is_local((nlopt_algorithm)b))
      return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                           "fit: \"%s\" after '+' in \"%s\" is not a local NLopt algorithm "
                           "(expected LN_/LD_ such as bobyqa or lbfgs); " NL_NAMES_HELP,
                           plus + 1, name);
    if (nl_is_local((nlopt_algorithm)a))
      return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                           "fit: \"%s\": a local algorithm takes no '+LOCAL' part "
                           "(expected GLOBAL+LOCAL with GLOBAL one of GN_DIRECT_L, GN_CRS2_LM, "
                           "GN_ISRES, G_MLSL_LDS, G_MLSL and LOCAL one of LN_BOBYQA, LN_SBPLX, "
                           "LN_COBYLA, LN_NELDERMEAD, LD_LBFGS, LD_MMA, LD_SLSQP)",
                           name);
  } else if (nl_is_mlsl((nlopt_algorithm)a)) {
    b = (int)NLOPT_LN_BOBYQA;
  }
  *main_alg = (nlopt_algorithm)a;
  *local = b;
  return RCB_OK;
}

/* State shared with the objective callback. */
typedef struct nl_ctx {
  rcb_fit *f;
  nlopt_opt opt;   /* the running optimiser, for nlopt_force_stop */
  double *xbest;   /* np */
  double fbest;    /* objective at xbest */
  int have_best;
  size_t calls;    /* objective calls, all stages */
  rcb_status st;   /* first error raised inside the objective */
  int stopped;     /* the progress callback asked to stop */
} nl_ctx;

static double nl_objective(unsigned n, const double *x, double *grad, void *data) {
  nl_ctx *c = (nl_ctx *)data;
  rcb_fit *f = c->f;
  double F = HUGE_VAL;
  rcb_status st;
  if (c->st != RCB_OK || c->stopped) {
    nlopt_force_stop(c->opt);
    return HUGE_VAL;
  }
  st = rcb_fit_objective(f, x, &F, grad);
  c->calls++;
  if (st != RCB_OK) {
    c->st = st;
    nlopt_force_stop(c->opt);
    return HUGE_VAL;
  }
  if (!isfinite(F)) return HUGE_VAL; /* a bad region, not an error */
  if (!c->have_best || F < c->fbest) {
    memcpy(c->xbest, x, n * sizeof *x);
    c->fbest = F;
    c->have_best = 1;
  }
  if (f->progress && f->progress(f->progress_user, c->calls, f->evaluations, F) != 0) {
    c->stopped = 1;
    nlopt_force_stop(c->opt);
  }
  return F;
}

/* Bounds in internal coordinates. */
static rcb_status nl_bounds(rcb_fit *f, int global, double *lb, double *ub) {
  size_t k;
  for (k = 0; k < f->np; k++) {
    const rcb_fit_par *p = &f->par[k];
    if (p->log_param) {
      lb[k] = p->lo > 0 ? log(p->lo) : -HUGE_VAL;
      ub[k] = p->hi > 0 ? log(p->hi) : -HUGE_VAL;
    } else {
      double s = p->scale > 0 ? p->scale : 1.0;
      lb[k] = p->lo / s;
      ub[k] = p->hi / s;
    }
    if (global && !(isfinite(lb[k]) && isfinite(ub[k])))
      return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                           "fit: global NLopt algorithm \"%s\" needs finite bounds, but "
                           "parameter %s has [%g, %g]; expected finite lo < hi (log "
                           "parameters: 0 < lo)",
                           f->algorithm, p->name, p->lo, p->hi);
  }
  return RCB_OK;
}

static size_t nl_budget(const rcb_fit *f, nlopt_algorithm a, int polished) {
  size_t it = f->max_iter > 0 ? f->max_iter : 100;
  if (!nl_is_local(a)) return (polished ? 2 : 10) * (f->np + 1) * it;
  return nl_uses_grad(a) ? 2 * it : (f->np + 1) * it;
}

/* Create an optimiser with bounds, tolerances and budget; NULL on no memory. */
static nlopt_opt nl_make(const rcb_fit *f, nlopt_algorithm a, const double *lb, const double *ub,
                         int tolerances, int polished) {
  nlopt_opt o = nlopt_create(a, (unsigned)f->np);
  if (!o) return NULL;
  nlopt_set_lower_bounds(o, lb);
  nlopt_set_upper_bounds(o, ub);
  if (tolerances) {
    if (f->ftol_rel > 0) nlopt_set_ftol_rel(o, f->ftol_rel);
    if (f->xtol_rel > 0) nlopt_set_xtol_rel(o, f->xtol_rel);
  }
  nlopt_set_maxeval(o, (int)nl_budget(f, a, polished));
  return o;
}

/* Map an NLopt result to a status; sets the message for failures. */
static rcb_status nl_result(rcb_fit *f, const nl_ctx *c, nlopt_result res, nlopt_algorithm a) {
  const char *an = nlopt_algorithm_to_string(a), *rn = nlopt_result_to_string(res);
  if (c->st != RCB_OK) return c->st; /* the objective's own message stands */
  if (c->stopped)
    return rcb_set_error(f->errmsg, RCB_ERR_STATE,
                         "fit: stopped by the caller (progress callback) after %zu objective "
                         "calls; best point kept",
                         c->calls);
  /* ROUNDOFF_LIMITED: NLopt's docs say the point is usually still useful
   * (LBFGS reports it on zero-residual data at the optimum): success, but
   * not "converged". */
  if (res > 0 || res == NLOPT_ROUNDOFF_LIMITED) return RCB_OK;
  /* LBFGS and MMA report a bare FAILURE when their line search cannot make
   * progress at a minimum of noisy data; after some progress that is the same
   * outcome as ROUNDOFF_LIMITED (the best point is kept, not "converged"). */
  if (res == NLOPT_FAILURE && c->calls > 1 && (int)a >= 0 &&
      strncmp(an ? an : "", "LD_", 3) == 0)
    return RCB_OK;
  switch (res) {
    case NLOPT_INVALID_ARGS:
      return rcb_set_error(f->errmsg, RCB_ERR_ARG, "fit: NLopt %s returned %s (%s)", an, rn,
                           c->opt && nlopt_get_errmsg(c->opt) ? nlopt_get_errmsg(c->opt)
                                                             : "invalid arguments");
    case NLOPT_OUT_OF_MEMORY:
      return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "fit: NLopt %s returned %s", an, rn);
    default:
      return rcb_set_error(f->errmsg, RCB_ERR_STATE,
                           "fit: NLopt %s failed with %s%s%s after %zu objective calls; the "
                           "best point found is kept in the model",
                           an, rn, c->opt && nlopt_get_errmsg(c->opt) ? ": " : "",
                           c->opt && nlopt_get_errmsg(c->opt) ? nlopt_get_errmsg(c->opt) : "",
                           c->calls);
  }
}

/* One optimiser run from x (in/out); returns the NLopt result. */
static nlopt_result nl_optimize(nl_ctx *c, nlopt_opt o, double *x) {
  double fx = HUGE_VAL;
  nlopt_result res;
  c->opt = o;
  nlopt_set_min_objective(o, nl_objective, c);
  res = nlopt_optimize(o, x, &fx);
  return res;
}

static int nl_converged(nlopt_result res) {
  return res > 0 && res != NLOPT_MAXEVAL_REACHED && res != NLOPT_MAXTIME_REACHED;
}

static rcb_status nl_run(rcb_fit *f, double *work) {
  size_t np = f->np, k;
  double *x = work, *lb = work + np, *ub = work + 2 * np;
  nl_ctx c;
  nlopt_algorithm a = NLOPT_LN_BOBYQA;
  nlopt_opt o = NULL, lo = NULL;
  nlopt_result res;
  int local = -1, global, polish;
  rcb_status st = nl_parse(f, &a, &local), st2;
  if (st != RCB_OK) return st;
  global = !nl_is_local(a);
  polish = global && !nl_is_mlsl(a) && local >= 0;
  if ((st = nl_bounds(f, global, lb, ub)) != RCB_OK) return st;
  memset(&c, 0, sizeof c);
  c.f = f;
  c.xbest = work + 3 * np;
  c.fbest = HUGE_VAL;
  rcb_fit_get_x(f, x);
  /* rcb_fit_run has evaluated the start (f->obj0): it is the first
   * candidate, so a global method that never samples it (DIRECT starts at
   * the centre of the box) cannot leave the model worse than it found it */
  c.have_best = f->evaluations > 0 && isfinite(f->obj0);
  for (k = 0; k < np; k++) { /* NLopt rejects a start outside the bounds */
    double xk = x[k] < lb[k] ? lb[k] : x[k] > ub[k] ? ub[k] : x[k];
    if (xk != x[k]) c.have_best = 0;
    x[k] = xk;
  }
  if (c.have_best) {
    memcpy(c.xbest, x, np * sizeof *x);
    c.fbest = f->obj0;
  }
  o = nl_make(f, a, lb, ub, !global, polish);
  if (!o) return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "fit: nlopt_create failed (no memory)");
  if (nl_is_mlsl(a)) {
    lo = nl_make(f, (nlopt_algorithm)local, lb, ub, 1, 0);
    if (!lo || nlopt_set_local_optimizer(o, lo) != NLOPT_SUCCESS) {
      nlopt_destroy(lo);
      nlopt_destroy(o);
      return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "fit: NLopt local optimiser set-up failed");
    }
    nlopt_destroy(lo); /* o keeps its own copy */
    lo = NULL;
  }
  res = nl_optimize(&c, o, x);
  st = nl_result(f, &c, res, a);
  f->converged = nl_converged(res);
  f->stalled = res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_FAILURE;
  nlopt_destroy(o);
  c.opt = NULL;

  if (st == RCB_OK && polish && c.have_best) {
    memcpy(x, c.xbest, np * sizeof *x);
    o = nl_make(f, (nlopt_algorithm)local, lb, ub, 1, 0);
    if (!o) return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "fit: nlopt_create failed (no memory)");
    res = nl_optimize(&c, o, x);
    st = nl_result(f, &c, res, (nlopt_algorithm)local);
    f->converged = nl_converged(res);
    f->stalled = res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_FAILURE;
    nlopt_destroy(o);
    c.opt = NULL;
  }

  f->iterations = c.calls;
  if (c.have_best) {
    /* leave the model at the best point seen, keeping any earlier message */
    char msg[RCB_ERRMSG_MAX];
    memcpy(msg, f->errmsg, sizeof msg);
    st2 = rcb_fit_set_x(f, c.xbest);
    if (st2 != RCB_OK && st == RCB_OK) return st2;
    memcpy(f->errmsg, msg, sizeof msg);
    f->obj = c.fbest;
  }
  if (st != RCB_OK) f->converged = 0;
  return st;
}

rcb_status rcb_fit_run_nlopt(rcb_fit *f) {
  double *work;
  rcb_status st;
  if (f->np == 0)
    return rcb_set_error(f->errmsg, RCB_ERR_STATE,
                         "fit: no parameters to fit; add some with rcb_fit_add_param");
  work = (double *)rcb_alloc(&f->alloc, 4 * f->np * sizeof *work);
  if (!work) return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "fit: out of memory (NLopt work)");
  st = nl_run(f, work);
  rcb_free(&f->alloc, work);
  return st;
}

#else /* !RCB_WITH_NLOPT */

rcb_status rcb_fit_run_nlopt(rcb_fit *f) {
  return rcb_set_error(f->errmsg, RCB_ERR_UNSUPPORTED,
                       "this librcb was built without NLopt (RCB_WITH_NLOPT=OFF); use the "
                       "paper method");
}

#endif
