/*
 * Frequency sweep, serial or on POSIX threads (RCB_WITH_THREADS; built
 * without them, every sweep runs on the calling thread), with results that
 * do not depend on the number of threads (bit for bit):
 *  - every frequency runs the same code on a workspace of its own thread;
 *    the dense and banded solvers keep no state between frequencies;
 *  - the sparse solver (KLU) refactors with the pivots of an earlier
 *    frequency, so its result depends on the history: the sweep is cut into
 *    blocks of RCB_SWEEP_BLOCK frequencies, each starting from a fresh
 *    symbolic + numeric factorisation, and threads take whole blocks;
 *  - the modal solver at one speed computes the basis once (on the caller's
 *    object) and the threads only read it.
 * A thread's workspace is a shallow copy of the caller's object: the
 * structural matrices, DOF rows and sparsity pattern are shared read-only,
 * the dynamic stiffness, right-hand sides, pivots, condition work, solver
 * state and modal basis are its own.
 */
#include <math.h>
#include <string.h>

#include "analyses/frf_internal.h"
#include "rcb/rcb_config.h"

#if RCB_WITH_THREADS
#include <pthread.h>
#endif

typedef struct sweep_part {
  rcb_frf *f;                         /* workspace of this part */
  const struct rcb_frf_modal *shared; /* modal basis shared read-only, or NULL */
  const double *omegas, *speeds;      /* rad/s */
  rcb_frf_kind kind;
  rcb_complex *H;
  size_t p0, p1, nch; /* frequencies [p0, p1), entries per frequency */
  rcb_status st;
} sweep_part;

rcb_status rcb_frf_solver_reset(rcb_frf *f) {
  rcb_status st;
  if (!f->L.sparse) return RCB_OK;
  f->factored = 0;
  f->ops->release(&f->L, &f->alloc);
  if ((st = f->ops->prepare(&f->L, &f->alloc)))
    return rcb_set_error(f->errmsg, st, "%s solver: symbolic analysis failed", f->ops->name);
  return RCB_OK;
}

static void run_part(sweep_part *s) {
  size_t p;
  s->st = RCB_OK;
  for (p = s->p0; p < s->p1; p++) {
    rcb_complex *H = s->H + p * s->nch;
    if (s->shared) {
      rcb_frf_modal_sum(s->shared, s->omegas[p], s->kind, H);
      continue;
    }
    if (p % RCB_SWEEP_BLOCK == 0 && (s->st = rcb_frf_solver_reset(s->f))) return;
    if ((s->st = rcb_frf_eval(s->f, s->omegas[p], s->speeds[p], s->kind, H))) return;
  }
}

#if RCB_WITH_THREADS
static void *part_main(void *arg) {
  run_part(arg);
  return NULL;
}
#endif

static void worker_destroy(rcb_frf *w) {
  if (!w) return;
  rcb_frf_modal_destroy(w);
  if (w->ops && w->ops->release) w->ops->release(&w->L, &w->alloc);
  rcb_frf_cond_free(w);
  rcb_free(&w->alloc, w->Z);
  rcb_free(&w->alloc, w->B);
  rcb_free(&w->alloc, w->ipiv);
  rcb_free(&w->alloc, w);
}

/* A thread's workspace: see the file comment for what is shared. */
static rcb_status worker_create(rcb_frf *f, rcb_frf **out) {
  size_t n = f->m->ndof, sz = rcb_layout_size(&f->L);
  rcb_frf *w = rcb_alloc(&f->alloc, sizeof *w);
  rcb_status st;
  *out = NULL;
  if (!w) return rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "sweep: out of memory (workspace)");
  *w = *f;
  w->modal = NULL;
  w->L.solver = NULL;
  w->cond_work = NULL;
  w->cond_rwork = NULL;
  w->Z = rcb_alloc(&w->alloc, sz * sizeof *w->Z);
  w->B = rcb_alloc(&w->alloc, n * (f->nin ? f->nin : 1) * sizeof *w->B);
  w->ipiv = rcb_alloc(&w->alloc, n * sizeof *w->ipiv);
  if (!w->Z || !w->B || !w->ipiv) st = RCB_ERR_NOMEM;
  else if ((st = rcb_frf_cond_setup(w)) == RCB_OK) {
    w->cond_on = f->cond_on;
    w->cond = f->cond;
    w->cond.checked = w->cond.estimated = w->cond.ill = 0;
    if (w->L.sparse) st = w->ops->prepare(&w->L, &w->alloc);
    if (!st && f->modal) st = rcb_frf_modal_create(w, f->modal);
  }
  if (st) {
    rcb_set_error(f->errmsg, st, "sweep: thread workspace: %s",
                  w->errmsg[0] ? w->errmsg : rcb_status_str(st));
    worker_destroy(w);
    return st;
  }
  *out = w;
  return RCB_OK;
}

#if RCB_WITH_THREADS
/* The worst condition estimate of a thread's solves joins the caller's
 * record (rcb_frf_get_condition), as if the solves had been its own. */
static void merge_condition(rcb_frf_condition *dst, const rcb_frf_condition *src) {
  dst->checked += src->checked;
  if (!src->estimated) return;
  if (!dst->estimated ||
      (!isnan(dst->rcond_min) && (isnan(src->rcond_min) || src->rcond_min < dst->rcond_min))) {
    dst->rcond_min = src->rcond_min;
    dst->omega = src->omega;
    dst->speed = src->speed;
  }
  dst->estimated += src->estimated;
  dst->ill += src->ill;
  dst->rcond_last = src->rcond_last;
}
#endif

static rcb_status check_grid(rcb_frf *f, size_t nfreq, const double *omegas,
                             const double *speeds, int *one_speed) {
  size_t p;
  *one_speed = 1;
  if (f->nin == 0)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG, "no input DOF: created for unbalance only");
  for (p = 0; p < nfreq; p++) {
    if (!isfinite(omegas[p]) || !isfinite(speeds[p]) || omegas[p] < 0)
      return rcb_set_error(f->errmsg, RCB_ERR_ARG,
                           "sweep point %zu: frequency %g rad/s, speed %g rad/s: expected "
                           "finite, omega >= 0", p, omegas[p], speeds[p]);
    if (speeds[p] != speeds[0]) *one_speed = 0;
  }
  return RCB_OK;
}

#if RCB_WITH_THREADS
/* Threads over whole blocks; part 0 runs on the calling thread. */
static rcb_status run_threads(rcb_frf *f, sweep_part *parts, size_t nt, rcb_frf **workers) {
  pthread_t tid[RCB_SWEEP_MAX_THREADS];
  size_t t, started = 1;
  rcb_status st = RCB_OK;
  for (t = 1; t < nt; t++) {
    if (pthread_create(&tid[t], NULL, part_main, &parts[t])) break;
    started++;
  }
  if (started < nt) {
    st = rcb_set_error(f->errmsg, RCB_ERR_NOMEM, "sweep: could not start thread %zu", started);
    parts[0].p1 = parts[0].p0; /* nothing more to do: join and report */
  }
  run_part(&parts[0]);
  for (t = 1; t < started; t++) pthread_join(tid[t], NULL);
  for (t = 0; t < nt && !st; t++)
    if (parts[t].st) {
      st = parts[t].st;
      if (workers[t] != f) memcpy(f->errmsg, workers[t]->errmsg, sizeof f->errmsg);
    }
  for (t = 1; t < nt; t++)
    if (workers[t] != f) merge_condition(&f->cond, &workers[t]->cond);
  return st;
}
#else
/* Built without threads: rcb_frf_sweep makes one part, run here. */
static rcb_status run_threads(rcb_frf *f, sweep_part *parts, size_t nt, rcb_frf **workers) {
  (void)f, (void)nt, (void)workers;
  run_part(&parts[0]);
  return parts[0].st;
}
#endif

rcb_status rcb_frf_sweep(rcb_frf *f, size_t nfreq, const double *omegas, const double *speeds,
                         rcb_frf_kind kind, rcb_complex *H, size_t nthreads) {
  sweep_part parts[RCB_SWEEP_MAX_THREADS];
  rcb_frf *workers[RCB_SWEEP_MAX_THREADS];
  size_t t, nt, nblocks = (nfreq + RCB_SWEEP_BLOCK - 1) / RCB_SWEEP_BLOCK;
  int one_speed;
  rcb_status st;
  if (!f) return RCB_ERR_ARG;
  if (nfreq && (!omegas || !speeds || !H)) return RCB_ERR_ARG;
  if (nthreads > RCB_SWEEP_MAX_THREADS)
    return rcb_set_error(f->errmsg, RCB_ERR_ARG, "sweep: %zu threads: at most %d", nthreads,
                         RCB_SWEEP_MAX_THREADS);
  if ((st = check_grid(f, nfreq, omegas, speeds, &one_speed))) return st;
  if (nfreq == 0) return RCB_OK; /* nothing to evaluate (and no part to run) */
  memset(workers, 0, sizeof workers);
  nt = nthreads < 1 || !RCB_WITH_THREADS ? 1 : nthreads;
  if (nt > nblocks) nt = nblocks ? nblocks : 1;
  if (f->modal && one_speed && nfreq && (st = rcb_frf_modal_basis(f, speeds[0]))) return st;
  for (t = 0; t < nt; t++) {
    sweep_part *s = &parts[t];
    memset(s, 0, sizeof *s);
    s->f = f;
    s->shared = f->modal && one_speed ? f->modal : NULL;
    s->omegas = omegas, s->speeds = speeds, s->kind = kind, s->H = H;
    s->nch = f->nout * f->nin;
    s->p0 = nblocks * t / nt * RCB_SWEEP_BLOCK;
    s->p1 = nblocks * (t + 1) / nt * RCB_SWEEP_BLOCK;
    if (s->p1 > nfreq) s->p1 = nfreq;
    workers[t] = f;
    if (t > 0 && !s->shared && (st = worker_create(f, &workers[t]))) break;
    s->f = workers[t];
  }
  if (!st) st = run_threads(f, parts, nt, workers);
  for (t = 1; t < nt; t++)
    if (workers[t] && workers[t] != f) worker_destroy(workers[t]);
  return st;
}
