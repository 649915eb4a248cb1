/* Status codes and version: generated from the X-macro list in rcb_core.h. */
#include "core/rcb_internal.h"

const char *rcb_status_str(rcb_status s) {
  switch (s) {
#define RCB_STATUS_CASE_(name, value, text) \
  case name:                                \
    return text;
    RCB_STATUS_LIST(RCB_STATUS_CASE_)
#undef RCB_STATUS_CASE_
  }
  return "unknown status";
}

int rcb_version_number(void) { return RCB_VERSION_NUMBER; }

#define RCB_STR2_(x) #x
#define RCB_STR_(x) RCB_STR2_(x)
const char *rcb_version_string(void) {
  return RCB_STR_(RCB_VERSION_MAJOR) "." RCB_STR_(RCB_VERSION_MINOR) "." RCB_STR_(
      RCB_VERSION_PATCH);
}
