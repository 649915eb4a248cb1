/* Shared by the libFuzzer harnesses: the readers of measurements take a
 * path, so the input goes into an anonymous in-memory file (memfd) named
 * /proc/self/fd/N; nothing touches the disk. */
#ifndef RCB_FUZZ_COMMON_H
#define RCB_FUZZ_COMMON_H

#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <complex.h>
#include <math.h>

#include "rcb/rcb.h"

/* Write data to a fresh memfd; path receives its /proc/self/fd name.
 * Returns the descriptor (close it after use) or aborts: a harness that
 * cannot set up must not report "no crash". */
static int rcb_fuzz_memfile(const uint8_t *data, size_t size, char *path, size_t psize) {
  int fd = memfd_create("rcb_fuzz", 0);
  size_t off = 0;
  if (fd < 0) abort();
  while (off < size) {
    ssize_t k = write(fd, data + off, size - off);
    if (k <= 0) abort();
    off += (size_t)k;
  }
  snprintf(path, psize, "/proc/self/fd/%d", fd);
  return fd;
}

/* A read that succeeded: a consistent container (points, an increasing
 * non-negative grid, finite data) or abort. One that failed: a message and
 * no channel, or abort. */
static void rcb_fuzz_check_meas(const rcb_meas *ms, rcb_status st) {
  size_t n = rcb_meas_point_count(ms), c, i;
  const double *x = rcb_meas_grid(ms);
  if (st != RCB_OK) {
    if (rcb_meas_errmsg(ms)[0] == '\0' || rcb_meas_channel_count(ms) != 0) abort();
    return;
  }
  if (n == 0 || rcb_meas_channel_count(ms) == 0) abort();
  for (i = 0; i < n; i++)
    if (!isfinite(x[i]) || x[i] < 0 || (i && !(x[i] > x[i - 1]))) abort();
  for (c = 0; c < rcb_meas_channel_count(ms); c++) {
    rcb_meas_channel_info ci;
    if (rcb_meas_channel(ms, c, &ci)) abort();
    for (i = 0; i < n; i++)
      if (!isfinite(creal(ci.data[i])) || !isfinite(cimag(ci.data[i]))) abort();
  }
}

#endif
