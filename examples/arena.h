/*
 * The caller's memory for the examples that run as firmware does
 * (examples/firmware, examples/consumer --arena): a bump arena behind
 * librcb's allocator hooks (rcb_allocator), free a no-op (a host reclaims it
 * at its next start). The hooks count their calls; once `sealed` is set,
 * every allocation is also counted as one the program did not expect.
 */
#ifndef RCB_EXAMPLES_ARENA_H
#define RCB_EXAMPLES_ARENA_H
#include <stddef.h>

typedef struct arena {
  unsigned char *base;
  size_t size, used;    /* bytes */
  size_t allocs, frees; /* calls through the hooks */
  int sealed;           /* 1 after initialisation: any allocation is a bug */
  size_t allocs_after_init;
} arena;

static void *arena_alloc(void *user, size_t n) {
  arena *a = user;
  size_t at = (a->used + 15u) & ~(size_t)15u; /* 16-byte alignment */
  a->allocs++;
  if (a->sealed) a->allocs_after_init++;
  if (at > a->size || n > a->size - at) return NULL;
  a->used = at + n;
  return a->base + at;
}

static void arena_free(void *user, void *p) {
  arena *a = user;
  (void)p;
  a->frees++;
}
#endif
