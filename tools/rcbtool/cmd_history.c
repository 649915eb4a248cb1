/* rcbtool history: the steps of a model-improvement session (fit, diagnose,
 * apply), their errors and parameter counts, and the error falling. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "cli_history.h"

const char cli_help_history[] =
    "usage: rcbtool history FILE [--json]\n"
    "\n"
    "Prints the steps recorded in FILE by 'rcbtool fit --history FILE' and 'rcbtool\n"
    "diagnose --history FILE': command, model, error %, noise floor %, number of\n"
    "parameters, note; then draws the error falling, one bar per step.\n"
    "FILE holds one JSON object per line; --json prints them as one JSON array.\n"
    "A file with a line that is not such a record is refused (exit 3), naming the\n"
    "line and what is wrong: a command other than fit, diagnose or apply, an error\n"
    "or floor that is negative or not finite (numbers are read whole, however\n"
    "long), a missing field. Blank lines are skipped. The longest bar is 50 #.\n";

/* The whole file, NUL-terminated, or NULL (cannot open, read error, out of
 * memory): never a part of it, which --history would write back as the whole. */
static char *slurp(const char *path, size_t *len) {
  FILE *fp = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0, n = 0, r;
  int bad = 0;
  *len = 0;
  if (!fp) return NULL;
  do {
    if (n + 4096 + 1 > cap) {
      char *nb = realloc(buf, cap = 2 * cap + 8192);
      if (!nb) {
        bad = 1;
        break;
      }
      buf = nb;
    }
    r = fread(buf + n, 1, cap - n - 1, fp);
    n += r;
  } while (r > 0);
  if (ferror(fp)) bad = 1;
  fclose(fp);
  if (bad) {
    free(buf);
    return NULL;
  }
  buf[n] = '\0';
  *len = n;
  return buf;
}

/* @p text (@p len bytes) read as a history into @p h: 0, or the message and
 * @p code naming @p path and the line that is no record (cli_history_read.c
 * says what is wrong with it): exit 5 for a --history to append to, 3 for
 * rcbtool history. */
static int read_history(const char *text, size_t len, const char *path, int code,
                        cli_history *h) {
  int r = cli_history_parse(text, len, h);
  if (r < 0) return cli_fail(CLI_EXIT_NUMERIC, "out of memory reading the history '%s'", path);
  if (r == 0) return 0;
  if (code == CLI_EXIT_IO)
    return cli_fail(code, "--history '%s':%zu: not a history record: %s; refusing to append "
                    "to a file that is not a history (expected one JSON line per step, as "
                    "--history writes them): give a new file name", path, h->bad_line, h->why);
  return cli_fail(code, "history '%s':%zu: not a history record: %s (expected one JSON line "
                  "per step with \"command\" (fit, diagnose or apply), \"model\" and "
                  "\"error_pct\", numbers finite and >= 0 or null, as 'rcbtool fit --history' "
                  "and 'rcbtool diagnose --history' write them); give a history file", path,
                  h->bad_line, h->why);
}

int cli_history_check(const char *path) {
  size_t len = 0;
  struct stat st;
  cli_history h;
  char *text;
  int rc;
  if (cli_plan_check()) return CLI_EXIT_IO;
  if (stat(path, &st) != 0) return 0; /* a new history */
  if (!S_ISREG(st.st_mode))
    return cli_fail(CLI_EXIT_IO, "--history '%s': not a regular file; expected a history "
                    "file (JSON lines written by --history) or a new file name", path);
  if (!(text = slurp(path, &len)))
    return cli_fail(CLI_EXIT_IO, "--history '%s': cannot read it", path);
  rc = read_history(text, len, path, CLI_EXIT_IO, &h);
  cli_history_free(&h);
  free(text);
  return rc;
}

int cli_history_append(const char *path, const char *command, const char *model,
                       double error_pct, double floor_pct, size_t nparams, const char *note) {
  size_t len = 0;
  char *old = NULL;
  cli_tmpfile t;
  struct stat st;
  FILE *fp;
  int ok, rc, e;
  if ((rc = cli_history_check(path))) return rc;
  /* the steps so far, all of them or the run fails: never a history of one step */
  if (stat(path, &st) == 0 && !(old = slurp(path, &len)))
    return cli_fail(CLI_EXIT_IO, "--history '%s': cannot read it", path);
  /* the whole history, old steps and the new one, in a temporary of the plan:
   * renamed onto the history when the run succeeded */
  if ((rc = cli_tmpfile_open(&t, path))) {
    free(old);
    return rc;
  }
  if (!(fp = fopen(t.write_path, "w"))) {
    e = errno;
    cli_tmpfile_close(&t, 0);
    free(old);
    return cli_fail(CLI_EXIT_IO, "--history '%s': cannot write it: %s", path, strerror(e));
  }
  errno = 0; /* the first failing write sets it: its reason is the message's */
  if (old) fwrite(old, 1, len, fp);
  if (old && len && old[len - 1] != '\n') fputc('\n', fp); /* not glued to its last line */
  fputs("{\"command\": ", fp);
  cli_json_str(fp, command);
  fputs(", \"model\": ", fp);
  cli_json_str(fp, model);
  fputs(", \"error_pct\": ", fp);
  cli_json_num(fp, error_pct);
  fputs(", \"floor_pct\": ", fp);
  cli_json_num(fp, floor_pct);
  fprintf(fp, ", \"params\": %zu, \"note\": ", nparams);
  cli_json_str(fp, note);
  fputs("}\n", fp);
  ok = !ferror(fp) && fflush(fp) == 0;
  e = errno ? errno : EIO;
  if (fclose(fp) != 0 && ok) {
    ok = 0;
    e = errno ? errno : EIO;
  }
  free(old);
  rc = cli_tmpfile_close(&t, ok);
  if (!ok) return cli_fail(CLI_EXIT_IO, "--history '%s': cannot write it: %s", path, strerror(e));
  return rc;
}

/* The model column: the file name whole (a long directory is cut to ".../"),
 * so two models never look alike. */
static const char *short_name(const char *path, char *buf, size_t size) {
  const char *slash = strrchr(path, '/');
  if (strlen(path) <= 28 || !slash) return path;
  snprintf(buf, size, ".../%s", slash + 1);
  return buf;
}

#define BAR_WIDTH 50 /* characters: the largest error's bar */

static void print_steps(const cli_history *h) {
  double emax = 0;
  size_t i;
  int b;
  printf("%-4s %-10s %-28s %10s %10s %6s  %s\n", "step", "command", "model", "error %",
         "floor % *", "params", "note");
  for (i = 0; i < h->n; i++) {
    const cli_hist_step *st = &h->step[i];
    char shown[300], tcmd[128], tmodel[1024], tnote[2048], e[32] = "-", f[32] = "-",
         np[32] = "-";
    if (st->error_pct > emax) emax = st->error_pct;
    /* the one escaping rule (cli_text.c): a file's bytes never reach the terminal raw */
    cli_text(st->command, tcmd, sizeof tcmd);
    cli_text(short_name(st->model, shown, sizeof shown), tmodel, sizeof tmodel);
    cli_text(st->note, tnote, sizeof tnote);
    if (!isnan(st->error_pct)) snprintf(e, sizeof e, "%.4g", st->error_pct);
    if (!isnan(st->floor_pct)) snprintf(f, sizeof f, "%.4g", st->floor_pct);
    if (st->params >= 0) snprintf(np, sizeof np, "%ld", st->params);
    printf("%-4zu %-10s %-28s %10s %10s %6s  %s\n", i + 1, tcmd, tmodel, e, f, np, tnote);
  }
  if (h->n == 0) return;
  puts("* predicted by the --noise model (eq. 19), not measured: the error reached can be "
       "lower");
  printf("\nerror %% by step (each # is %.3g %%):\n", emax / BAR_WIDTH);
  for (i = 0; i < h->n; i++) {
    /* 0 to BAR_WIDTH characters, whatever the file holds */
    int bars = cli_history_bar(h->step[i].error_pct, emax, BAR_WIDTH);
    printf("%4zu |", i + 1);
    for (b = 0; b < bars; b++) putchar('#');
    if (isnan(h->step[i].error_pct))
      puts(" - %");
    else
      printf(" %.4g %%\n", h->step[i].error_pct);
  }
}

/* The steps as one JSON array, every field written again (strings through
 * cli_json_str, numbers through cli_json_num): valid JSON whatever the file held,
 * the same numbers as the table. */
static void print_json(const cli_history *h) {
  size_t i;
  fputs("[", stdout);
  for (i = 0; i < h->n; i++) {
    const cli_hist_step *st = &h->step[i];
    printf("%s\n{\"command\": ", i ? "," : "");
    cli_json_str(stdout, st->command);
    fputs(", \"model\": ", stdout);
    cli_json_str(stdout, st->model);
    fputs(", \"note\": ", stdout);
    cli_json_str(stdout, st->note);
    fputs(", \"error_pct\": ", stdout);
    cli_json_num(stdout, st->error_pct);
    fputs(", \"floor_pct\": ", stdout);
    cli_json_num(stdout, st->floor_pct);
    fputs(", \"params\": ", stdout);
    cli_json_num(stdout, st->params < 0 ? (double)NAN : (double)st->params);
    putchar('}');
  }
  fputs("]\n", stdout);
}

int cmd_history(int argc, char **argv) {
  cli_args a;
  size_t len;
  cli_history h;
  char *text;
  int rc = cli_parse(argc, argv, NULL, 0, &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_history);
  if (!a.model)
    return cli_usage(a.cmd, "missing the history file; expected rcbtool history FILE");
  if (!(text = slurp(a.model, &len)))
    return cli_fail(CLI_EXIT_INPUT, "history '%s': cannot read it", a.model);
  rc = read_history(text, len, a.model, CLI_EXIT_INPUT, &h);
  free(text);
  if (!rc && a.json)
    print_json(&h);
  else if (!rc)
    print_steps(&h);
  cli_history_free(&h);
  return rc;
}
