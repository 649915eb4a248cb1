/* rcbtool: the run's input/output plan (issue #26).
 *
 * Every verb declares its inputs and outputs before anything is read or
 * written: cli_parse declares the positional argument, -o and every option
 * whose cli_opt.io says it is a file; a verb declares what only it knows
 * (a measurement, a series of files, a derived name). One check, cli_plan_check,
 * refuses any output that is an input (device and inode: a symbolic link, a hard
 * link or another spelling is the same file), two outputs that are one file,
 * an output that is a directory, and an output whose directory is missing or
 * not writable. Outputs are opened only through the plan (cli_plan_open.c:
 * cli_out_open, cli_tmpfile_open refuse a path the plan does not hold), each
 * written to a temporary in its own directory; cli_plan_finish renames them all after the verb succeeded and
 * removes them all otherwise; a signal removes them all too. A file both read
 * and rewritten (CLI_IO_INOUT) is locked by the check, before the verb reads
 * it, until after the renames (cli_plan_lock.c): one writer at a time. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "cli_plan_private.h"

/* One declared file. */
typedef struct plan_file {
  char *path;    /* as given */
  char *what;    /* "model", "signals", "-o", "--stats", ... */
  unsigned io;   /* CLI_IO_IN | CLI_IO_OUT | CLI_IO_MKDIR */
  int checked;   /* an output that passed cli_plan_check */
  char *lock;    /* CLI_IO_INOUT: the lock file held (cli_plan_lock.c), NULL when none */
  int lockfd, lockslot;
} plan_file;

/* A temporary written and closed, renamed onto its output when the run succeeded. */
typedef struct plan_pending {
  char *tmp, *path;
  int slot;
} plan_pending;

static struct {
  char positional[32]; /* what the first positional argument is ("model", "signals") */
  const cli_file_opt *opts; /* the verb's file options */
  size_t nopts;
  plan_file *f;
  size_t n, cap;
  plan_pending *p;
  size_t np, capp;
  int nomem; /* a declaration was lost to an allocation failure */
} plan;

/* ---- temporary files removed on SIGINT, SIGTERM, SIGHUP ---- */

#define CLI_TMP_SLOTS 64
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

/* SIGINT, SIGTERM, SIGHUP held (@p on) or restored: a file made and its entry on the
 * list, or all the renames, happen as one step for the signal handler. */
static void hold_signals(int on, sigset_t *old) {
  sigset_t block;
  sigemptyset(&block);
  sigaddset(&block, SIGINT);
  sigaddset(&block, SIGTERM);
  sigaddset(&block, SIGHUP);
  sigprocmask(on ? SIG_BLOCK : SIG_SETMASK, on ? &block : old, on ? old : NULL);
}

int cli_mkstemp(char *tmpl, int *slot) {
  sigset_t old;
  int fd, e;
  hold_signals(1, &old); /* a signal between mkstemp and the list would leave the file */
  fd = mkstemp(tmpl);
  e = errno;
  *slot = fd >= 0 ? cli_tmp_register(tmpl) : -1;
  hold_signals(0, &old);
  errno = e;
  return fd;
}

/* ---- declarations ---- */

static char *dup_str(const char *s) {
  char *d = malloc(strlen(s) + 1);
  if (d) strcpy(d, s);
  return d;
}

void cli_plan_begin(const char *help) {
  static const char usage[] = "usage: rcbtool ";
  const char *p = help;
  size_t n = 0;
  snprintf(plan.positional, sizeof plan.positional, "input");
  if (!help || strncmp(p, usage, sizeof usage - 1) != 0) return;
  p += sizeof usage - 1;
  p += strcspn(p, " \n");
  while (*p == ' ') p++;
  /* "MODEL.ini" -> "model", "SIGNALS" -> "signals"; "IN" and "FILE" stay "input" */
  if (strncmp(p, "IN ", 3) == 0 || strncmp(p, "FILE", 4) == 0) return;
  while (p[n] >= 'A' && p[n] <= 'Z' && n + 1 < sizeof plan.positional) {
    plan.positional[n] = (char)(p[n] - 'A' + 'a');
    n++;
  }
  if (n) plan.positional[n] = '\0';
}

static void declare(const char *path, const char *what, unsigned io) {
  size_t i;
  plan_file *f;
  if (!path || !*path || strcmp(path, "-") == 0) return;
  for (i = 0; i < plan.n; i++)
    if (strcmp(plan.f[i].path, path) == 0 && strcmp(plan.f[i].what, what) == 0) {
      plan.f[i].io |= io;
      return;
    }
  if (plan.n == plan.cap) {
    size_t cap = plan.cap ? 2 * plan.cap : 16;
    plan_file *nf = realloc(plan.f, cap * sizeof *nf);
    if (!nf) {
      plan.nomem = 1;
      return;
    }
    plan.f = nf;
    plan.cap = cap;
  }
  f = &plan.f[plan.n];
  memset(f, 0, sizeof *f);
  f->path = dup_str(path);
  f->what = dup_str(what);
  f->io = io;
  f->lockfd = f->lockslot = -1;
  if (!f->path || !f->what) {
    free(f->path);
    free(f->what);
    plan.nomem = 1;
    return;
  }
  plan.n++;
}

void cli_plan_input(const char *path, const char *what) { declare(path, what, CLI_IO_IN); }

void cli_plan_output(const char *path, const char *what, unsigned io) {
  declare(path, what, io | CLI_IO_OUT);
}

void cli_plan_options(const cli_file_opt *files, size_t n) {
  plan.opts = files;
  plan.nopts = n;
}

const char *cli_plan_positional(void) { return plan.positional[0] ? plan.positional : "input"; }

int cli_plan_args(const cli_args *a) {
  size_t i;
  cli_plan_input(a->model, plan.positional);
  for (i = 1; i < a->nfiles; i++) cli_plan_input(a->files[i], plan.positional);
  cli_plan_output(a->output, "-o", 0);
  for (i = 0; i < plan.nopts; i++)
    declare(cli_opt_value(a, plan.opts[i].name), plan.opts[i].name, plan.opts[i].io);
  return cli_plan_check();
}

/* ---- the check ---- */

/* "the signals file", "the --sd file", "-o" -> "the output (-o)". */
static void describe(const plan_file *f, char *buf, size_t size) {
  if (f->io & CLI_IO_OUT && !(f->io & CLI_IO_IN))
    snprintf(buf, size, "%s %s", f->what[0] == '-' ? "the output" : "the output file",
             f->what);
  else
    snprintf(buf, size, "the %s file", f->what);
}

/* The directory part of @p path ("." when none) in @p buf. */
static void dir_of(const char *path, char *buf, size_t size) {
  const char *slash = strrchr(path, '/');
  size_t n;
  if (!slash) {
    snprintf(buf, size, ".");
    return;
  }
  n = slash == path ? 1 : (size_t)(slash - path);
  if (n >= size) n = size - 1;
  memcpy(buf, path, n);
  buf[n] = '\0';
}

/* The path with its directory resolved (links, "./", "../"): two spellings of
 * one new file give one name. NULL when the directory does not exist yet. */
static char *canonical(const char *path) {
  char dir[PATH_MAX], real[PATH_MAX], *out;
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  dir_of(path, dir, sizeof dir);
  if (!realpath(dir, real)) return NULL;
  if (!(out = malloc(strlen(real) + strlen(base) + 2))) return NULL;
  sprintf(out, "%s/%s", strcmp(real, "/") == 0 ? "" : real, base);
  return out;
}

/* The nearest existing directory of @p path (for outputs whose directories are
 * made): must be writable. */
static int check_dir(const plan_file *o) {
  char dir[PATH_MAX], d[160];
  struct stat st;
  describe(o, d, sizeof d);
  dir_of(o->path, dir, sizeof dir);
  for (;;) {
    if (stat(dir, &st) == 0) {
      if (!S_ISDIR(st.st_mode))
        return cli_fail(CLI_EXIT_IO, "cannot write %s '%s': '%s' is not a directory", d,
                        o->path, dir);
      if (access(dir, W_OK | X_OK) != 0)
        return cli_fail(CLI_EXIT_IO, "cannot write %s '%s': the directory '%s' is not "
                        "writable: %s", d, o->path, dir, strerror(errno));
      return 0;
    }
    if (!(o->io & CLI_IO_MKDIR))
      return cli_fail(CLI_EXIT_IO, "cannot write %s '%s': the directory '%s' does not exist "
                      "(create it first, or choose another path)", d, o->path, dir);
    if (strcmp(dir, ".") == 0 || strcmp(dir, "/") == 0) return 0;
    {
      char up[PATH_MAX];
      dir_of(dir, up, sizeof up);
      strcpy(dir, up);
    }
  }
}

static int check_pair(const plan_file *o, const struct stat *so, const char *co,
                      const plan_file *g) {
  struct stat sg;
  char dg[160], d[160];
  int same = 0;
  if (stat(g->path, &sg) == 0 && so && so->st_dev == sg.st_dev && so->st_ino == sg.st_ino)
    same = 1;
  if (!same && co && (g->io & CLI_IO_OUT)) {
    char *cg = canonical(g->path);
    same = cg && strcmp(cg, co) == 0;
    free(cg);
  }
  if (!same) return 0;
  describe(o, d, sizeof d);
  describe(g, dg, sizeof dg);
  if (g->io & CLI_IO_IN)
    return cli_fail(CLI_EXIT_IO, "refusing to write %s '%s' over %s '%s', an input of this "
                    "run (the same file: a link or another spelling counts); choose another "
                    "name for %s", d, o->path, dg, g->path, o->what);
  /* two outputs: a device such as /dev/null may take both */
  if (so && !S_ISREG(so->st_mode)) return 0;
  return cli_fail(CLI_EXIT_IO, "refusing to write %s '%s' and %s '%s' to the same file; "
                  "give each output its own name", dg, g->path, d, o->path);
}

int cli_plan_check(void) {
  size_t i, k;
  int rc;
  if (plan.nomem) return cli_fail(CLI_EXIT_NUMERIC, "out of memory declaring the files of "
                                  "this run");
  for (i = 0; i < plan.n; i++) {
    plan_file *o = &plan.f[i];
    struct stat so, sl;
    int exists;
    char *co, d[160];
    if (!(o->io & CLI_IO_OUT)) continue;
    describe(o, d, sizeof d);
    exists = stat(o->path, &so) == 0;
    if (exists && S_ISDIR(so.st_mode))
      return cli_fail(CLI_EXIT_IO, "cannot write %s '%s': it is a directory", d, o->path);
    if (!exists && lstat(o->path, &sl) != 0 && (rc = check_dir(o))) return rc;
    if (exists && S_ISREG(so.st_mode) && (rc = check_dir(o))) return rc;
    co = canonical(o->path);
    for (k = 0; k < plan.n; k++) {
      if (k == i || (!(plan.f[k].io & CLI_IO_IN) && k < i)) continue;
      if ((rc = check_pair(o, exists ? &so : NULL, co, &plan.f[k]))) {
        free(co);
        return rc;
      }
    }
    free(co);
    o->checked = 1;
  }
  /* every check passed: a file read and rewritten is locked before it is read */
  for (i = 0; i < plan.n; i++) {
    plan_file *f = &plan.f[i];
    if ((f->io & CLI_IO_INOUT) == CLI_IO_INOUT && f->lockfd < 0 &&
        (rc = cli_plan_lock(f->path, f->what, &f->lock, &f->lockfd, &f->lockslot)))
      return rc;
  }
  return 0;
}

/* The declared output @p path, or an internal error (exit 5): a verb opened a
 * file it never declared. */
int cli_plan_declared(const char *path) {
  size_t i;
  for (i = 0; i < plan.n; i++)
    if ((plan.f[i].io & CLI_IO_OUT) && strcmp(plan.f[i].path, path) == 0) {
      if (!plan.f[i].checked && cli_plan_check()) return CLI_EXIT_IO;
      return 0;
    }
  return cli_fail(CLI_EXIT_IO, "internal error: the output '%s' is not in the run's plan "
                  "(every output is declared before the work; please report this)", path);
}

int cli_errno_exit(int e) { return e == ENOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_IO; }

/* ---- commits: all or nothing ---- */

int cli_plan_pend(char *tmp, const char *path, int slot) {
  plan_pending *p;
  if (plan.np == plan.capp) {
    size_t cap = plan.capp ? 2 * plan.capp : 8;
    plan_pending *np = realloc(plan.p, cap * sizeof *np);
    if (!np) return -1;
    plan.p = np;
    plan.capp = cap;
  }
  p = &plan.p[plan.np];
  if (!(p->path = dup_str(path))) return -1;
  p->tmp = tmp;
  p->slot = slot;
  plan.np++;
  return 0;
}

int cli_plan_adopt(const char *tmp, const char *path) {
  char *copy;
  int rc, slot;
  if ((rc = cli_plan_declared(path))) return rc;
  if (!(copy = dup_str(tmp))) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  slot = cli_tmp_register(copy);
  if (cli_plan_pend(copy, path, slot) != 0) {
    cli_tmp_release(slot);
    free(copy);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  return 0;
}

/* fsync the directory of path (best effort): a rename in it is then on the
 * disk, so a power cut after the run leaves the new file, not the old one
 * (the monitor's --state relies on it). */
static void sync_dir(const char *path) {
  const char *slash = strrchr(path, '/');
  char *dir = NULL;
  int fd;
  if (slash && !(dir = malloc((size_t)(slash - path) + 2))) return;
  if (dir) {
    memcpy(dir, path, (size_t)(slash - path) + 1);
    dir[slash - path + 1] = '\0';
  }
  fd = open(dir ? dir : ".", O_RDONLY);
  free(dir);
  if (fd < 0) return;
  (void)fsync(fd);
  close(fd);
}

int cli_plan_finish(int rc) {
  size_t i, done = 0;
  sigset_t old;
  /* the renames run with SIGINT, SIGTERM and SIGHUP held: a signal then ends the
   * process after every output was renamed, never between two of them */
  hold_signals(1, &old);
  for (i = 0; i < plan.np && !rc; i++, done++)
    if (rename(plan.p[i].tmp, plan.p[i].path) != 0) {
      int e = errno;
      rc = cli_fail(CLI_EXIT_IO, "cannot write output file '%s': %s%s", plan.p[i].path,
                    strerror(e), i ? " (the outputs before it were written)" : "");
    }
  for (i = 0; i < done; i++) sync_dir(plan.p[i].path);
  for (i = 0; i < plan.np; i++) {
    if (i >= done) remove(plan.p[i].tmp);
    cli_tmp_release(plan.p[i].slot);
    free(plan.p[i].tmp);
    free(plan.p[i].path);
  }
  plan.np = 0;
  /* the locks last: another run reads a file only once this run's rename is done */
  for (i = 0; i < plan.n; i++) {
    cli_plan_unlock(plan.f[i].lock, plan.f[i].lockfd, plan.f[i].lockslot);
    plan.f[i].lock = NULL;
    plan.f[i].lockfd = plan.f[i].lockslot = -1;
  }
  /* a temporary a command made and neither committed nor removed (a path that
   * forgot its abort) is removed here, as a signal would */
  for (i = 0; i < CLI_TMP_SLOTS; i++)
    if (tmp_live[i]) {
      unlink(tmp_paths[i]);
      tmp_live[i] = 0;
    }
  hold_signals(0, &old);
  return rc;
}
