/* Allocation through the per-object hooks (NULL hooks mean malloc/free). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"

void rcb_allocator_init(rcb_allocator *dst, const rcb_allocator *src) {
  if (src && src->alloc && src->free) {
    *dst = *src;
  } else {
    dst->alloc = NULL;
    dst->free = NULL;
    dst->user = NULL;
  }
}

void *rcb_alloc(const rcb_allocator *a, size_t size) {
  void *p;
  if (size == 0) size = 1;
  p = (a && a->alloc) ? a->alloc(a->user, size) : malloc(size);
  if (p) memset(p, 0, size);
  return p;
}

void rcb_free(const rcb_allocator *a, void *p) {
  if (!p) return;
  if (a && a->free)
    a->free(a->user, p);
  else
    free(p);
}

int rcb_grow(const rcb_allocator *a, void **items, size_t *cap, size_t need, size_t item_size) {
  size_t ncap;
  void *p;
  if (need <= *cap) return 0;
  ncap = *cap ? *cap : 4;
  while (ncap < need) ncap *= 2;
  if (ncap > SIZE_MAX / item_size) return -1;
  p = rcb_alloc(a, ncap * item_size);
  if (!p) return -1;
  if (*items) {
    memcpy(p, *items, *cap * item_size);
    rcb_free(a, *items);
  }
  *items = p;
  *cap = ncap;
  return 0;
}
