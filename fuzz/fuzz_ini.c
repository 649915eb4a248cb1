/*
 * libFuzzer harness: the INI model loader (inih + the two-pass builder +
 * finalize + warnings). Properties checked beyond "no crash, no leak, no
 * sanitizer report":
 *  - a failed load leaves a message and an empty model;
 *  - a model that loads writes back INI text (rcb_model_write_ini) that loads
 *    again to the same node and DOF counts (the writer's round-trip contract).
 * Reproduce a crash: build with -DRCB_BUILD_FUZZERS=ON (clang), then
 *   ./fuzz/fuzz_ini CRASH_FILE
 */
#include "fuzz_common.h"

#include "rcb/rcb.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  rcb_model *m = NULL, *m2 = NULL;
  char *text = malloc(size + 1);
  size_t need = 0, i;
  char *ini;
  if (!text) return 0;
  memcpy(text, data, size);
  text[size] = '\0';
  if (rcb_model_create(&m, NULL)) abort();
  if (rcb_model_load_string(m, text, "<fuzz>") != RCB_OK) {
    if (rcb_model_errmsg(m)[0] == '\0') abort();     /* an error without a message */
    if (rcb_model_node_count(m) != 0) abort();       /* a half-built model */
    rcb_model_destroy(m);
    free(text);
    return 0;
  }
  for (i = 0; i < rcb_model_warning_count(m); i++)
    if (!rcb_model_warning(m, i)) abort();
  if (rcb_model_write_ini(m, NULL, 0, &need) != RCB_ERR_WORKSPACE || need == 0) abort();
  ini = malloc(need);
  if (!ini) abort();
  if (rcb_model_write_ini(m, ini, need, &need) != RCB_OK) abort();
  if (rcb_model_create(&m2, NULL)) abort();
  if (rcb_model_load_string(m2, ini, "<written>") != RCB_OK) {
    fprintf(stderr, "written model does not load: %s\n%s\n", rcb_model_errmsg(m2), ini);
    abort();
  }
  if (rcb_model_node_count(m2) != rcb_model_node_count(m) ||
      rcb_model_dof_count(m2) != rcb_model_dof_count(m))
    abort();
  rcb_model_destroy(m2);
  rcb_model_destroy(m);
  free(ini);
  free(text);
  return 0;
}
