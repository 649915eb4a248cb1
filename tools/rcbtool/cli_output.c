/* rcbtool: output destination (stdout or atomic -o FILE), CSV/JSON number and
 * string writers, and the progress line on stderr. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

/* ---- the inputs of this run: no output may be one of them ---- */

#define CLI_MAX_INPUTS 8
typedef struct cli_input {
  dev_t dev;
  ino_t ino;
  const char *path, *what;
} cli_input;
static cli_input inputs[CLI_MAX_INPUTS];
static size_t ninputs;

void cli_input_add(const char *path, const char *what) {
  struct stat st;
  size_t i;
  if (!path || strcmp(path, "-") == 0 || stat(path, &st) != 0) return;
  for (i = 0; i < ninputs; i++)
    if (inputs[i].dev == st.st_dev && inputs[i].ino == st.st_ino) return;
  if (ninputs == CLI_MAX_INPUTS) return;
  inputs[ninputs].dev = st.st_dev;
  inputs[ninputs].ino = st.st_ino;
  inputs[ninputs].path = path;
  inputs[ninputs].what = what;
  ninputs++;
}

int cli_output_check(const char *path) {
  struct stat st;
  size_t i;
  /* by device and inode: a link, "./x" or "../d/x" is the same file */
  if (!path || strcmp(path, "-") == 0 || stat(path, &st) != 0) return 0;
  for (i = 0; i < ninputs; i++)
    if (inputs[i].dev == st.st_dev && inputs[i].ino == st.st_ino)
      return cli_fail(CLI_EXIT_IO, "refusing to write the output '%s' over the %s file '%s' "
                      "(an input of this run); choose another output name", path,
                      inputs[i].what, inputs[i].path);
  return 0;
}

/* ---- temporary files removed on SIGINT, SIGTERM, SIGHUP ---- */

#define CLI_TMP_SLOTS 8
#define CLI_TMP_PATH 4096
static char tmp_paths[CLI_TMP_SLOTS][CLI_TMP_PATH];
static volatile sig_atomic_t tmp_live[CLI_TMP_SLOTS];

/* Async-signal-safe: unlink() the live temporaries, then die of the signal
 * (SA_RESETHAND restored the default action; the signal is delivered again
 * when the handler returns). */
static void on_signal(int sig) {
  int i, e = errno;
  for (i = 0; i < CLI_TMP_SLOTS; i++)
    if (tmp_live[i]) unlink(tmp_paths[i]);
  errno = e;
  raise(sig);
}

void cli_signals_install(void) {
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
  size_t i;
  for (i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
    struct sigaction sa, old;
    if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue; /* nohup */
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = (int)SA_RESETHAND;
    sigaction(sigs[i], &sa, NULL);
  }
}

int cli_tmp_register(const char *path) {
  int i;
  if (strlen(path) >= CLI_TMP_PATH) return -1;
  for (i = 0; i < CLI_TMP_SLOTS; i++)
    if (!tmp_live[i]) {
      strcpy(tmp_paths[i], path);
      tmp_live[i] = 1; /* after the copy: the handler never sees half a name */
      return i;
    }
  return -1;
}

void cli_tmp_release(int slot) {
  if (slot >= 0 && slot < CLI_TMP_SLOTS) tmp_live[slot] = 0;
}

static void plain_mode(int fd);

int cli_tmpfile_open(cli_tmpfile *t, const char *path) {
  struct stat st;
  int fd;
  memset(t, 0, sizeof *t);
  t->path = t->write_path = path;
  t->slot[0] = t->slot[1] = -1;
  /* a device or pipe is written in place (a rename would replace it) */
  if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) return 0;
  if (!(t->tmp = malloc(strlen(path) + sizeof ".XXXXXX.tmp000")))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(t->tmp, path);
  strcat(t->tmp, ".XXXXXX");
  if ((fd = mkstemp(t->tmp)) < 0) {
    int e = errno;
    free(t->tmp);
    t->tmp = NULL;
    return cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", path, strerror(e));
  }
  plain_mode(fd); /* a writer that reuses the file (rcb_plots.py) keeps its mode */
  close(fd);
  t->slot[0] = cli_tmp_register(t->tmp);
  /* the library's own temporary beside it: "<name>.tmp000", ours as its name is unique */
  strcat(t->tmp, ".tmp000");
  t->slot[1] = cli_tmp_register(t->tmp);
  t->tmp[strlen(t->tmp) - 7] = '\0';
  t->write_path = t->tmp;
  return 0;
}

int cli_tmpfile_close(cli_tmpfile *t, int ok) {
  int rc = 0;
  if (t->tmp && ok && rename(t->tmp, t->path) != 0)
    rc = cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", t->path, strerror(errno));
  if (t->tmp && (!ok || rc)) remove(t->tmp);
  cli_tmp_release(t->slot[0]);
  cli_tmp_release(t->slot[1]);
  free(t->tmp);
  memset(t, 0, sizeof *t);
  t->slot[0] = t->slot[1] = -1;
  return rc;
}

/* Bytes of one number as text: "-1.2345678901234567e-100" (24) and a separator. */
#define CLI_BYTES_PER_NUMBER 25.0

int cli_check_size(const cli_args *a, double rows, double numbers) {
  double limit = a->max_output_mb > 0 ? a->max_output_mb : CLI_MAX_OUTPUT_MB;
  double mb = rows * numbers * CLI_BYTES_PER_NUMBER / 1e6;
  if (mb <= limit) return 0;
  return cli_usage(a->cmd, "the output would be about %.3g MB (%.3g rows x %.3g numbers, ~%g "
                   "bytes each), above the limit of %g MB; use fewer points or channels, or "
                   "raise the limit with --max-output MB",
                   mb, rows, numbers, CLI_BYTES_PER_NUMBER, limit);
}

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
  o->slot = -1;
  if (!a->output || strcmp(a->output, "-") == 0) {
    o->fp = stdout;
    return 0;
  }
  if (same_file(a->output, a->model))
    return cli_fail(CLI_EXIT_IO, "refusing to write the output over the model file '%s'",
                    a->model);
  if (cli_output_check(a->output)) return CLI_EXIT_IO;
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
  o->slot = cli_tmp_register(o->tmp);
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
  cli_tmp_release(o->slot);
  memset(o, 0, sizeof *o);
  o->slot = -1;
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

int cli_out_flush(cli_out *o) {
  int e;
  if (!o->fp) return 0;
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
  return 0;
}

int cli_out_close(cli_out *o) {
  int e, rc = cli_out_flush(o);
  if (rc) return rc;
  if (o->tmp && rename(o->tmp, o->path) != 0) {
    e = errno;
    cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s", o->path, strerror(e));
    cli_out_abort(o);
    return CLI_EXIT_IO;
  }
  free(o->tmp);
  cli_tmp_release(o->slot);
  memset(o, 0, sizeof *o);
  o->slot = -1;
  return 0;
}

int cli_is_rotation(const char *channel) {
  const char *dot = strrchr(channel, '.');
  return dot && (strcmp(dot, ".rx") == 0 || strcmp(dot, ".ry") == 0);
}

const char *cli_channel_unit(const char *resp, const char *ref, int kind, char *buf,
                             size_t size) {
  static const char *const per[3] = {"", " s", " s^2"}; /* receptance, mobility, inertance */
  const char *num = cli_is_rotation(resp) ? "rad" : "m";
  char den[32];
  if (!ref) {
    snprintf(buf, size, "%s", num);
    return buf;
  }
  snprintf(den, sizeof den, "%s%s", cli_is_rotation(ref) ? "N m" : "N",
           per[kind >= 0 && kind < 3 ? kind : 0]);
  snprintf(buf, size, strchr(den, ' ') ? "%s/(%s)" : "%s/%s", num, den);
  return buf;
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
  if (!p->on || done <= p->shown) return; /* a count that only rises */
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
