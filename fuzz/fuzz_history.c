/*
 * libFuzzer harness: the history reader of rcbtool (cli_history_parse,
 * tools/rcbtool/cli_history_read.c; issue #34 item 6). Any bytes either read
 * as steps that hold what the table and the bars rely on (a known command,
 * errors and floors finite and >= 0 or NaN for null, a count or -1, line
 * numbers rising), every bar 0..50 wide, and the steps written back as the
 * writer would read to the same numbers; or are refused with the line and a
 * reason, and no step kept.
 * Reproduce: ./fuzz/fuzz_history CRASH_FILE
 */
#define _GNU_SOURCE /* open_memstream */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_history.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int known(const char *c) {
  return strcmp(c, "fit") == 0 || strcmp(c, "diagnose") == 0 || strcmp(c, "apply") == 0;
}

static int ok_pct(double x) { return isnan(x) || (isfinite(x) && x >= 0); }

/* A string as JSON with every byte >= 0x80 and every control as \u00XX:
 * the decoded bytes come back as UTF-8 of those code points, so only the
 * numbers and commands are compared after the round trip. */
static void put_str(FILE *fp, const char *s) {
  fputc('"', fp);
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      fprintf(fp, "\\%c", c);
    else if (c < 0x20 || c >= 0x7f)
      fprintf(fp, "\\u%04x", c);
    else
      fputc(c, fp);
  }
  fputc('"', fp);
}

static void put_num(FILE *fp, double x) {
  if (isnan(x))
    fputs("null", fp);
  else
    fprintf(fp, "%.17g", x);
}

static int same(double a, double b) { return (isnan(a) && isnan(b)) || a == b; }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  cli_history h, g;
  char *text = NULL;
  size_t tlen = 0, i, lines = 1, prev = 0;
  FILE *fp;
  int r = cli_history_parse((const char *)data, size, &h);
  if (r < 0) abort(); /* no allocation fails at these sizes */
  for (i = 0; i < size; i++) lines += data[i] == '\n';
  if (r == 1) {
    if (h.n != 0 || h.bad_line == 0 || h.bad_line > lines || h.why[0] == '\0') abort();
    cli_history_free(&h);
    return 0;
  }
  if (h.bad_line != 0) abort();
  for (i = 0; i < h.n; i++) {
    const cli_hist_step *st = &h.step[i];
    double emax = 0;
    size_t k;
    if (!st->command || !st->model || !st->note || !known(st->command)) abort();
    if (!ok_pct(st->error_pct) || !ok_pct(st->floor_pct) || st->params < -1) abort();
    if (st->line <= prev || st->line > lines) abort();
    prev = st->line;
    for (k = 0; k < h.n; k++)
      if (h.step[k].error_pct > emax) emax = h.step[k].error_pct;
    k = (size_t)cli_history_bar(st->error_pct, emax, 50);
    if (k > 50) abort();
  }
  /* written back (numbers as %.17g, as cli_json_num) and read again */
  if (!(fp = open_memstream(&text, &tlen))) abort();
  for (i = 0; i < h.n; i++) {
    const cli_hist_step *st = &h.step[i];
    fputs("{\"command\": ", fp);
    put_str(fp, st->command);
    fputs(", \"model\": ", fp);
    put_str(fp, st->model);
    fputs(", \"error_pct\": ", fp);
    put_num(fp, st->error_pct);
    fputs(", \"floor_pct\": ", fp);
    put_num(fp, st->floor_pct);
    fputs(", \"params\": ", fp);
    if (st->params < 0)
      fputs("null", fp);
    else
      fprintf(fp, "%ld", st->params);
    fputs(", \"note\": ", fp);
    put_str(fp, st->note);
    fputs("}\n", fp);
  }
  if (fclose(fp) != 0) abort();
  if (cli_history_parse(text, tlen, &g) != 0 || g.n != h.n) abort();
  for (i = 0; i < h.n; i++)
    if (strcmp(g.step[i].command, h.step[i].command) != 0 ||
        !same(g.step[i].error_pct, h.step[i].error_pct) ||
        !same(g.step[i].floor_pct, h.step[i].floor_pct) || g.step[i].params != h.step[i].params)
      abort();
  cli_history_free(&g);
  cli_history_free(&h);
  free(text);
  return 0;
}
