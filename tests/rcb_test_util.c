#define _POSIX_C_SOURCE 200809L /* mkdtemp, fork, setenv */
#include "rcb_test_util.h"

#include <complex.h>
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#define TEST_PI 3.14159265358979323846

int rcb_test_close(double a, double b, double rtol, double atol) {
  double s = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
  return fabs(a - b) <= rtol * s + atol;
}

rcb_model *rcb_test_model_from_string(const char *ini) {
  rcb_model *m = NULL;
  rcb_status st;
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  st = rcb_model_load_string(m, ini, "<test>");
  if (st != RCB_OK) fail_msg("model load failed: %s", rcb_model_errmsg(m));
  return m;
}

rcb_model *rcb_test_model_from_example(const char *name) {
  char path[1024];
  rcb_model *m = NULL;
  rcb_status st;
  snprintf(path, sizeof path, "%s/%s", RCB_EXAMPLES_DIR, name);
  assert_int_equal(rcb_model_create(&m, NULL), RCB_OK);
  st = rcb_model_load_file(m, path);
  if (st != RCB_OK) fail_msg("model load failed: %s", rcb_model_errmsg(m));
  return m;
}

rcb_model *rcb_test_model_edited(const char *name, const char *after, const char *extra) {
  char path[1024], *txt, *out;
  const char *at;
  FILE *fp;
  long len;
  size_t pre;
  rcb_model *m;
  snprintf(path, sizeof path, "%s/%s", RCB_EXAMPLES_DIR, name);
  fp = fopen(path, "rb");
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  len = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  assert_true(len > 0);
  txt = calloc((size_t)len + 1, 1);
  out = calloc((size_t)len + strlen(extra) + 4, 1);
  assert_int_equal(fread(txt, 1, (size_t)len, fp), (size_t)len);
  fclose(fp);
  at = strstr(txt, after);
  if (!at || !(at = strchr(at, '\n'))) fail_msg("%s: no line '%s'", name, after);
  pre = (size_t)(at + 1 - txt);
  memcpy(out, txt, pre);
  snprintf(out + pre, strlen(extra) + 2, "%s\n", extra);
  strcat(out, txt + pre);
  m = rcb_test_model_from_string(out);
  free(txt);
  free(out);
  return m;
}

static void *count_alloc(void *user, size_t size) {
  ((rcb_test_counter *)user)->allocs++;
  return malloc(size);
}

static void count_free(void *user, void *p) {
  ((rcb_test_counter *)user)->frees++;
  free(p);
}

rcb_allocator rcb_test_counting_allocator(rcb_test_counter *c) {
  rcb_allocator a;
  a.alloc = count_alloc;
  a.free = count_free;
  a.user = c;
  return a;
}

/* Fork at allocation f->allocs: returns 1 in the child (its allocation
 * fails), 0 in the parent once the child has ended. */
static int walk_fork(rcb_test_failing *f) {
  rcb_test_walk *w = f->walk;
  int ws = 0;
  pid_t pid;
  fflush(NULL); /* nothing buffered is written twice */
  pid = fork();
  if (pid < 0) {
    perror("rcb_test walk: fork");
    abort();
  }
  if (pid == 0) {
    struct rlimit none = {0, 0};
    setrlimit(RLIMIT_CORE, &none);        /* an abort dumps no core */
    setenv("CMOCKA_TEST_ABORT", "1", 1); /* an assertion ends the child */
    w->in_child = 1;
    return 1;
  }
  while (waitpid(pid, &ws, 0) < 0)
    if (errno != EINTR) {
      perror("rcb_test walk: waitpid");
      abort();
    }
  w->forks++;
  if (!WIFEXITED(ws) || WEXITSTATUS(ws) != 0) w->failed_at = f->allocs, w->status = ws;
  return 0;
}

size_t rcb_test_walk_stride(void) {
  const char *s = getenv("RCB_ALLOC_WALK_STRIDE");
  long v = s ? strtol(s, NULL, 10) : 1;
  return v > 1 ? (size_t)v : 1;
}

void rcb_test_walk_child_end(const rcb_test_failing *f, const char *name, rcb_status st,
                             int msg_ok) {
  const char *why = NULL;
  if (!f->walk || !f->walk->in_child) return;
  if (f->live != 0) why = "blocks leaked";
  else if (st == RCB_OK) why = "the run returned RCB_OK";
  else if (st > 0) why = "a status that is not an error";
  else if (!msg_ok) why = "no error message";
  if (why)
    fprintf(stderr, "%s: allocation %zu failing: %s (status %s, %zu blocks live)\n", name,
            f->fail_at, why, rcb_status_str(st), f->live);
  fflush(NULL);
  _exit(why ? 1 : 0);
}

static void *failing_alloc(void *user, size_t size) {
  rcb_test_failing *f = user;
  f->allocs++;
  if (f->walk && !f->walk->in_child && !f->walk->failed_at && f->allocs >= f->walk->from &&
      (f->walk->stride < 2 || (f->allocs - f->walk->from) % f->walk->stride == 0) &&
      walk_fork(f))
    f->fail_at = f->allocs;
  if (f->fail_at && f->allocs == f->fail_at) {
    f->hit = 1;
    return NULL;
  }
  f->live++;
  return malloc(size);
}

static void failing_free(void *user, void *p) {
  rcb_test_failing *f = user;
  if (!p) return;
  f->frees++;
  f->live--;
  free(p);
}

rcb_allocator rcb_test_failing_allocator(rcb_test_failing *f) {
  rcb_allocator a;
  a.alloc = failing_alloc;
  a.free = failing_free;
  a.user = f;
  return a;
}

/* Synthetic FRF measurement of model m: channels outs x ins, n points on
 * [f0, f1] Hz at speed rpm, as the given kind. */
rcb_meas *rcb_test_frf_meas(const rcb_model *m, const char *const *outs, size_t no,
                            const char *const *ins, size_t ni, double f0, double f1, size_t n,
                            double rpm, rcb_frf_kind kind) {
  rcb_meas *ms = NULL;
  rcb_frf *fr = NULL;
  rcb_dof od[8], id[8];
  double *x = calloc(n, sizeof *x);
  rcb_complex *H = calloc(n * no * ni, sizeof *H), *col = calloc(n, sizeof *col);
  size_t i, o, q;
  for (o = 0; o < no; o++) assert_int_equal(rcb_model_find_dof(m, outs[o], &od[o]), RCB_OK);
  for (q = 0; q < ni; q++) assert_int_equal(rcb_model_find_dof(m, ins[q], &id[q]), RCB_OK);
  assert_int_equal(rcb_frf_create(&fr, m, no, od, ni, id, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < n; i++) {
    x[i] = 2.0 * TEST_PI * (f0 + (f1 - f0) * (double)i / (double)(n - 1));
    assert_int_equal(rcb_frf_eval(fr, x[i], rpm * (TEST_PI / 30.0), kind, H + i * no * ni), RCB_OK);
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_FRF, n, x, rpm * (TEST_PI / 30.0)), RCB_OK);
  for (q = 0; q < ni; q++)
    for (o = 0; o < no; o++) {
      for (i = 0; i < n; i++) col[i] = H[i * no * ni + o + no * q];
      assert_int_equal(rcb_meas_add_channel(ms, outs[o], ins[q], kind, col), RCB_OK);
    }
  rcb_frf_destroy(fr);
  free(x);
  free(H);
  free(col);
  return ms;
}

/* Noise-free unbalance responses of m at outs over r0..r1 rpm, n speeds. */
rcb_meas *rcb_test_unbalance_meas(const rcb_model *m, const char *const *outs, size_t no,
                                  double r0, double r1, size_t n) {
  rcb_meas *ms = NULL;
  rcb_frf *fr = NULL;
  rcb_dof od[8] = {{0}};
  double *x = calloc(n, sizeof *x);
  rcb_complex *Q = calloc(n * no, sizeof *Q), *col = calloc(n, sizeof *col);
  size_t i, o;
  for (o = 0; o < no; o++) assert_int_equal(rcb_model_find_dof(m, outs[o], &od[o]), RCB_OK);
  assert_int_equal(rcb_frf_create(&fr, m, no, od, 0, NULL, RCB_SOLVER_AUTO, NULL), RCB_OK);
  for (i = 0; i < n; i++) {
    x[i] = (TEST_PI / 30.0) * (r0 + (r1 - r0) * (double)i / (double)(n - 1));
    assert_int_equal(rcb_frf_unbalance(fr, x[i], Q + i * no), RCB_OK);
  }
  assert_int_equal(rcb_meas_create(&ms, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(ms, RCB_MEAS_UNBALANCE, n, x, 0.0), RCB_OK);
  for (o = 0; o < no; o++) {
    for (i = 0; i < n; i++) col[i] = Q[i * no + o];
    assert_int_equal(rcb_meas_add_channel(ms, outs[o], NULL, RCB_RECEPTANCE, col), RCB_OK);
  }
  rcb_frf_destroy(fr);
  free(x);
  free(Q);
  free(col);
  return ms;
}

static char tmpdir_[256];

int rcb_test_setup_tmpdir(void **state) {
  (void)state;
  snprintf(tmpdir_, sizeof tmpdir_, "/tmp/rcb_test_XXXXXX");
  return mkdtemp(tmpdir_) ? 0 : -1;
}

int rcb_test_teardown_tmpdir(void **state) {
  char cmd[300];
  (void)state;
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir_);
  return system(cmd) == 0 ? 0 : -1;
}

const char *rcb_test_tmpdir(void) { return tmpdir_; }

const char *rcb_test_tmp_path(const char *name) {
  static char buf[4][512];
  static int k;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir_, name);
  return buf[k];
}

/* (rcb_test_util.h) */
rcb_meas *rcb_test_meas_copy(const rcb_meas *ms, const double complex *fac,
                             const char *const *rename) {
  rcb_meas *out = NULL;
  size_t n = rcb_meas_point_count(ms), c, i;
  rcb_complex *col = calloc(n, sizeof *col);
  assert_non_null(col);
  assert_int_equal(rcb_meas_create(&out, NULL), RCB_OK);
  assert_int_equal(rcb_meas_set_grid(out, rcb_meas_get_type(ms), n, rcb_meas_grid(ms),
                                     rcb_meas_speed(ms)),
                   RCB_OK);
  for (c = 0; c < rcb_meas_channel_count(ms); c++) {
    rcb_meas_channel_info ci;
    assert_int_equal(rcb_meas_channel(ms, c, &ci), RCB_OK);
    if (fac[c] == 0.0) continue;
    for (i = 0; i < n; i++) col[i] = fac[c] * ci.data[i];
    assert_int_equal(rcb_meas_add_channel(out, rename ? rename[c] : ci.response, ci.reference,
                                          ci.kind, col),
                     RCB_OK);
  }
  free(col);
  return out;
}
