/* rcbtool: command-line front end of librcb (lateral rotordynamics of
 * rotor-coupling-bearing systems). Dispatches to one file per subcommand. */
#include <stdio.h>
#include <string.h>

#include "cli.h"

static const cli_command commands[] = {
    {"check", "validate a model, print its node/DOF and station tables", cli_help_check,
     cmd_check},
    {"matrices", "global M, C, G, K matrices at a speed", cli_help_matrices, cmd_matrices},
    {"frf", "frequency response functions between channels", cli_help_frf, cmd_frf},
    {"unbalance", "steady unbalance response over a speed range", cli_help_unbalance,
     cmd_unbalance},
    {"modes", "damped natural frequencies, damping and whirl at a speed", cli_help_modes,
     cmd_modes},
    {"campbell", "Campbell diagram data and 1X critical speeds", cli_help_campbell,
     cmd_campbell},
    {"simulate", "synthetic measurements (FRF or unbalance, eq. 19 noise) as UFF58/CSV",
     cli_help_simulate, cmd_simulate},
    {"estimate", "FRFs with coherence and standard deviations from sampled signals (Welch)",
     cli_help_estimate, cmd_estimate},
    {"order", "1X/2X unbalance responses per speed from run-up signals with a keyphasor",
     cli_help_order, cmd_order},
    {"convert", "measurements between UFF58 (ASCII/binary) and CSV, and between kinds",
     cli_help_convert, cmd_convert},
    {"fit", "fit model parameters to a measurement, with uncertainty", cli_help_fit,
     cmd_fit},
    {"sensitivity", "rank measurement channels by sensitivity to parameters",
     cli_help_sensitivity, cmd_sensitivity},
    {"compare", "where the model fails: errors per channel and band, peaks vs modes, plots",
     cli_help_compare, cmd_compare},
    {"diagnose", "which physical effect is missing, and where; --apply adds it (fitted)",
     cli_help_diagnose, cmd_diagnose},
    {"plan", "which added channel (or speed) would tell two rival effects apart",
     cli_help_plan, cmd_plan},
    {"history", "the steps of a session (fit, diagnose, apply) and the error falling",
     cli_help_history, cmd_history},
    {"monitor", "condition monitoring of a series of measurements: alarms, effect, trend",
     cli_help_monitor, cmd_monitor},
    {"transient", "time histories: constant speed, run-up, coast-down (SUNDIALS)",
     cli_help_transient, cmd_transient},
    {"timecheck", "unbalance response: frequency domain vs time integration, per speed",
     cli_help_timecheck, cmd_timecheck},
};
#define N_COMMANDS (sizeof commands / sizeof commands[0])

static const cli_command *find_command(const char *name) {
  size_t i;
  for (i = 0; i < N_COMMANDS; i++)
    if (strcmp(commands[i].name, name) == 0) return &commands[i];
  return NULL;
}

static void print_usage(FILE *fp) {
  size_t i;
  fputs("usage: rcbtool <command> MODEL.ini [options]\n"
        "       rcbtool help [command]\n"
        "       rcbtool --version\n\n"
        "Commands:\n",
        fp);
  for (i = 0; i < N_COMMANDS; i++)
    fprintf(fp, "  %-12s %s\n", commands[i].name, commands[i].summary);
  fputs("\nCommon options: --json (JSON instead of CSV), -o FILE (write FILE atomically),\n"
        "--progress (progress line on stderr), --help.\n"
        "Speeds are in rpm and frequencies in Hz on the command line.\n"
        "Exit codes: 0 ok, 2 usage error, 3 bad input (model or data),\n"
        "4 numerical failure, 5 output I/O error, 6 a file the run reads and rewrites\n"
        "(--history, --state) is being updated by another run (RCB_LOCK_WAIT=SECONDS,\n"
        "default 10, is how long a run waits for it).\n",
        fp);
}

static int cmd_help(int argc, char **argv) {
  const cli_command *c;
  if (argc < 2) {
    print_usage(stdout);
    return cli_print_help("");
  }
  c = find_command(argv[1]);
  if (!c) return cli_usage(NULL, "unknown command '%s'", argv[1]);
  return cli_print_help(c->help);
}

static int print_version(void) {
  printf("rcbtool %d.%d.%d (librcb %s)\n", RCB_VERSION_MAJOR, RCB_VERSION_MINOR,
         RCB_VERSION_PATCH, rcb_version_string());
  return cli_print_help("");
}

int main(int argc, char **argv) {
  const cli_command *c;
  cli_signals_install();
  if (argc < 2) {
    print_usage(stderr);
    return CLI_EXIT_USAGE;
  }
  if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "-V") == 0) return print_version();
  if (strcmp(argv[1], "help") == 0 || strcmp(argv[1], "--help") == 0 ||
      strcmp(argv[1], "-h") == 0)
    return cmd_help(argc - 1, argv + 1);
  c = find_command(argv[1]);
  if (!c) {
    char list[256] = "";
    size_t i, n = 0;
    for (i = 0; i < N_COMMANDS && n < sizeof list; i++)
      n += (size_t)snprintf(list + n, sizeof list - n, "%s, ", commands[i].name);
    return cli_usage(NULL, "unknown command '%s'; expected one of %shelp", argv[1], list);
  }
  cli_plan_begin(c->help);
  return cli_plan_finish(c->run(argc - 1, argv + 1));
}
