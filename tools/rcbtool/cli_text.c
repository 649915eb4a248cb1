/* rcbtool: the one escaping rule for text we print or write (issue #26).
 *
 * Names and notes come from files and command lines a user did not write
 * (a series file named with ESC sequences, a history line with BEL in its
 * note). Two functions escape them, and every printed field goes through one:
 *   - terminal text (tables, messages, CSV comments, logs): valid UTF-8 and
 *     printable ASCII as they are; C0 controls, DEL, C1 controls (U+0080-U+009F)
 *     and every byte of invalid UTF-8 as \xNN, so nothing can move the cursor,
 *     retitle the window or split a CSV line;
 *   - JSON strings: '"' and '\' escaped, controls as \u00XX, a byte of invalid
 *     UTF-8 as \u00XX (that byte read as Latin-1), so the output is always
 *     valid JSON and no byte is lost. */
#include <string.h>

#include "cli.h"

/* Length of the valid UTF-8 sequence at @p s (1 for ASCII), its code point in
 * *cp; 0 for a byte that starts no valid sequence (a continuation byte, an
 * overlong form, a surrogate, beyond U+10FFFF, cut short, or the NUL). */
static size_t utf8_len(const unsigned char *s, unsigned *cp) {
  size_t n, i;
  *cp = s[0];
  if (s[0] > 0 && s[0] < 0x80) return 1;
  if (s[0] < 0xc2 || s[0] > 0xf4) return 0;
  n = s[0] < 0xe0 ? 2 : s[0] < 0xf0 ? 3 : 4;
  *cp = s[0] & (0x3fu >> (n - 1));
  for (i = 1; i < n; i++) {
    if ((s[i] & 0xc0) != 0x80) return 0; /* also stops at the NUL */
    *cp = (*cp << 6) | (s[i] & 0x3fu);
  }
  if ((n == 3 && *cp < 0x800) || (n == 4 && (*cp < 0x10000 || *cp > 0x10ffff)) ||
      (*cp >= 0xd800 && *cp <= 0xdfff))
    return 0;
  return n;
}

/* A control character: C0, DEL or C1. */
static int is_control(unsigned cp) { return cp < 0x20 || (cp >= 0x7f && cp <= 0x9f); }

/* Length of what may go to a terminal as it is at @p s; 0: escape its first byte. */
static size_t printable(const unsigned char *s) {
  unsigned cp;
  size_t n = utf8_len(s, &cp);
  return n && !is_control(cp) ? n : 0;
}

void cli_put_text(FILE *fp, const char *s) {
  const unsigned char *p = (const unsigned char *)(s ? s : "");
  while (*p) {
    size_t n = printable(p);
    if (n) {
      fwrite(p, 1, n, fp);
      p += n;
    } else {
      fprintf(fp, "\\x%02x", *p++);
    }
  }
}

const char *cli_text(const char *s, char *buf, size_t size) {
  const unsigned char *p = (const unsigned char *)(s ? s : "");
  size_t len = 0;
  while (*p) {
    size_t n = printable(p);
    if (n ? len + n >= size : len + 4 >= size) break; /* cut, never half an escape */
    if (n) {
      memcpy(buf + len, p, n);
      len += n;
      p += n;
    } else {
      snprintf(buf + len, size - len, "\\x%02x", *p++);
      len += 4;
    }
  }
  if (size) buf[len < size ? len : size - 1] = '\0';
  return buf;
}

void cli_json_str(FILE *fp, const char *s) {
  const unsigned char *p = (const unsigned char *)(s ? s : "");
  fputc('"', fp);
  while (*p) {
    unsigned cp;
    size_t n = utf8_len(p, &cp);
    if (*p == '"' || *p == '\\') {
      fputc('\\', fp);
      fputc(*p++, fp);
    } else if (!n) {
      fprintf(fp, "\\u%04x", *p++); /* a stray byte, read as Latin-1 */
    } else if (is_control(cp)) {
      fprintf(fp, "\\u%04x", cp);
      p += n;
    } else {
      fwrite(p, 1, n, fp);
      p += n;
    }
  }
  fputc('"', fp);
}
