/*
 * libFuzzer harness: the CSV measurement reader (rcb_meas_read_csv). A read
 * either succeeds with a consistent container (finite, increasing abscissa,
 * finite values) or fails with a message and leaves it empty.
 * Reproduce: ./fuzz/fuzz_csv CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  rcb_meas *ms = NULL;
  char path[64];
  int fd = rcb_fuzz_memfile(data, size, path, sizeof path);
  if (rcb_meas_create(&ms, NULL)) abort();
  rcb_fuzz_check_meas(ms, rcb_meas_read_csv(ms, path));
  rcb_meas_destroy(ms);
  close(fd);
  return 0;
}
