/* rcbtool convert: measurements between UFF dataset 58 (ASCII/binary) and CSV,
 * and between receptance, mobility and inertance. Also the UFF node-map and
 * file-format helpers shared with rcbtool simulate. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

const char cli_help_convert[] =
    "usage: rcbtool convert IN OUT [--map NODE=STATION,...] [--kind K] [--binary]\n"
    "\n"
    "Reads a measurement (UFF dataset 58 / 58b, or CSV) and writes it again in the\n"
    "format given by OUT's extension: .uff, .unv or .uf for UFF dataset 58 (ASCII,\n"
    "or binary 58b with --binary), .csv for CSV. The output is written atomically.\n"
    "  --map LIST   UFF node number <-> model station, e.g. 10=DA,20=C.A; a UFF node\n"
    "               without an entry reads as model node \"#N\" (0-based node N);\n"
    "               writing UFF, a station without an entry gets the next free\n"
    "               number (the numbers used are printed on stderr); reading CSV,\n"
    "               stations written as node numbers (2.x/11.x_re) map through it.\n"
    "               NODE.DIR=STATION.DIR maps one channel of the file, in any\n"
    "               direction, to a model channel: 1.z=DA.x (an accelerometer's\n"
    "               own axis, UFF direction 3), 3.s=DB.y (a scalar record,\n"
    "               direction 0); DIR x, y, z, rx, ry, rz or s, the model's DIR\n"
    "               x, y, rx or ry; it wins over its node's NODE=STATION entry.\n"
    "               A z, rz or scalar record without one is skipped, the warning\n"
    "               naming the entry that would read it\n"
    "  --kind K     convert FRFs to receptance (m/N), mobility (m/(N s)) or\n"
    "               inertance (m/(N s^2)) before writing\n"
    "  --binary     write binary 58b instead of ASCII 58\n"
    "\n"
    "UFF: function type 4 (FRF; ordinate displacement, velocity or acceleration\n"
    "over excitation force decides the kind) or 1 with reference node 0 (unbalance\n"
    "response); complex data (types 5, 6); abscissa in Hz (type 18) or rpm (19);\n"
    "the rotor speed of an FRF test is the z-axis value (type 19, rpm; negative =\n"
    "synchronous); directions 1, 2, 4, 5 = x, y, rx, ry (negative flips the sign).\n"
    "CSV: '# kind = K' and '# rpm = R' comment lines, then freq_hz (FRF) or rpm\n"
    "(unbalance) and per channel 'RESP/REF re','RESP/REF im' (or mag/amp and\n"
    "phase_deg columns), as rcbtool frf and rcbtool unbalance write; the part may\n"
    "follow '_' (RESP/REF_re, _im, _mag, _phase_deg), as lab scripts write it.\n"
    "A 'mag' or 'dB' column without phase is read as magnitudes only (written back\n"
    "as a 'mag' column; UFF output refused: a dataset 58 FRF is complex).\n"
    "Exit codes: 2 usage, 3 unreadable or bad input data, 5 output not written.\n";

static const char *const kind_names[] = {"receptance", "mobility", "inertance"};

int cli_meas_format(const char *cmd, const char *path, int *is_uff) {
  const char *dot = strrchr(path, '.');
  const char *slash = strrchr(path, '/');
  if (dot && (!slash || dot > slash)) {
    if (strcmp(dot, ".csv") == 0 || strcmp(dot, ".CSV") == 0) {
      *is_uff = 0;
      return 0;
    }
    if (strcmp(dot, ".uff") == 0 || strcmp(dot, ".unv") == 0 || strcmp(dot, ".uf") == 0 ||
        strcmp(dot, ".UFF") == 0 || strcmp(dot, ".UNV") == 0) {
      *is_uff = 1;
      return 0;
    }
  }
  return cli_usage(cmd, "'%s': unknown file type; expected a name ending in .uff, .unv, .uf "
                   "(UFF dataset 58) or .csv", path);
}

int cli_meas_write(const char *cmd, const rcb_meas *ms, const char *path, int binary,
                   cli_uff_map *mp) {
  int is_uff = 0, rc;
  rcb_status st;
  cli_tmpfile tf;
  if ((rc = cli_meas_format(cmd, path, &is_uff))) return rc;
  if (is_uff && (rc = cli_uff_automap(cmd, ms, mp))) return rc;
  /* written to a temporary file of ours (removed on a signal), renamed at the end */
  if ((rc = cli_tmpfile_open(&tf, path))) return rc;
  st = is_uff ? rcb_meas_write_uff(ms, tf.write_path, binary, mp->n, mp->nodes)
              : rcb_meas_write_csv(ms, tf.write_path);
  if (st) {
    /* the library names the file it wrote, our temporary: the user's is the output */
    char msg[1024];
    int e = errno; /* a write the library could not start for want of memory: exit 4 */
    cli_path_subst(cli_msg(rcb_meas_errmsg(ms), st), tf.write_path, path, msg, sizeof msg);
    cli_tmpfile_close(&tf, 0);
    return cli_fail(st == RCB_ERR_IO ? cli_errno_exit(e)
                    : st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "%s", msg);
  }
  return cli_tmpfile_close(&tf, 1);
}

/* ---- convert ---- */

/* Options that take a value, for finding the positional arguments. */
static int takes_value(const char *arg) {
  static const char *const withval[] = {"-o", "--output", "--map", "--kind"};
  size_t i;
  if (strchr(arg, '=')) return 0;
  for (i = 0; i < sizeof withval / sizeof withval[0]; i++)
    if (strcmp(arg, withval[i]) == 0) return 1;
  return 0;
}

/* Take the second positional argument (OUT) out of argv: cli_parse knows one. */
static int split_out(int argc, char **argv, char **args, int *nargs, const char **out) {
  int k, npos = 0, only_pos = 0, n = 0;
  *out = NULL;
  for (k = 0; k < argc; k++) {
    const char *arg = argv[k];
    int pos = k > 0 && (only_pos || arg[0] != '-' || arg[1] == '\0');
    if (k > 0 && !only_pos && strcmp(arg, "--") == 0) only_pos = 1;
    if (pos && ++npos == 2) {
      *out = arg;
      continue;
    }
    args[n++] = argv[k];
    if (k > 0 && !pos && !only_pos && takes_value(arg) && k + 1 < argc) args[n++] = argv[++k];
  }
  *nargs = n;
  return npos;
}

static int read_input(const cli_args *a, rcb_meas *ms, const cli_uff_map *mp) {
  int is_uff = 0, rc;
  rcb_status st;
  size_t w;
  if ((rc = cli_meas_format(a->cmd, a->model, &is_uff))) return rc;
  st = is_uff ? rcb_meas_read_uff(ms, a->model, mp->n, mp->nodes)
              : rcb_meas_read_csv_map(ms, a->model, mp->n, mp->nodes);
  /* what was skipped (and the map entry that would read it), the speed not stated */
  for (w = 0; w < rcb_meas_warning_count(ms); w++)
    fprintf(stderr, "rcbtool: warning: %s\n", rcb_meas_warning(ms, w));
  if (st)
    return cli_fail(st == RCB_ERR_NOMEM ? CLI_EXIT_NUMERIC : CLI_EXIT_INPUT, "%s",
                    cli_msg(rcb_meas_errmsg(ms), st));
  return 0;
}

static int convert(const cli_args *a, const char *out) {
  cli_uff_map mp;
  rcb_meas *ms = NULL;
  int rc, kind = -1, is_uff;
  if ((rc = cli_opt_choice(a, "--kind", kind_names, 3, -1, &kind)) ||
      (rc = cli_meas_format(a->cmd, out, &is_uff)))
    return rc;
  if (cli_opt_value(a, "--binary") && !is_uff)
    return cli_usage(a->cmd, "--binary applies to UFF output only ('%s' is CSV)", out);
  if ((rc = cli_uff_map_parse(a, "--map", NULL, &mp))) {
    cli_uff_map_free(&mp);
    return rc;
  }
  if (rcb_meas_create(&ms, NULL)) {
    cli_uff_map_free(&mp);
    return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  }
  rc = read_input(a, ms, &mp);
  if (!rc && kind >= 0) {
    rcb_status st = rcb_meas_convert(ms, (rcb_frf_kind)kind);
    if (st) rc = cli_fail(CLI_EXIT_INPUT, "%s: %s", a->model, cli_msg(rcb_meas_errmsg(ms), st));
  }
  if (!rc) rc = cli_meas_write(a->cmd, ms, out, cli_opt_value(a, "--binary") != NULL, &mp);
  rcb_meas_destroy(ms);
  cli_uff_map_free(&mp);
  return rc;
}

int cmd_convert(int argc, char **argv) {
  cli_opt opts[] = {{"--map", "NODE=STATION,...", NULL},
                    {"--kind", "KIND", NULL},
                    {"--binary", NULL, NULL}};
  cli_args a;
  const char *out = NULL;
  char **args = malloc(((size_t)argc + 1) * sizeof *args);
  int nargs = 0, npos, rc, k;
  if (!args) return cli_fail(CLI_EXIT_NUMERIC, "out of memory");
  npos = split_out(argc, argv, args, &nargs, &out);
  for (k = 1; k < argc; k++)
    if (strcmp(argv[k], "--help") == 0 || strcmp(argv[k], "-h") == 0) {
      free(args);
      return cli_print_help(cli_help_convert);
    }
  if (npos == 0) {
    free(args);
    return cli_usage(argv[0], "missing the input file: expected 'rcbtool convert IN OUT'");
  }
  cli_plan_output(out, "OUT", 0); /* the second positional; checked by cli_parse */
  rc = cli_parse(nargs, args, opts, sizeof opts / sizeof opts[0], &a);
  if (!rc && out && a.output)
    rc = cli_usage(a.cmd, "give the output once: as OUT or as -o FILE, not both");
  if (!rc && !out) out = a.output;
  if (!rc && !out) rc = cli_usage(a.cmd, "missing the output file: expected 'rcbtool convert "
                                         "IN OUT' (OUT ending in .uff, .unv or .csv)");
  if (!rc && a.json) rc = cli_usage(a.cmd, "--json does not apply: the output format follows "
                                           "OUT's extension");
  if (!rc) rc = convert(&a, out);
  free(args);
  return rc;
}
