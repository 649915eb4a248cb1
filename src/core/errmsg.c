/* Per-object error messages: the library never prints. */
#include <stdio.h>

#include "core/rcb_internal.h"

rcb_status (rcb_set_error)(char *buf, rcb_status st, const char *fmt, ...) {
  va_list ap;
  if (buf) {
    va_start(ap, fmt);
    vsnprintf(buf, RCB_ERRMSG_MAX, fmt, ap);
    va_end(ap);
  }
  return st;
}
