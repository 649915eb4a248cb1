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
/* Allocation counts seen through rcb_test_counting_allocator's hooks. */
typedef struct rcb_test_counter {
  size_t allocs, frees;
} rcb_test_counter;
/* Allocator hooks (malloc/free) that count every call into *c. */
rcb_allocator rcb_test_counting_allocator(rcb_test_counter *c);
#endif
