/*
 * libFuzzer harness: the signals CSV reader (rcb_signals_read_csv, issue #35
 * item 6: its fixed-size buffers cut units and names without a word). A read
 * either succeeds with at most 256 channels of names under 64 characters, a
 * finite positive rate and finite samples, or fails with a message and
 * leaves the container empty.
 * Reproduce: ./fuzz/fuzz_signals_csv CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  rcb_signals *s = NULL;
  char path[64];
  int fd = rcb_fuzz_memfile(data, size, path, sizeof path);
  size_t c, i, n, nch;
  rcb_status st;
  if (rcb_signals_create(&s, NULL)) abort();
  st = rcb_signals_read_csv(s, path);
  n = rcb_signals_length(s);
  nch = rcb_signals_channel_count(s);
  if (st != RCB_OK) {
    if (rcb_signals_errmsg(s)[0] == '\0' || nch != 0) abort();
  } else {
    double rate = rcb_signals_rate(s);
    if (nch == 0 || nch > 256 || n < 2 || !isfinite(rate) || !(rate > 0.0)) abort();
    for (c = 0; c < nch; c++) {
      const char *name;
      const double *v;
      if (rcb_signals_channel(s, c, &name, NULL, &v) || !name[0] || strlen(name) > 63) abort();
      for (i = 0; i < n; i++)
        if (!isfinite(v[i])) abort();
    }
  }
  rcb_signals_destroy(s);
  close(fd);
  return 0;
}
