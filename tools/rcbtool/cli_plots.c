/* rcbtool: pictures through tools/python/rcb_plots.py (matplotlib), run as a
 * child process (compare --plot, monitor --plot). */
#include <errno.h>
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

int cli_plot_dir(const char *prefix) {
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

int cli_run_plotter(const char *what, const char *json, const char *out, const char *format,
                    const char *nothing_kept) {
  const char *py = getenv("RCB_PYTHON");
  char script[4096];
  pid_t pid;
  int status = 0;
  if (!py || !*py) py = "python3";
  if (find_plots_script(script, sizeof script))
    return cli_fail(CLI_EXIT_IO, "--plot: cannot find the plotting script %s (set RCB_PLOTS "
                    "to the path of tools/python/rcb_plots.py); %s", script, nothing_kept);
  fflush(stdout);
  fflush(stderr);
  pid = fork();
  if (pid < 0) return cli_fail(CLI_EXIT_IO, "--plot: fork failed: %s", strerror(errno));
  if (pid == 0) {
    execlp(py, py, script, what, json, out, format, (char *)NULL);
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
                    nothing_kept);
  return cli_fail(CLI_EXIT_IO, "--plot: the plotting script failed (%s %s); %s", py, script,
                  nothing_kept);
}
