/*
 * libFuzzer harness: the monitor's state loader (rcb_monitor_load, issue #34
 * item 7). One monitor is made once (the paper system, 4 inertances x 24
 * lines, kt tracked, bearing effects) and run 3 updates: its saved state is
 * the "pristine" one every input starts from. The input's CRC-32 is made
 * again over the length it states (so that mutations reach the field checks,
 * as an attacker who knows the layout would), then:
 *  - a refused state: a message, and the monitor left as it was (its saved
 *    bytes those of the pristine state);
 *  - a loaded state: it is one the monitor writes (saved back, the bytes
 *    are the input's but for the model's two response sums, compared to
 *    1e-9, and the CRC), the next update succeeds with finite statistics,
 *    and the state that update writes loads again.
 * The monitor is then put back (the pristine state loaded).
 * Seeds: RCB_FUZZ_WRITE_SEEDS=DIR ./fuzz_monitor_state writes the states of
 * this monitor after 0, 1, 5, 33 and 40 updates and after a CUSUM reset into
 * DIR (fuzz/corpus/monitor_state) and exits.
 * Reproduce: ./fuzz/fuzz_monitor_state CRASH_FILE
 */
#include "fuzz_common.h" /* first: it defines _GNU_SOURCE */
#include "fuzz_monitor_common.h"

#define STMAX 65536

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The harness's one monitor and its pristine state (a harness may keep
 * state between inputs; the library keeps none). */
static rcb_monitor *g_mon;
static unsigned char g_pristine[STMAX], g_buf[STMAX], g_out[STMAX];
static size_t g_npristine;
static uint64_t g_seed = 1;

static void put_u32(unsigned char *p, uint32_t v) {
  int i;
  for (i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
static uint32_t get_u32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void save(const rcb_monitor *mon, unsigned char *b, size_t *n) {
  if (rcb_monitor_save(mon, b, STMAX, n)) abort();
}

static void update(rcb_monitor *mon, uint64_t *s) {
  rcb_monitor_result r;
  values(s, g_v);
  if (rcb_monitor_update(mon, g_v, NULL, &r)) abort();
}

static void write_seed(const char *dir, const char *name) {
  char path[4096];
  size_t n;
  FILE *fp;
  save(g_mon, g_out, &n);
  snprintf(path, sizeof path, "%s/%s", dir, name);
  if (!(fp = fopen(path, "wb")) || fwrite(g_out, 1, n, fp) != n || fclose(fp)) abort();
}

/* The seeds: states after 0, 1, 5, 33 (the drift ring wrapped) and 40
 * updates, and 10 updates after a CUSUM reset at 40. */
static void write_seeds(const char *dir) {
  static const size_t at[] = {1, 5, 33, 40};
  size_t u = 0, k;
  char name[32];
  write_seed(dir, "after_0");
  for (k = 0; k < sizeof at / sizeof at[0]; k++) {
    while (u < at[k]) update(g_mon, &g_seed), u++;
    snprintf(name, sizeof name, "after_%zu", u);
    write_seed(dir, name);
  }
  rcb_monitor_reset_cusum(g_mon);
  for (k = 0; k < 10; k++) update(g_mon, &g_seed);
  write_seed(dir, "reset_then_10");
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  rcb_model *m = NULL;
  rcb_meas *setup;
  rcb_monitor_param tp;
  rcb_monitor_opts o;
  double kt;
  const char *seeds = getenv("RCB_FUZZ_WRITE_SEEDS");
  size_t u;
  (void)argc, (void)argv;
  if (rcb_model_create(&m, NULL) || rcb_model_load_file(m, RCB_FUZZ_EXAMPLES "/paper_system.ini") ||
      rcb_model_get_param(m, "coupling.C.kt", &kt))
    abort();
  setup = setup_of(m);
  memset(&o, 0, sizeof o);
  tp.name = "coupling.C.kt", tp.lo = 0.5 * kt, tp.hi = 1.5 * kt;
  o.ntracked = 1, o.tracked = &tp;
  o.beta_a = 2.0, o.beta_s = 0.2;
  o.setup_averages = 4;
  o.effects = (1u << RCB_EFFECT_BEARING_CROSS_COUPLING) | (1u << RCB_EFFECT_BEARING_STIFFNESS);
  if (rcb_monitor_create(&g_mon, m, setup, &o, NULL)) abort();
  rcb_meas_destroy(setup);
  rcb_model_destroy(m);
  if (seeds) {
    write_seeds(seeds);
    exit(0);
  }
  for (u = 0; u < 3; u++) update(g_mon, &g_seed);
  save(g_mon, g_pristine, &g_npristine);
  return 0;
}

/* A loaded state: what the monitor writes, and it carries on. */
static void loaded(size_t len) {
  rcb_monitor_result r;
  size_t n, a;
  uint64_t s = 99;
  save(g_mon, g_out, &n);
  /* bytes 24 .. 39: the model's response sums, compared to 1e-9 */
  if (n != len || memcmp(g_out, g_buf, 24) != 0 || memcmp(g_out + 40, g_buf + 40, n - 44) != 0)
    abort();
  values(&s, g_v);
  if (rcb_monitor_update(g_mon, g_v, NULL, &r)) abort();
  if (!isfinite(r.T) || r.update != rcb_monitor_update_count(g_mon)) abort();
  for (a = 0; a < r.ntracked; a++)
    if (!isfinite(r.tracked[a].u) || !isfinite(r.tracked[a].cusum_up) ||
        !isfinite(r.tracked[a].cusum_down) || !isfinite(r.tracked[a].value))
      abort();
  save(g_mon, g_out, &n);
  if (rcb_monitor_load(g_mon, g_out, n)) abort(); /* what it writes, it loads */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  size_t n, len;
  rcb_status st;
  if (size > STMAX) return 0;
  memcpy(g_buf, data, size);
  /* the CRC-32 made again over the length the state states */
  if (size >= 12 && (len = get_u32(g_buf + 8)) >= 8 && len <= size)
    put_u32(g_buf + len - 4, (uint32_t)rcb_monitor_crc32(0, g_buf, len - 4));
  else
    len = 0;
  st = rcb_monitor_load(g_mon, g_buf, size);
  if (st != RCB_OK) {
    if (rcb_monitor_errmsg(g_mon)[0] == '\0') abort();
    save(g_mon, g_out, &n); /* left as it was */
    if (n != g_npristine || memcmp(g_out, g_pristine, n) != 0) abort();
    return 0;
  }
  loaded(len);
  if (rcb_monitor_load(g_mon, g_pristine, g_npristine)) abort();
  return 0;
}
