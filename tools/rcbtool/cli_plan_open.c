/* rcbtool: opening the outputs of a run, only through its plan (cli_plan.c).
 *
 * cli_out_open (a stream: -o and the side files written with fprintf) and
 * cli_tmpfile_open (a path for a writer of its own: the library's measurement
 * writers, the plotting script) refuse a path the plan does not hold; each
 * makes a temporary beside its output (mkstemp, on the signal handler's list)
 * and, when closed after a good write, hands it to the plan, which renames all
 * of them when the run succeeded. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "cli_plan_private.h"

/* ---- opening outputs (only through the plan) ---- */

/* The temporary file gets the mode a plain fopen would have given (0666 & ~umask). */
static void plain_mode(int fd) {
  mode_t mask = umask(0);
  umask(mask);
  (void)fchmod(fd, (mode_t)(0666 & ~mask));
}

int cli_tmpfile_open(cli_tmpfile *t, const char *path) {
  struct stat st;
  int fd, rc;
  memset(t, 0, sizeof *t);
  t->path = t->write_path = path;
  t->slot[0] = t->slot[1] = -1;
  if ((rc = cli_plan_declared(path))) return rc;
  /* a device or pipe is written in place (a rename would replace it) */
  if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) return 0;
  if (!(t->tmp = malloc(strlen(path) + sizeof ".XXXXXX.tmp000")))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(t->tmp, path);
  strcat(t->tmp, ".XXXXXX");
  if ((fd = cli_mkstemp(t->tmp, &t->slot[0])) < 0) {
    int e = errno;
    free(t->tmp);
    t->tmp = NULL;
    return cli_fail(cli_errno_exit(e), "cannot write output file '%s': %s", path, strerror(e));
  }
  plain_mode(fd); /* a writer that reuses the file (rcb_plots.py) keeps its mode */
  close(fd);
  /* the library's own temporary beside it: "<name>.tmp000", ours as its name is unique */
  strcat(t->tmp, ".tmp000");
  t->slot[1] = cli_tmp_register(t->tmp);
  t->tmp[strlen(t->tmp) - 7] = '\0';
  t->write_path = t->tmp;
  return 0;
}

int cli_tmpfile_close(cli_tmpfile *t, int ok) {
  int rc = 0;
  cli_tmp_release(t->slot[1]);
  if (t->tmp && ok && cli_plan_pend(t->tmp, t->path, t->slot[0]) == 0) {
    t->tmp = NULL; /* the plan owns it now: renamed when the run succeeded */
    t->slot[0] = -1;
  } else if (t->tmp && ok) {
    rc = cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  if (t->tmp) remove(t->tmp);
  cli_tmp_release(t->slot[0]);
  free(t->tmp);
  memset(t, 0, sizeof *t);
  t->slot[0] = t->slot[1] = -1;
  return rc;
}

/* An existing device or pipe (e.g. /dev/stdout) is written in place: a rename
 * would replace the device node by a plain file. */
static int open_special(cli_out *o, const char *path) {
  o->path = path;
  o->fp = fopen(path, "w");
  if (!o->fp)
    return cli_fail(cli_errno_exit(errno), "cannot write output file '%s': %s", path,
                    strerror(errno));
  return 0;
}

int cli_out_open(cli_out *o, const cli_args *a) {
  struct stat st;
  int fd, rc;
  memset(o, 0, sizeof *o);
  o->slot = -1;
  if (!a->output || strcmp(a->output, "-") == 0) {
    o->fp = stdout;
    return 0;
  }
  if ((rc = cli_plan_declared(a->output))) return rc;
  if (stat(a->output, &st) == 0 && !S_ISREG(st.st_mode)) return open_special(o, a->output);
  o->path = a->output;
  o->tmp = malloc(strlen(a->output) + sizeof ".XXXXXX");
  if (!o->tmp) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(o->tmp, a->output);
  strcat(o->tmp, ".XXXXXX");
  fd = cli_mkstemp(o->tmp, &o->slot); /* same directory, so the final rename is atomic */
  if (fd < 0) {
    int e = errno;
    free(o->tmp);
    o->tmp = NULL;
    return cli_fail(cli_errno_exit(e), "cannot write output file '%s': %s", a->output,
                    strerror(e));
  }
  plain_mode(fd);
  o->fp = fdopen(fd, "w");
  if (!o->fp) {
    int e = errno;
    close(fd);
    cli_out_abort(o);
    return cli_fail(cli_errno_exit(e), "cannot write output file '%s': %s", a->output,
                    strerror(e));
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
    cli_out_abort(o);
    return cli_fail(cli_errno_exit(e), "cannot write output file '%s': %s", o->path,
                    strerror(e));
  }
  o->fp = NULL;
  return 0;
}

int cli_out_close(cli_out *o) {
  int rc = cli_out_flush(o);
  if (rc) return rc;
  if (o->tmp) {
    if (cli_plan_pend(o->tmp, o->path, o->slot) != 0) {
      cli_out_abort(o);
      return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
    }
    o->tmp = NULL; /* renamed by cli_plan_finish when the run succeeded */
    o->slot = -1;
  }
  memset(o, 0, sizeof *o);
  o->slot = -1;
  return 0;
}

void cli_path_subst(const char *msg, const char *tmp, const char *path, char *buf,
                    size_t size) {
  size_t n = 0, lt = strlen(tmp), lp = strlen(path);
  buf[0] = '\0';
  while (*msg && n + 1 < size) {
    /* the library's own temporary ("<tmp>.tmp000") is named as the output too */
    if (lt && strncmp(msg, tmp, lt) == 0) {
      msg += lt;
      if (strncmp(msg, ".tmp000", 7) == 0) msg += 7;
      if (n + lp >= size) break;
      memcpy(buf + n, path, lp);
      n += lp;
      continue;
    }
    buf[n++] = *msg++;
  }
  buf[n] = '\0';
}
