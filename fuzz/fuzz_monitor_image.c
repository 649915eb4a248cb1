/*
 * libFuzzer harness: the monitor's commissioning image (rcb_monitor_opts.image,
 * issue #34 item 5). One monitor is made once (the paper system, 4
 * inertances x 24 lines, kt tracked, bearing effects, re-linearised: the
 * image then carries the low-rank blocks); its image is the pristine one.
 * The input's checksum (its last 8 bytes, monitor_image.c's 64-bit word
 * hash) is made again (so that mutations reach the field checks, as an
 * attacker who knows the layout would), then rcb_monitor_create takes it:
 *  - refused: a message, no monitor left half-made (destroyed cleanly);
 *  - taken: the monitor's image saves back to the input's bytes, and an
 *    update succeeds or fails with a message (a singular re-evaluation, a
 *    covariance no Cholesky takes). Its statistics are not asserted finite: the loader
 *    checks the values finite and Q's columns of unit length, not that
 *    they are what a create computes (G, the low-rank blocks), so crafted
 *    values can overflow them; what this harness looks for is a read or
 *    write outside the blocks (ASan) and undefined behaviour (UBSan).
 * Seeds: RCB_FUZZ_WRITE_SEEDS=DIR ./fuzz_monitor_image writes the image of
 * this monitor and of the same without re-linearisation into DIR
 * (fuzz/corpus/monitor_image) and exits.
 * Reproduce: ./fuzz/fuzz_monitor_image CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */
#include "fuzz_monitor_common.h"

#define IMMAX (1u << 20)

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rcb_model *g_model;
static rcb_meas *g_setup;
static rcb_monitor_param g_tp;
static rcb_monitor_opts g_o;
static unsigned char g_buf[IMMAX], g_out[IMMAX];


/* monitor_image.c's checksum: FNV-1a's step on 64-bit little-endian
 * words, the tail byte by byte, a final mix. */
static uint64_t get_u64(const unsigned char *p) {
  uint64_t v = 0;
  int i;
  for (i = 7; i >= 0; i--) v = (v << 8) | p[i];
  return v;
}
static uint64_t checksum(const unsigned char *p, size_t n) {
  uint64_t h = 0xcbf29ce484222325ull;
  size_t i;
  for (i = 0; i + 8 <= n; i += 8) h = (h ^ get_u64(p + i)) * 0x100000001b3ull;
  for (; i < n; i++) h = (h ^ p[i]) * 0x100000001b3ull;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  return h ^ (h >> 33);
}

static size_t image_of(size_t relin, unsigned char *b) {
  rcb_monitor *mon = NULL;
  rcb_monitor_opts o = g_o;
  size_t n = 0;
  o.relinearise = relin, o.image = NULL, o.image_size = 0;
  if (rcb_monitor_create(&mon, g_model, g_setup, &o, NULL) ||
      rcb_monitor_image_save(mon, b, IMMAX, &n))
    abort();
  rcb_monitor_destroy(mon);
  return n;
}

static void write_seed(const char *dir, const char *name, size_t relin) {
  char path[4096];
  size_t n = image_of(relin, g_out);
  FILE *fp;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  if (!(fp = fopen(path, "wb")) || fwrite(g_out, 1, n, fp) != n || fclose(fp)) abort();
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  double kt;
  const char *seeds = getenv("RCB_FUZZ_WRITE_SEEDS");
  (void)argc, (void)argv;
  if (rcb_model_create(&g_model, NULL) ||
      rcb_model_load_file(g_model, RCB_FUZZ_EXAMPLES "/paper_system.ini") ||
      rcb_model_get_param(g_model, "coupling.C.kt", &kt))
    abort();
  g_setup = setup_of(g_model);
  memset(&g_o, 0, sizeof g_o);
  g_tp.name = "coupling.C.kt", g_tp.lo = 0.5 * kt, g_tp.hi = 1.5 * kt;
  g_o.ntracked = 1, g_o.tracked = &g_tp;
  g_o.beta_a = 2.0, g_o.beta_s = 0.2;
  g_o.setup_averages = 4;
  g_o.reweight = 1;
  g_o.relinearise = 4;
  g_o.effects = (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) | (1u << RCB_EFFECT_BEARING_STIFFNESS);
  if (seeds) {
    write_seed(seeds, "relinearised", 4);
    write_seed(seeds, "linear", 0);
    exit(0);
  }
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  rcb_monitor *mon = NULL;
  rcb_monitor_result r;
  rcb_monitor_opts o = g_o;
  size_t n = 0, a;
  uint64_t s = 99, h;
  rcb_status st;
  int i;
  if (size > IMMAX) return 0;
  memcpy(g_buf, data, size);
  if (size >= 16) { /* the checksum made again */
    h = checksum(g_buf, size - 8);
    for (i = 0; i < 8; i++) g_buf[size - 8 + (size_t)i] = (unsigned char)(h >> (8 * i));
  }
  /* the linear seed's image is refused by this re-linearised monitor (its
   * fingerprint); its mutations still reach the checks before it */
  o.image = g_buf, o.image_size = size;
  st = rcb_monitor_create(&mon, g_model, g_setup, &o, NULL);
  if (st != RCB_OK) {
    if (!mon || rcb_monitor_errmsg(mon)[0] == '\0') abort();
    rcb_monitor_destroy(mon);
    return 0;
  }
  /* taken: what the monitor writes, and it carries on */
  if (rcb_monitor_image_save(mon, g_out, IMMAX, &n) || n != size || memcmp(g_out, g_buf, n))
    abort();
  values(&s, g_v);
  st = rcb_monitor_update(mon, g_v, NULL, &r);
  if (st != RCB_OK && rcb_monitor_errmsg(mon)[0] == '\0') abort();
  if (st == RCB_OK && (r.update != 1 || r.ntracked != 1)) abort();
  for (a = 0; st == RCB_OK && a < r.ntop; a++)
    if (r.top[a].index >= rcb_monitor_candidate_count(mon)) abort();
  rcb_monitor_destroy(mon);
  return 0;
}
