/*
 * libFuzzer harness, differential: rcb_strtod and rcb_strtod_in (the text
 * readers' number parser, src/core/numparse.c) against the C library's
 * strtod on any byte string: the same value bits, end and errno, or abort.
 * rcb_strtod_in gets the string followed by digits up to its lim, which it
 * must not take as part of the number.
 * Reproduce: ./fuzz/fuzz_strtod CRASH_FILE
 */
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/rcb_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  char s[512], pad[600];
  char *e1, *e2, *e3;
  double a, b, c;
  int r1, r2, r3;
  if (size > sizeof s - 1) size = sizeof s - 1;
  memcpy(s, data, size);
  s[size] = '\0';
  memset(pad, '5', sizeof pad);
  memcpy(pad, s, size + 1);
  errno = 0;
  a = rcb_strtod(s, &e1);
  r1 = errno;
  errno = 0;
  c = rcb_strtod_in(pad, pad + sizeof pad, &e3);
  r3 = errno;
  errno = 0;
  b = strtod(s, &e2);
  r2 = errno;
  if (memcmp(&a, &b, sizeof a) != 0 || e1 != e2 || r1 != r2) abort();
  if (memcmp(&c, &b, sizeof c) != 0 || e3 - pad != e2 - s || r3 != r2) abort();
  return 0;
}
