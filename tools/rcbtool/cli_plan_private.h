/* rcbtool: what the files of the plan module share (cli_plan.c keeps the plan,
 * cli_plan_open.c opens its outputs, cli_plan_lock.c locks the files it reads
 * and rewrites). Included by those three only: a command opens files through
 * cli_out_open / cli_tmpfile_open (cli.h). */
#ifndef RCBTOOL_CLI_PLAN_PRIVATE_H
#define RCBTOOL_CLI_PLAN_PRIVATE_H

/** 0 if @p path is a declared output (the plan checked), else exit 5 (an
 * internal error: a command opened a file it never declared). */
int cli_plan_declared(const char *path);
/** Hand the temporary @p tmp (malloc'd, taken over) of output @p path, slot
 * @p slot of the signal handler's list, to the commit; 0, or -1 out of memory. */
int cli_plan_pend(char *tmp, const char *path, int slot);

/** Lock the file @p path (@p what: "--history", ...) that this run reads and
 * replaces, waiting up to RCB_LOCK_WAIT seconds for another run holding it
 * (cli_plan_lock.c). 0 with the lock held (*lockpath malloc'd, *fd, *slot; *fd
 * -1 when nothing needs a lock: a device), else the message and exit 6 (held),
 * 2 (a bad RCB_LOCK_WAIT), 4 or 5. */
int cli_plan_lock(const char *path, const char *what, char **lockpath, int *fd, int *slot);
/** Release a lock of cli_plan_lock (nothing when @p fd < 0); frees @p lockpath. */
void cli_plan_unlock(char *lockpath, int fd, int slot);

#endif /* RCBTOOL_CLI_PLAN_PRIVATE_H */
