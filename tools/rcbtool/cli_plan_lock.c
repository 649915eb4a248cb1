/* rcbtool: one writer at a time for a file a run reads and replaces (issue #34
 * item 6).
 *
 * A file declared both input and output (CLI_IO_INOUT: a --history, the
 * monitor's --state) is read, then replaced by the rename of a temporary. Two
 * runs on it at once would both read the old content and the second rename
 * would drop the first run's update without a word. cli_plan_check therefore
 * takes a lock for each such file, before the verb reads it, and
 * cli_plan_finish releases it after the renames: the whole read-modify-write is
 * one step for every other run.
 *
 * The lock is an fcntl write lock on "<file>.lock" beside the file, not on the
 * file itself: the rename replaces the file's inode, and a lock on the old
 * inode would let the next run in while the rename is still to come. The
 * holder removes the lock file before it lets go (so no .lock is left behind);
 * a run that got its lock on a lock file already removed sees that the name no
 * longer leads to its inode and tries again. A run that finds the lock held
 * polls for RCB_LOCK_WAIT seconds (default 10), then gives up with exit 6,
 * naming the file and the process that holds it. */
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "cli_plan_private.h"

#define LOCK_WAIT_DEFAULT 10.0 /* s: longer than a usual fit or monitor update */
#define LOCK_WAIT_MAX 86400.0  /* s: a day; a larger value is a typing error */
#define LOCK_POLL_NS 20000000L /* 20 ms between tries: 500 a waited 10 s */

/* RCB_LOCK_WAIT in seconds (default LOCK_WAIT_DEFAULT), or -1 when it holds
 * no number in [0, LOCK_WAIT_MAX]. */
static double lock_wait(void) {
  const char *s = getenv("RCB_LOCK_WAIT");
  char *end;
  double w;
  if (!s || !*s) return LOCK_WAIT_DEFAULT;
  w = strtod(s, &end);
  if (end == s || *end != '\0' || !(w >= 0 && w <= LOCK_WAIT_MAX)) return -1;
  return w;
}

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* 1 when @p fd is still the file named @p lock (no holder before us removed it). */
static int still_named(int fd, const char *lock) {
  struct stat a, b;
  return fstat(fd, &a) == 0 && stat(lock, &b) == 0 && a.st_dev == b.st_dev &&
         a.st_ino == b.st_ino;
}

/* The process holding @p fd's lock (0 if unknown: gone meanwhile, or a
 * network file system that does not say). */
static long holder_of(int fd) {
  struct flock fl;
  memset(&fl, 0, sizeof fl);
  fl.l_type = F_WRLCK;
  fl.l_whence = SEEK_SET;
  if (fcntl(fd, F_GETLK, &fl) != 0 || fl.l_type == F_UNLCK) return 0;
  return (long)fl.l_pid;
}

static int refuse_busy(const char *path, const char *what, const char *lock, long pid,
                       double wait) {
  char who[64] = "another run";
  if (pid > 0) snprintf(who, sizeof who, "another run (process %ld)", pid);
  return cli_fail(CLI_EXIT_LOCKED, "the %s file '%s' is being updated by %s, which holds "
                  "'%s'; waited %g s, nothing was read or written. Run again when it has "
                  "finished (RCB_LOCK_WAIT=SECONDS sets the wait)", what, path, who, lock,
                  wait);
}

/* One try at the lock on @p fd: 1 taken, 0 held by another run, -1 an error
 * (errno). */
static int try_lock(int fd) {
  struct flock fl;
  memset(&fl, 0, sizeof fl);
  fl.l_type = F_WRLCK;
  fl.l_whence = SEEK_SET; /* l_start = l_len = 0: the whole file */
  if (fcntl(fd, F_SETLK, &fl) == 0) return 1;
  return errno == EACCES || errno == EAGAIN ? 0 : -1;
}

int cli_plan_lock(const char *path, const char *what, char **lockpath, int *fd, int *slot) {
  struct stat st;
  double wait = lock_wait(), deadline;
  char *lock;
  int k;
  *lockpath = NULL;
  *fd = *slot = -1;
  if (wait < 0)
    return cli_fail(CLI_EXIT_USAGE, "RCB_LOCK_WAIT='%s': expected the seconds to wait for "
                    "a file another run is updating, a number from 0 to %g",
                    getenv("RCB_LOCK_WAIT"), LOCK_WAIT_MAX);
  if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) return 0; /* a device: written in place */
  if (!(lock = malloc(strlen(path) + sizeof ".lock")))
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(lock, path);
  strcat(lock, ".lock");
  deadline = now_s() + wait;
  for (;;) {
    if (*fd < 0 && (*fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0666)) < 0) {
      int e = errno;
      int rc = cli_fail(cli_errno_exit(e), "cannot lock the %s file '%s': cannot open '%s': "
                        "%s", what, path, lock, strerror(e));
      free(lock);
      return rc;
    }
    if ((k = try_lock(*fd)) > 0) {
      if (still_named(*fd, lock)) break;
      close(*fd); /* the holder before us removed it: lock the one named now */
      *fd = -1;
      continue;
    }
    if (k < 0 || now_s() >= deadline) {
      int e = errno;
      long pid = k < 0 ? 0 : holder_of(*fd);
      int rc = k < 0 ? cli_fail(CLI_EXIT_IO, "cannot lock the %s file '%s' (with '%s'): %s; "
                                "refusing to update it unguarded", what, path, lock,
                                strerror(e))
                     : refuse_busy(path, what, lock, pid, wait);
      close(*fd);
      *fd = -1;
      free(lock);
      return rc;
    }
    {
      struct timespec t = {0, LOCK_POLL_NS};
      nanosleep(&t, NULL);
    }
  }
  *lockpath = lock;
  *slot = cli_tmp_register(lock); /* a signal removes it as it removes the temporaries */
  return 0;
}

void cli_plan_unlock(char *lockpath, int fd, int slot) {
  if (fd < 0) return;
  /* removed while still held: a run waiting on this inode then sees it unnamed */
  unlink(lockpath);
  cli_tmp_release(slot);
  close(fd);
  free(lockpath);
}
