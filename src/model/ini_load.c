/* INI loader: placeholder until the loader lands (see model/ini_load.c task). */
#include "core/rcb_internal.h"
#include "model/model_util.h"

rcb_status rcb_model_load_file(rcb_model *m, const char *path) {
  if (!m || !path) return RCB_ERR_ARG;
  return rcb_model_fail(m, RCB_ERR_UNSUPPORTED, "%s: INI loading not implemented yet", path);
}

rcb_status rcb_model_load_string(rcb_model *m, const char *text, const char *source_name) {
  if (!m || !text) return RCB_ERR_ARG;
  return rcb_model_fail(m, RCB_ERR_UNSUPPORTED, "%s: INI loading not implemented yet",
                        source_name ? source_name : "<string>");
}
