/*
 * libFuzzer harness: the CSV measurement reader (rcb_meas_read_csv, and
 * rcb_meas_read_csv_map with a small node map for stations written as
 * numbers, issue #35). A read either succeeds with a consistent container
 * (finite, increasing abscissa, finite values) or fails with a message and
 * leaves it empty; without the map, a numeric station is always refused.
 * Reproduce: ./fuzz/fuzz_csv CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const rcb_uff_node MAP[] = {
    {1, "DA", NULL, NULL},
    {2, "DB", NULL, NULL},
    {10, "C.A", NULL, NULL},
    {11, "C.B", NULL, NULL}
};

static void read_once(const char *path, size_t nmap) {
  rcb_meas *ms = NULL;
  if (rcb_meas_create(&ms, NULL)) abort();
  rcb_fuzz_check_meas(ms, nmap ? rcb_meas_read_csv_map(ms, path, nmap, MAP)
                               : rcb_meas_read_csv(ms, path));
  rcb_meas_destroy(ms);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  char path[64];
  int fd = rcb_fuzz_memfile(data, size, path, sizeof path);
  read_once(path, 4);
  read_once(path, 0);
  close(fd);
  return 0;
}
