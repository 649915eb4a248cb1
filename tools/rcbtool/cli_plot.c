/* --plot of compare, estimate, order and monitor: the plotting script
 * tools/python/rcb_plots.py (installed to share/rcb) run on our JSON. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cli.h"

/* rcb_plots.py: $RCB_PLOTS, next to rcbtool, <prefix>/share/rcb, or the
 * source tree this rcbtool was built from. */
static int find_plots_script(char *buf, size_t size) {
  const char *env = getenv("RCB_PLOTS");
  char exe[4096];
  ssize_t len;
  const char *rel[] = {"/rcb_plots.py", "/../share/rcb/rcb_plots.py"};
  size_t i;
  if (env && *env) {
    snprintf(buf, size, "%s", env);
    return access(buf, R_OK) == 0 ? 0 : -1;
  }
  len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (len > 0) {
    char *slash;
    exe[len] = '\0';
    slash = strrchr(exe, '/');
    if (slash) *slash = '\0';
    for (i = 0; i < sizeof rel / sizeof rel[0]; i++) {
      int w = snprintf(buf, size, "%s%s", exe, rel[i]);
      if (w > 0 && (size_t)w < size && access(buf, R_OK) == 0) return 0;
    }
  }
#ifdef RCBTOOL_SOURCE_PLOTS
  snprintf(buf, size, "%s", RCBTOOL_SOURCE_PLOTS);
  if (access(buf, R_OK) == 0) return 0;
#endif
  snprintf(buf, size, "rcb_plots.py");
  return -1;
}

/* --plot PREFIX: the directories of PREFIX are made when missing (mkdir -p), so
 * `--plot out/walk` runs in a fresh clone (issue #17). */
int cli_plot_mkdir(const char *prefix) {
  char *dir = malloc(strlen(prefix) + 1), *p;
  struct stat sb;
  int rc = 0;
  if (!dir) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  strcpy(dir, prefix);
  p = strrchr(dir, '/');
  if (!p || p == dir) {
    free(dir);
    return 0; /* the current or the root directory */
  }
  *p = '\0';
  for (p = dir + 1; !rc; p++) {
    char c = *p;
    if (c != '/' && c != '\0') continue;
    *p = '\0';
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
      rc = cli_fail(CLI_EXIT_IO, "--plot %s: cannot create the directory '%s': %s", prefix,
                    dir, strerror(errno));
    else if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode))
      rc = cli_fail(CLI_EXIT_IO, "--plot %s: '%s' is not a directory", prefix, dir);
    *p = c;
    if (c == '\0') break;
  }
  free(dir);
  return rc;
}

int cli_plot_run(const char *kind, const char *json, const char *out, const char *format,
                 const char *kept) {
  const char *py = getenv("RCB_PYTHON");
  char script[4096];
  pid_t pid;
  int status = 0;
  if (!py || !*py) py = "python3";
  if (find_plots_script(script, sizeof script))
    return cli_fail(CLI_EXIT_IO, "--plot: cannot find the plotting script %s (set RCB_PLOTS "
                    "to the path of tools/python/rcb_plots.py); %s", script, kept);
  fflush(stdout);
  fflush(stderr);
  pid = fork();
  if (pid < 0) return cli_fail(CLI_EXIT_IO, "--plot: fork failed: %s", strerror(errno));
  if (pid == 0) {
    execlp(py, py, script, kind, json, out, format, (char *)NULL);
    fprintf(stderr, "rcbtool: --plot: cannot run Python '%s': %s (install Python 3 with "
            "matplotlib, or set RCB_PYTHON to such an interpreter)\n", py, strerror(errno));
    _exit(127);
  }
  if (waitpid(pid, &status, 0) < 0)
    return cli_fail(CLI_EXIT_IO, "--plot: waiting for Python failed: %s", strerror(errno));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return 0;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3)
    return cli_fail(CLI_EXIT_IO, "--plot: Python '%s' has no matplotlib (pip install "
                    "matplotlib, or set RCB_PYTHON to an interpreter that has it); %s", py,
                    kept);
  return cli_fail(CLI_EXIT_IO, "--plot: the plotting script failed (%s %s); %s", py, script,
                  kept);
}


int cli_plot_write(const char *kind, const char *png, cli_plot_json_fn json, const void *ctx,
                   const char *kept) {
  cli_tmpfile jt, pt;
  FILE *fp;
  int rc;
  if ((rc = cli_plot_mkdir(png)) || (rc = cli_tmpfile_open(&jt, png))) return rc;
  if (!(fp = fopen(jt.write_path, "w"))) {
    rc = cli_fail(CLI_EXIT_IO, "--plot %s: cannot write its data file: %s", png,
                  strerror(errno));
    cli_tmpfile_close(&jt, 0);
    return rc;
  }
  json(fp, ctx);
  errno = 0;
  if (ferror(fp) || fclose(fp) != 0) {
    int e = errno ? errno : EIO;
    cli_tmpfile_close(&jt, 0);
    return cli_fail(cli_errno_exit(e), "--plot %s: cannot write its data file: %s", png,
                    strerror(e));
  }
  if ((rc = cli_tmpfile_open(&pt, png))) {
    cli_tmpfile_close(&jt, 0);
    return rc;
  }
  rc = cli_plot_run(kind, jt.write_path, pt.write_path, NULL, kept);
  cli_tmpfile_close(&jt, 0); /* the data file is not kept */
  if (cli_tmpfile_close(&pt, rc == 0) && !rc) rc = CLI_EXIT_IO;
  return rc;
}
