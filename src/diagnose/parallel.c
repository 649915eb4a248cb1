/*
 * Jobs of a diagnosis across candidates (pre-fits, refits), serial or on
 * POSIX threads (RCB_WITH_THREADS; built without them, every job runs on the
 * calling thread), with results that do not depend on the number of threads
 * (bit for bit):
 *  - a job reads the diagnosis' settings, base and nominal models and the
 *    measurement, which no job changes, and writes only into its own
 *    candidate: each builds its candidate's model (a clone with its own
 *    memory), its fits and their workspaces, so it runs the same code on
 *    the same numbers on whichever thread takes it;
 *  - each thread works on a shallow copy of the diagnosis object (the same
 *    idea as the threaded sweep, src/analyses/sweep.c): its own error
 *    message and work counters, merged in job order at the end;
 *  - the first failing job in job order decides the status and message,
 *    as in a serial run.
 * Threads call the allocator hooks concurrently: hooks given to
 * rcb_diag_create must then be thread-safe (malloc is).
 */
#include <string.h>

#include "diagnose/diag_internal.h"
#include "rcb/rcb_config.h"

#if RCB_WITH_THREADS
#include <pthread.h>

typedef struct diag_pool {
  rcb_diag *d;
  size_t n, next;
  rcb_diag_job job;
  void *ctx;
  rcb_status *st; /* per job */
  pthread_mutex_t lock;
} diag_pool;

typedef struct diag_worker {
  diag_pool *pool;
  rcb_diag wk;    /* shallow copy: own errmsg and counters */
  size_t failed;  /* the first job this worker saw fail (pool->n: none) */
  char msg[RCB_ERRMSG_MAX];
} diag_worker;

static size_t take(diag_pool *p) {
  size_t i;
  pthread_mutex_lock(&p->lock);
  i = p->next < p->n ? p->next++ : p->n;
  pthread_mutex_unlock(&p->lock);
  return i;
}

static void *worker_main(void *arg) {
  diag_worker *w = arg;
  diag_pool *p = w->pool;
  size_t i;
  /* jobs are taken in rising order, so a worker's first failure is the
   * lowest failing job it ran */
  while ((i = take(p)) < p->n) {
    p->st[i] = p->job(&w->wk, i, p->ctx);
    if (p->st[i] && w->failed == p->n) {
      w->failed = i;
      memcpy(w->msg, w->wk.errmsg, sizeof w->msg);
    }
  }
  return NULL;
}

static rcb_status run_threads(rcb_diag *d, size_t n, rcb_diag_job job, void *ctx,
                              rcb_diag_after after) {
  diag_worker w[RCB_DIAG_MAX_THREADS];
  pthread_t tid[RCB_DIAG_MAX_THREADS];
  diag_pool p;
  size_t nt = d->nthreads < n ? d->nthreads : n, t, started = 1, i, first = n;
  rcb_status st = RCB_OK;
  memset(&p, 0, sizeof p);
  p.d = d, p.n = n, p.job = job, p.ctx = ctx;
  if (!(p.st = rcb_alloc(&d->alloc, n * sizeof *p.st)))
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "out of memory");
  if (pthread_mutex_init(&p.lock, NULL)) {
    rcb_free(&d->alloc, p.st);
    return rcb_diag_fail(d, RCB_ERR_NOMEM, "could not create a mutex");
  }
  for (t = 0; t < nt; t++) {
    w[t].pool = &p;
    w[t].wk = *d;
    memset(&w[t].wk.stats, 0, sizeof w[t].wk.stats);
    w[t].failed = n;
    w[t].msg[0] = '\0';
  }
  for (t = 1; t < nt; t++, started++)
    if (pthread_create(&tid[t], NULL, worker_main, &w[t])) break;
  worker_main(&w[0]); /* the calling thread works too; the others take what is left */
  for (t = 1; t < started; t++) pthread_join(tid[t], NULL);
  pthread_mutex_destroy(&p.lock);
  for (t = 0; t < started; t++) {
    d->stats.evaluations += w[t].wk.stats.evaluations;
    d->stats.refits += w[t].wk.stats.refits;
    d->stats.restarts += w[t].wk.stats.restarts;
    if (w[t].failed < first) {
      first = w[t].failed;
      memcpy(d->errmsg, w[t].msg, sizeof d->errmsg);
    }
  }
  if (first < n) st = p.st[first];
  for (i = 0; !st && after && i < n; i++) st = after(d, i, ctx);
  rcb_free(&d->alloc, p.st);
  return st;
}
#endif

rcb_status rcb_diag_for_each(rcb_diag *d, size_t n, rcb_diag_job job, void *ctx,
                             rcb_diag_after after) {
  rcb_status st = RCB_OK;
  size_t i;
#if RCB_WITH_THREADS
  if (d->nthreads > 1 && n > 1) return run_threads(d, n, job, ctx, after);
#endif
  for (i = 0; !st && i < n; i++) {
    st = job(d, i, ctx);
    if (!st && after) st = after(d, i, ctx);
  }
  return st;
}
