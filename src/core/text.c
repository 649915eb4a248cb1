/* Small text helpers shared by the stages (name suggestions in messages). */
#include <ctype.h>
#include <string.h>

#include "core/rcb_internal.h"

#define RCB_EDIT_MAX 160

size_t rcb_edit_distance(const char *a, const char *b) {
  size_t row[RCB_EDIT_MAX + 1], la = strlen(a), lb = strlen(b), i, j;
  if (la > RCB_EDIT_MAX || lb > RCB_EDIT_MAX) return (size_t)-1;
  for (j = 0; j <= lb; j++) row[j] = j;
  for (i = 1; i <= la; i++) {
    size_t diag = row[0];
    row[0] = i;
    for (j = 1; j <= lb; j++) {
      size_t up = row[j];
      size_t cost = tolower((unsigned char)a[i - 1]) == tolower((unsigned char)b[j - 1]) ? 0 : 1;
      size_t best = diag + cost;
      if (up + 1 < best) best = up + 1;
      if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
      row[j] = best;
      diag = up;
    }
  }
  return row[lb];
}
