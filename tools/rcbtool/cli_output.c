/* rcbtool: output destination (stdout or atomic -o FILE), CSV/JSON number and
 * string writers, and the progress line on stderr. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

/* Do two paths name the same existing file? */
static int same_file(const char *p, const char *q) {
  struct stat sp, sq;
  if (!p || !q || stat(p, &sp) != 0 || stat(q, &sq) != 0) return 0;
  return sp.st_dev == sq.st_dev && sp.st_ino == sq.st_ino;
}

/* The temporary file gets the mode a plain fopen would have given (0666 & ~umask). */
static void plain_mode(int fd) {
  mode_t mask = umask(0);
  umask(mask);
  (void)fchmod(fd, (mode_t)(0666 & ~mask));
}

/* An existing device or pipe (e.g. /dev/stdout) is written in place: a rename
 * would replace the device node by a plain file. */
static int open_special(cli_out *o, const char *path) {
  o->path = path;
  o->fp = fopen(path, "w");
  if (!o->fp)
    return cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", path, strerror(errno));
  return 0;
}

int cli_out_open(cli_out *o, const cli_args *a) {
  struct stat st;
  int fd;
  memset(o, 0, sizeof *o);
  if (!a->output || strcmp(a->output, "-") == 0) {
    o->fp = stdout;
    return 0;
  }
  if (same_file(a->output, a->model))
    return cli_fail(CLI_EXIT_IO, "refusing to write the output over the model file '%s'",
                    a->model);
  if (stat(a->output, &st) == 0 && S_ISDIR(st.st_mode))
    return cli_fail(CLI_EXIT_IO, "cannot write output file '%s': it is a directory",
                    a->output);
  if (stat(a->output, &st) == 0 && !S_ISREG(st.st_mode)) return open_special(o, a->output);
  o->path = a->output;
  o->tmp = malloc(strlen(a->output) + sizeof ".XXXXXX");
  if (!o->tmp) return cli_fail(CLI_EXIT_IO, "out of memory");
  strcpy(o->tmp, a->output);
  strcat(o->tmp, ".XXXXXX");
  fd = mkstemp(o->tmp); /* same directory, so the final rename is atomic */
  if (fd < 0) {
    int e = errno;
    free(o->tmp);
    o->tmp = NULL;
    return cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", a->output, strerror(e));
  }
  plain_mode(fd);
  o->fp = fdopen(fd, "w");
  if (!o->fp) {
    int e = errno;
    close(fd);
    cli_out_abort(o);
    return cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", a->output, strerror(e));
  }
  return 0;
}

void cli_out_abort(cli_out *o) {
  if (o->fp && o->fp != stdout) fclose(o->fp);
  if (o->tmp) {
    remove(o->tmp);
    free(o->tmp);
  }
  memset(o, 0, sizeof *o);
}

/* Flush the temporary file to disk; errno describes a failure. */
static int finish_file(FILE *fp) {
  int bad = ferror(fp) != 0;
  if (!bad && fflush(fp) != 0) bad = 1;
  if (!bad && fsync(fileno(fp)) != 0 && errno != EINVAL) bad = 1;
  if (fclose(fp) != 0) bad = 1;
  if (bad && errno == 0) errno = EIO;
  return bad;
}

int cli_out_close(cli_out *o) {
  int e;
  if (o->fp == stdout) {
    errno = 0;
    o->fp = NULL;
    if (fflush(stdout) != 0 || ferror(stdout))
      return cli_fail(CLI_EXIT_IO, "cannot write to standard output: %s",
                      strerror(errno ? errno : EIO));
    return 0;
  }
  errno = 0;
  if (finish_file(o->fp)) {
    e = errno;
    o->fp = NULL;
    cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", o->path, strerror(e));
    cli_out_abort(o);
    return CLI_EXIT_IO;
  }
  o->fp = NULL;
  if (o->tmp && rename(o->tmp, o->path) != 0) {
    e = errno;
    cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", o->path, strerror(e));
    cli_out_abort(o);
    return CLI_EXIT_IO;
  }
  free(o->tmp);
  memset(o, 0, sizeof *o);
  return 0;
}

void cli_csv_num(FILE *fp, double x) { fprintf(fp, "%.17g", x); }

void cli_json_num(FILE *fp, double x) {
  if (isfinite(x))
    fprintf(fp, "%.17g", x);
  else
    fputs("null", fp);
}

void cli_json_str(FILE *fp, const char *s) {
  fputc('"', fp);
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      fprintf(fp, "\\%c", c);
    else if (c < 0x20)
      fprintf(fp, "\\u%04x", c);
    else
      fputc(c, fp);
  }
  fputc('"', fp);
}

void cli_json_nums(FILE *fp, const double *x, size_t n, size_t stride) {
  size_t i;
  fputc('[', fp);
  for (i = 0; i < n; i++) {
    if (i) fputs(", ", fp);
    cli_json_num(fp, x[i * stride]);
  }
  fputc(']', fp);
}

const char *cli_whirl_name(rcb_whirl w) {
  switch (w) {
    case RCB_WHIRL_FORWARD:
      return "forward";
    case RCB_WHIRL_BACKWARD:
      return "backward";
    default:
      return "mixed";
  }
}

/* Sweeps shorter than this stay silent on a terminal unless --progress. */
#define CLI_PROGRESS_MIN 50

void cli_progress_start(cli_progress *p, const cli_args *a, const char *label,
                        const char *unit, size_t total) {
  p->tty = isatty(fileno(stderr));
  p->on = a->progress || (p->tty && total >= CLI_PROGRESS_MIN);
  p->label = label;
  p->unit = unit;
  p->total = total;
  p->shown = 0;
}

void cli_progress_step(cli_progress *p, size_t done) {
  /* A terminal gets ~100 updates in place; a log file one line per 10 %. */
  size_t steps = p->tty ? 100 : 10;
  if (!p->on || done == p->shown) return;
  if (done != p->total && done * steps / p->total == p->shown * steps / p->total) return;
  fprintf(stderr, "%s%s: %zu/%zu %s", p->tty ? "\r" : "", p->label, done, p->total, p->unit);
  if (!p->tty) fputc('\n', stderr);
  fflush(stderr);
  p->shown = done;
}

void cli_progress_end(cli_progress *p) {
  if (p->on && p->tty && p->shown > 0) fputc('\n', stderr);
  p->on = 0;
}
