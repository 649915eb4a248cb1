/*
 * The options of a measurement-like sweep, shared by `simulate` and
 * `sensitivity`: either FRFs over a frequency band at one rotor speed
 * (--frf: --in, --fmin/--fmax in Hz, --rpm, --kind) or an unbalance response
 * over a speed range (--unbalance: --rpm-min/--rpm-max in rpm).
 */
#include "cli.h"

const char *const cli_kind_names[3] = {"receptance", "mobility", "inertance"};

int cli_sweep_frf(const cli_args *a, const char *in_what, double *fmin_hz, double *fmax_hz,
                  double *rpm, int *kind) {
  int rc;
  if (cli_opt_value(a, "--rpm-min") || cli_opt_value(a, "--rpm-max"))
    return cli_usage(a->cmd, "--rpm-min/--rpm-max belong to --unbalance; for --frf give "
                     "--fmin/--fmax (Hz) and --rpm");
  if ((rc = cli_opt_require(a, "--in", in_what)) ||
      (rc = cli_opt_require(a, "--fmax", "the last frequency in Hz")) ||
      (rc = cli_opt_nonneg(a, "--fmin", "Hz", 0.0, fmin_hz)) ||
      (rc = cli_opt_nonneg(a, "--fmax", "Hz", 0.0, fmax_hz)) ||
      (rc = cli_opt_nonneg(a, "--rpm", "rotor speed, rpm", 0.0, rpm)) ||
      (rc = cli_opt_choice(a, "--kind", cli_kind_names, 3, RCB_RECEPTANCE, kind)))
    return rc;
  return 0;
}

int cli_sweep_unbalance(const cli_args *a, const char *frf_only, double *rpm_min,
                        double *rpm_max) {
  int rc;
  if (cli_opt_value(a, "--in") || cli_opt_value(a, "--fmin") || cli_opt_value(a, "--fmax") ||
      cli_opt_value(a, "--rpm") || cli_opt_value(a, "--synchronous") ||
      cli_opt_value(a, "--kind"))
    return cli_usage(a->cmd, "%s", frf_only);
  if ((rc = cli_opt_require(a, "--rpm-max", "the highest rotor speed in rpm")) ||
      (rc = cli_opt_nonneg(a, "--rpm-min", "rpm", 0.0, rpm_min)) ||
      (rc = cli_opt_nonneg(a, "--rpm-max", "rpm", 0.0, rpm_max)))
    return rc;
  return 0;
}
