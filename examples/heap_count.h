/*
 * The C heap counted (issue #36), for the examples that run in the caller's
 * memory (examples/consumer --arena, examples/firmware): included once, in
 * the program's main file, under RCB_EXAMPLE_COUNT_HEAP, which
 * heap_count.cmake defines when it links the program with
 *   -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free   (GNU ld, lld)
 * The linker then sends every call of these from the objects it links
 * statically (the program and librcb.a; not from shared libraries) here,
 * where it is counted and passed on. With the allocator hooks set, librcb
 * must make none: heap_calls stays 0.
 */
#ifndef RCB_EXAMPLES_HEAP_COUNT_H
#define RCB_EXAMPLES_HEAP_COUNT_H
#include <stddef.h>

static size_t heap_calls; /* calls of malloc, calloc, realloc, free (non-NULL) */

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);
void __real_free(void *p);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t size);
void *__wrap_realloc(void *p, size_t n);
void __wrap_free(void *p);

void *__wrap_malloc(size_t n) {
  heap_calls++;
  return __real_malloc(n);
}
void *__wrap_calloc(size_t n, size_t size) {
  heap_calls++;
  return __real_calloc(n, size);
}
void *__wrap_realloc(void *p, size_t n) {
  heap_calls++;
  return __real_realloc(p, n);
}
void __wrap_free(void *p) {
  heap_calls += p != NULL;
  __real_free(p);
}
#endif
