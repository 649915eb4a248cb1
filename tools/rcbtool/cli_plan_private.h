/* rcbtool: what the two files of the plan module share (cli_plan.c keeps the
 * plan, cli_plan_open.c opens its outputs). Included by those two only: a
 * command opens files through cli_out_open / cli_tmpfile_open (cli.h). */
#ifndef RCBTOOL_CLI_PLAN_PRIVATE_H
#define RCBTOOL_CLI_PLAN_PRIVATE_H

/** 0 if @p path is a declared output (the plan checked), else exit 5 (an
 * internal error: a command opened a file it never declared). */
int cli_plan_declared(const char *path);
/** Hand the temporary @p tmp (malloc'd, taken over) of output @p path, slot
 * @p slot of the signal handler's list, to the commit; 0, or -1 out of memory. */
int cli_plan_pend(char *tmp, const char *path, int slot);

#endif /* RCBTOOL_CLI_PLAN_PRIVATE_H */
