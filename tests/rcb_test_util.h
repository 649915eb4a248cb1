/* Shared helpers for the cmocka tests. */
#ifndef RCB_TEST_UTIL_H
#define RCB_TEST_UTIL_H
#include <stddef.h>

#include "rcb/rcb.h"

/* |a - b| <= rtol * max(|a|, |b|) + atol */
int rcb_test_close(double a, double b, double rtol, double atol);
/* Build a model from INI text or abort the test with the model's message. */
rcb_model *rcb_test_model_from_string(const char *ini);
/* Load examples/<name> or abort. */
rcb_model *rcb_test_model_from_example(const char *name);
/* examples/<name> with the lines `extra` put right after the line `after`
 * (e.g. "[bearing B2]"), loaded, or abort. */
rcb_model *rcb_test_model_edited(const char *name, const char *after, const char *extra);
/* Allocation counts seen through rcb_test_counting_allocator's hooks. */
typedef struct rcb_test_counter {
  size_t allocs, frees;
} rcb_test_counter;
/* Allocator hooks (malloc/free) that count every call into *c. */
rcb_allocator rcb_test_counting_allocator(rcb_test_counter *c);
/* An allocator whose fail_at-th allocation fails (1-based; 0 = never), for the
 * allocation-failure walks; it counts what it hands out and takes back. */
typedef struct rcb_test_failing {
  size_t fail_at; /* 1-based index of the allocation that fails, 0 = never */
  size_t allocs;  /* allocation calls so far (the failing one included) */
  size_t frees;   /* free calls on pointers it handed out */
  size_t live;    /* allocated and not yet freed */
  int hit;        /* the failing allocation was reached */
  struct rcb_test_walk *walk; /* when set: each allocation from walk->from forks */
} rcb_test_failing;
/* Allocator hooks over *f (which must outlive every object made with them). */
rcb_allocator rcb_test_failing_allocator(rcb_test_failing *f);

/* The allocation-failure walk by fork (issue #27). One run of a scenario with
 * f->walk set: at each allocation k >= from the process forks; the child
 * fails allocation k and goes on from there to the scenario's end, where
 * rcb_test_walk_child_end checks it and exits; the parent waits for it, then
 * allocates and goes on. Every allocation fails in turn at the cost of about
 * one run, where a run per allocation re-ran everything before it (the
 * diagnosis's ~4800 allocations: 8 minutes). The first child that fails
 * stops the forking. In a child, a cmocka assertion aborts it
 * (CMOCKA_TEST_ABORT), so the parent sees it. */
typedef struct rcb_test_walk {
  size_t from;      /* the first allocation failed (1-based) */
  size_t stride;    /* then every stride-th (0 or 1: every one) */
  size_t forks;     /* children run */
  size_t failed_at; /* the allocation whose child failed; 0: none */
  int status;       /* that child's wait status */
  int in_child;     /* this process is a child: its allocation fail_at failed */
} rcb_test_walk;
/* The stride of the walks: RCB_ALLOC_WALK_STRIDE, else 1. The sanitizer
 * stage of ./scripts/dev.sh test sets it: a fork there copies ASan's shadow
 * mappings (about 10 ms of system time each, against 0.4 ms without). */
size_t rcb_test_walk_stride(void);
/* In a child (w->in_child): exits 0 when the scenario ended in an error
 * (status st < 0, message non-empty: msg_ok) with nothing of f's live, else
 * prints why and exits 1. In the parent: returns. */
void rcb_test_walk_child_end(const rcb_test_failing *f, const char *name, rcb_status st,
                             int msg_ok);
/* Noise-free FRFs of m (the given kind) at outs x ins, n points evenly on
 * [f0, f1] Hz at rpm, as a measurement (aborts the test on failure). */
rcb_meas *rcb_test_frf_meas(const rcb_model *m, const char *const *outs, size_t no,
                            const char *const *ins, size_t ni, double f0, double f1, size_t n,
                            double rpm, rcb_frf_kind kind);
/* A copy of ms, channel c's data multiplied by fac[c] (0: channel left
 * out), and its response renamed to rename[c] when rename is not NULL: a
 * probe's gain, a sign flipped, two probes swapped (aborts the test on
 * failure). */
rcb_meas *rcb_test_meas_copy(const rcb_meas *ms, const _Complex double *fac,
                             const char *const *rename);
/* Noise-free unbalance responses of m at channels outs (no of them), n speeds
 * evenly from r0 to r1 rpm, as a measurement (aborts the test on failure). */
rcb_meas *rcb_test_unbalance_meas(const rcb_model *m, const char *const *outs, size_t no,
                                  double r0, double r1, size_t n);
/* A scratch folder for a test group: cmocka group setup/teardown create
 * /tmp/rcb_test_XXXXXX and remove it with its contents. */
int rcb_test_setup_tmpdir(void **state);
int rcb_test_teardown_tmpdir(void **state);
const char *rcb_test_tmpdir(void);
/* FOLDER/name in the scratch folder (4 rotating buffers: use it at once). */
const char *rcb_test_tmp_path(const char *name);
#endif
