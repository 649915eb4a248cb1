/*
 * libFuzzer harness: the UFF dataset 58 reader, ASCII and binary 58b
 * (rcb_meas_read_uff), with a small node map and without one. A read either
 * succeeds with a consistent container or fails with a message and leaves
 * it empty. Reproduce: ./fuzz/fuzz_uff CRASH_FILE
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
  rcb_fuzz_check_meas(ms, rcb_meas_read_uff(ms, path, nmap, nmap ? MAP : NULL));
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
