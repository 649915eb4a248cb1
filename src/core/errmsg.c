/* Per-object error messages: the library never prints. */
#include <stdio.h>

#include "core/rcb_internal.h"

rcb_status (rcb_set_error)(char *buf, rcb_status st, const char *fmt, ...) {
  va_list ap;
  if (buf) {
    va_start(ap, fmt);
    vsnprintf(buf, RCB_ERRMSG_MAX, fmt, ap);
    va_end(ap);
    rcb_escape_controls(buf, RCB_ERRMSG_MAX);
  }
  return st;
}

/* In place, filled from the end: the escaped text of bytes [0, i) ends at j >= i,
 * so a byte is read before anything is written over it. */
void rcb_escape_controls(char *buf, size_t size) {
  static const char hex[] = "0123456789abcdef";
  size_t n, out = 0, j;
  if (!buf || size == 0) return;
  for (n = 0; buf[n]; n++) { /* the bytes that fit once escaped */
    unsigned char c = (unsigned char)buf[n];
    size_t w = (c < 0x20 || c == 0x7f) ? 4 : 1;
    if (out + w >= size) break;
    out += w;
  }
  buf[out] = '\0';
  for (j = out; n > 0; n--) {
    unsigned char c = (unsigned char)buf[n - 1];
    if (c < 0x20 || c == 0x7f) {
      buf[--j] = hex[c & 15];
      buf[--j] = hex[c >> 4];
      buf[--j] = 'x';
      buf[--j] = '\\';
    } else {
      buf[--j] = (char)c;
    }
  }
}
