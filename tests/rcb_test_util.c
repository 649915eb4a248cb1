#include "rcb_test_util.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

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
