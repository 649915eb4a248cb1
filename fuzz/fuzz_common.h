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

#endif
