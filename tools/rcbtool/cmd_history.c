/* rcbtool history: the steps of a model-improvement session (fit, diagnose,
 * apply), their errors and parameter counts, and the error falling. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

const char cli_help_history[] =
    "usage: rcbtool history FILE [--json]\n"
    "\n"
    "Prints the steps recorded in FILE by 'rcbtool fit --history FILE' and 'rcbtool\n"
    "diagnose --history FILE': command, model, error %, noise floor %, number of\n"
    "parameters, note; then draws the error falling, one bar per step.\n"
    "FILE holds one JSON object per line; --json prints them as one JSON array.\n"
    "A file with a line that is not such a record is refused (exit 3), naming the\n"
    "line.\n";

static char *slurp(const char *path, size_t *len) {
  FILE *fp = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0, n = 0, r;
  *len = 0;
  if (!fp) return NULL;
  do {
    if (n + 4096 + 1 > cap) {
      char *nb = realloc(buf, cap = 2 * cap + 8192);
      if (!nb) break;
      buf = nb;
    }
    r = fread(buf + n, 1, cap - n - 1, fp);
    n += r;
  } while (r > 0);
  fclose(fp);
  if (buf) buf[n] = '\0';
  *len = n;
  return buf;
}

/* A line (@p n bytes, no newline) is a history record: one JSON object with the
 * fields cli_history_append writes. */
static int field(const char *line, const char *key, char *out, size_t size);

/* A number field as --history writes it: absent, null, or a finite number
 * (a nan or 1e999 typed into the file is no record: cli_json_num writes null). */
static int number_ok(const char *line, const char *key) {
  char v[64], *end;
  double x;
  if (!field(line, key, v, sizeof v) || strcmp(v, "null") == 0) return 1;
  x = strtod(v, &end);
  return end != v && *end == '\0' && isfinite(x);
}

static int is_record(const char *line, size_t n) {
  static const char *const keys[] = {"\"command\": ", "\"model\": ", "\"error_pct\": "};
  static const char *const nums[] = {"error_pct", "floor_pct", "params"};
  char buf[4096];
  size_t i;
  if (n < 2 || n >= sizeof buf || line[0] != '{' || line[n - 1] != '}') return 0;
  memcpy(buf, line, n);
  buf[n] = '\0';
  for (i = 0; i < sizeof keys / sizeof keys[0]; i++)
    if (!strstr(buf, keys[i])) return 0;
  for (i = 0; i < sizeof nums / sizeof nums[0]; i++)
    if (!number_ok(buf, nums[i])) return 0;
  return strlen(buf) == n; /* no NUL byte inside */
}

/* 0 if @p text (@p len bytes) is empty or history lines only; else the
 * number of the first line that is not. */
static size_t first_bad_line(const char *text, size_t len) {
  size_t pos = 0, k = 0;
  while (pos < len) {
    const char *nl = memchr(text + pos, '\n', len - pos);
    size_t end = nl ? (size_t)(nl - text) : len, n = end - pos;
    k++;
    if (n > 0 && text[end - 1] == '\r') n--;
    if (n > 0 && !is_record(text + pos, n)) return k;
    pos = end + 1;
  }
  return 0;
}

int cli_history_check(const char *path) {
  size_t len = 0, bad;
  struct stat st;
  char *text;
  if (cli_plan_check()) return CLI_EXIT_IO;
  if (stat(path, &st) != 0) return 0; /* a new history */
  if (!S_ISREG(st.st_mode))
    return cli_fail(CLI_EXIT_IO, "--history '%s': not a regular file; expected a history "
                    "file (JSON lines written by --history) or a new file name", path);
  if (!(text = slurp(path, &len)))
    return cli_fail(CLI_EXIT_IO, "--history '%s': cannot read it", path);
  bad = first_bad_line(text, len);
  free(text);
  if (bad)
    return cli_fail(CLI_EXIT_IO, "--history '%s':%zu: not a history record; refusing to "
                    "append to a file that is not a history (expected one JSON line per "
                    "step, as --history writes them): give a new file name", path, bad);
  return 0;
}

int cli_history_append(const char *path, const char *command, const char *model,
                       double error_pct, double floor_pct, size_t nparams, const char *note) {
  size_t len = 0;
  char *old;
  cli_tmpfile t;
  FILE *fp;
  int ok, rc, e;
  if ((rc = cli_history_check(path))) return rc;
  old = slurp(path, &len);
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

/* The value of "key": in a JSON line (a string or a number), copied to out. */
static int field(const char *line, const char *key, char *out, size_t size) {
  char pat[64];
  const char *p;
  size_t n = 0;
  snprintf(pat, sizeof pat, "\"%s\": ", key);
  if (!(p = strstr(line, pat))) return 0;
  p += strlen(pat);
  if (*p == '"') {
    for (p++; *p && *p != '"' && n + 5 < size; p++) {
      if (*p != '\\' || !p[1]) {
        out[n++] = *p;
        continue;
      }
      p++; /* a JSON escape: \uXXXX back to UTF-8 (cli_json_str writes them) */
      if (*p == 'u' && strspn(p + 1, "0123456789abcdefABCDEF") >= 4) {
        char hex[5] = {p[1], p[2], p[3], p[4], 0};
        unsigned long cp = strtoul(hex, NULL, 16);
        p += 4;
        if (cp == 0) cp = 0xfffd; /* a NUL would end the text: U+FFFD, shown as such */
        if (cp < 0x80) {
          out[n++] = (char)cp;
        } else if (cp < 0x800) {
          out[n++] = (char)(0xc0 | (cp >> 6));
          out[n++] = (char)(0x80 | (cp & 0x3f));
        } else {
          out[n++] = (char)(0xe0 | (cp >> 12));
          out[n++] = (char)(0x80 | ((cp >> 6) & 0x3f));
          out[n++] = (char)(0x80 | (cp & 0x3f));
        }
      } else {
        out[n++] = *p == 'n' ? '\n' : *p == 't' ? '\t' : *p == 'r' ? '\r' : *p == 'b' ? '\b'
                 : *p == 'f' ? '\f' : *p;
      }
    }
  } else {
    while (*p && *p != ',' && *p != '}' && n + 1 < size) out[n++] = *p++;
  }
  out[n] = '\0';
  return 1;
}

/* A number field of a record (0 when it holds none, e.g. null), with the
 * conversion checked (cert-err34-c) instead of atof's silent 0. */
static double num_field(const char *s) {
  char *end;
  double v = strtod(s, &end);
  return end == s ? 0.0 : v;
}

/* The model column: the file name whole (a long directory is cut to ".../"),
 * so two models never look alike. */
static const char *short_name(const char *path, char *buf, size_t size) {
  const char *slash = strrchr(path, '/');
  if (strlen(path) <= 28 || !slash) return path;
  snprintf(buf, size, ".../%s", slash + 1);
  return buf;
}

static void print_steps(char *text) {
  char *line, *save = NULL;
  double emax = 0;
  int step = 0, pass;
  for (pass = 0; pass < 2; pass++) {
    char *copy = strdup(text);
    if (!copy) return;
    step = 0;
    if (pass == 1) {
      printf("%-4s %-10s %-28s %10s %10s %6s  %s\n", "step", "command", "model", "error %",
             "floor % *", "params", "note");
    }
    for (line = strtok_r(copy, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
      char cmd[32] = "", model[256] = "", err[64] = "", flo[64] = "", np[16] = "",
           note[512] = "", shown[300], tcmd[128], tmodel[1024], tnote[2048], tnp[64];
      double e;
      field(line, "command", cmd, sizeof cmd);
      field(line, "model", model, sizeof model);
      field(line, "error_pct", err, sizeof err);
      field(line, "floor_pct", flo, sizeof flo);
      field(line, "params", np, sizeof np);
      field(line, "note", note, sizeof note);
      e = num_field(err);
      step++;
      if (pass == 0) {
        if (e > emax) emax = e;
        continue;
      }
      /* the one escaping rule (cli_text.c): a file's bytes never reach the terminal raw */
      cli_text(cmd, tcmd, sizeof tcmd);
      cli_text(short_name(model, shown, sizeof shown), tmodel, sizeof tmodel);
      cli_text(note, tnote, sizeof tnote);
      cli_text(np, tnp, sizeof tnp);
      if (strcmp(flo, "null") != 0 && flo[0])
        printf("%-4d %-10s %-28s %10.4g %10.4g %6s  %s\n", step, tcmd, tmodel, e,
               num_field(flo), tnp, tnote);
      else
        printf("%-4d %-10s %-28s %10.4g %10s %6s  %s\n", step, tcmd, tmodel, e, "-", tnp,
               tnote);
    }
    free(copy);
  }
  if (step == 0) return;
  puts("* predicted by the --noise model (eq. 19), not measured: the error reached can be "
       "lower");
  printf("\nerror %% by step (each # is %.3g %%):\n", emax / 50);
  {
    char *copy = strdup(text);
    int k = 0;
    if (!copy) return;
    for (line = strtok_r(copy, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
      char err[64] = "";
      int bars, b;
      field(line, "error_pct", err, sizeof err);
      bars = emax > 0 ? (int)lround(50.0 * num_field(err) / emax) : 0;
      printf("%4d |", ++k);
      for (b = 0; b < bars; b++) putchar('#');
      printf(" %.4g %%\n", num_field(err));
    }
    free(copy);
  }
}

/* One record written again field by field (strings through cli_json_str,
 * numbers through cli_json_num): valid JSON whatever the line held. */
static void print_json_record(const char *line, int first) {
  static const char *const strs[] = {"command", "model", "note"};
  static const char *const nums[] = {"error_pct", "floor_pct", "params"};
  char buf[4096];
  size_t i;
  printf("%s\n{", first ? "" : ",");
  for (i = 0; i < 3; i++) {
    printf("%s\"%s\": ", i ? ", " : "", strs[i]);
    buf[0] = '\0';
    field(line, strs[i], buf, sizeof buf);
    cli_json_str(stdout, buf);
  }
  for (i = 0; i < 3; i++) {
    char *end;
    double v;
    buf[0] = '\0';
    field(line, nums[i], buf, sizeof buf);
    v = strtod(buf, &end);
    printf(", \"%s\": ", nums[i]);
    cli_json_num(stdout, end == buf ? (double)NAN : v);
  }
  putchar('}');
}

int cmd_history(int argc, char **argv) {
  cli_args a;
  size_t len, bad;
  char *text;
  int rc = cli_parse(argc, argv, NULL, 0, &a);
  if (rc) return rc;
  if (a.help) return cli_print_help(cli_help_history);
  if (!a.model)
    return cli_usage(a.cmd, "missing the history file; expected rcbtool history FILE");
  if (!(text = slurp(a.model, &len)))
    return cli_fail(CLI_EXIT_INPUT, "history '%s': cannot read it", a.model);
  if ((bad = first_bad_line(text, len)) != 0) {
    free(text);
    return cli_fail(CLI_EXIT_INPUT, "history '%s':%zu: not a history record (expected one JSON "
                    "line per step with \"command\", \"model\" and \"error_pct\", numbers "
                    "finite or null, as 'rcbtool fit --history' and 'rcbtool diagnose --history' "
                    "write them); give a history file", a.model, bad);
  }
  if (a.json) {
    char *line, *save = NULL;
    int first = 1;
    fputs("[", stdout);
    for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
      print_json_record(line, first);
      first = 0;
    }
    fputs("]\n", stdout);
  } else {
    print_steps(text);
  }
  free(text);
  return 0;
}
