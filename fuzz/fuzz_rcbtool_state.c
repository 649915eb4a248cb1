/*
 * libFuzzer harness: rcbtool's --state file parser (mon_saved_parse in
 * tools/rcbtool/cmd_monitor_state.c, issue #34 item 7), compiled in with the
 * two CLI functions it calls stubbed here: cli_fail keeps the message (it
 * must name the file), and the temporary-file pair aborts (parsing writes
 * nothing). The file's CRC-32 (its last 4 bytes) is made again so that
 * mutations reach the layout and the records. A parse either fails with a
 * message naming the file and nothing kept, or succeeds with what rcbtool
 * writes: a set-up, the library's state, records numbered 1 .. n with
 * bounded counts and flags.
 * Seeds: fuzz/corpus/rcbtool_state, states written by rcbtool monitor
 * --state (fuzz/README.md).
 * Reproduce: ./fuzz/fuzz_rcbtool_state CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */

#include <stdarg.h>

#include "cmd_monitor.h"

#define PATH "fuzzed.rcbmon"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char g_msg[4096];

int(cli_fail)(int code, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(g_msg, sizeof g_msg, fmt, ap);
  va_end(ap);
  return code;
}
int cli_tmpfile_open(cli_tmpfile *t, const char *path) {
  (void)t, (void)path;
  abort();
}
int cli_tmpfile_close(cli_tmpfile *t, int ok) {
  (void)t, (void)ok;
  abort();
}

static void check_saved(const mon_saved *sv) {
  size_t k, i;
  if (!sv->setup || rcb_meas_point_count(sv->setup) == 0 || !sv->blob || !sv->opts ||
      !sv->comm || (sv->nrec && (!sv->rec || !sv->recfile)))
    abort();
  for (k = 0; k < sv->nopts; k++)
    if (!sv->opts[k]) abort();
  for (k = 0; k < sv->nrec; k++) {
    const rcb_monitor_result *r = &sv->rec[k].r;
    if (!sv->recfile[k] || r->update != k + 1 || r->ntop > RCB_MONITOR_TOP ||
        r->ntracked < 1 || r->ntracked > RCB_MONITOR_MAX_TRACKED ||
        r->drift_dof > RCB_MONITOR_MAXP)
      abort();
    for (i = 0; i < r->ntop; i++)
      if (r->top[i].np < 1 || r->top[i].np > RCB_MONITOR_MAXP) abort();
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  mon_saved sv;
  unsigned char *b = malloc(size ? size : 1);
  int rc;
  if (!b) abort();
  memcpy(b, data, size);
  if (size >= 20) { /* the CRC-32 of all but the last 4 bytes, little-endian */
    unsigned long c = rcb_monitor_crc32(0, b, size - 4);
    int i;
    for (i = 0; i < 4; i++) b[size - 4 + (size_t)i] = (unsigned char)(c >> (8 * i));
  }
  g_msg[0] = '\0';
  rc = mon_saved_parse("monitor", PATH, b, size, &sv);
  if (rc) {
    if (rc != CLI_EXIT_INPUT || !strstr(g_msg, PATH) || sv.setup || sv.blob || sv.rec) abort();
  } else {
    check_saved(&sv);
    mon_saved_free(&sv);
  }
  free(b);
  return 0;
}
