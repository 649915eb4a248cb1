/**
 * @file cli.h
 * @brief rcbtool internals shared by the subcommands: option parsing, model
 * loading, channel lists, output (CSV/JSON, atomic -o), progress and exit codes.
 *
 * rcbtool uses only the public librcb header. Units at this edge: speeds in
 * rpm and frequencies in Hz; they are converted to rad/s for the library.
 */
#ifndef RCBTOOL_CLI_H
#define RCBTOOL_CLI_H

#include <stdio.h>

#include <rcb/rcb.h>

/** Exit codes (the CLI contract). */
enum {
  CLI_EXIT_OK = 0,
  CLI_EXIT_USAGE = 2,   /**< bad command line */
  CLI_EXIT_INPUT = 3,   /**< bad input: model file or data */
  CLI_EXIT_NUMERIC = 4, /**< numerical failure in an analysis */
  CLI_EXIT_IO = 5,      /**< output could not be written */
  CLI_EXIT_LOCKED = 6   /**< a file of the run is being updated by another run */
};

#define CLI_PI 3.14159265358979323846
#define CLI_RPM_TO_RAD_S (CLI_PI / 30.0) /* rad/s per rpm */
#define CLI_HZ_TO_RAD_S (2.0 * CLI_PI)   /* rad/s per Hz */
/* A numeric macro as a string literal, for help texts (a default stated once). */
#define CLI_STR_(x) #x
#define CLI_STR(x) CLI_STR_(x)

/** One command-specific option, e.g. {"--rpm", "R"}; metavar NULL = flag. */
typedef struct cli_opt {
  const char *name;
  const char *metavar;
  const char *value; /**< filled by cli_parse: the argument, "" for a flag, NULL if absent */
} cli_opt;

/** What a file option is to the run's plan (cli_plan.c). */
enum {
  CLI_IO_IN = 1,    /**< a file the run reads */
  CLI_IO_OUT = 2,   /**< a file the run writes (through the plan only) */
  CLI_IO_MKDIR = 4, /**< an output whose missing directories are made (--plot) */
  CLI_IO_INOUT = CLI_IO_IN | CLI_IO_OUT /**< read, then rewritten (--history) */
};
/** A verb's file option, e.g. {"--stats", CLI_IO_OUT}: a verb's table of these,
 * given to cli_plan_options before cli_parse, is its declaration of its files. */
typedef struct cli_file_opt {
  const char *name;
  unsigned io;
} cli_file_opt;

/** Most positional files a command takes (estimate: one signals file per hit). */
#define CLI_FILES_MAX 256

/** A parsed command line. */
typedef struct cli_args {
  const char *cmd;    /**< subcommand name */
  const char *model;  /**< MODEL.ini path (the first positional argument) */
  const char *files[CLI_FILES_MAX]; /**< every positional argument (files[0] == model) */
  size_t nfiles;      /**< how many (1 unless the command takes several) */
  const char *output; /**< -o FILE, NULL = stdout */
  int json;           /**< --json */
  int progress;       /**< --progress */
  double max_output_mb; /**< --max-output MB: largest output accepted, MB (0: default) */
  int help;           /**< --help / -h */
  cli_opt *opts;
  size_t nopts;
} cli_args;

/** A subcommand: name, one-line summary, help text, entry point. */
typedef struct cli_command {
  const char *name;
  const char *summary;
  const char *help;
  int (*run)(int argc, char **argv);
} cli_command;

/* ---- messages (cli_common.c) ---- */

/** Print "rcbtool: <message>" to stderr (control bytes shown as \xNN) and
 * return @p code. */
int cli_fail(int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
#ifdef __clang_analyzer__ /* returns code: see rcb_set_error in src/core/rcb_internal.h */
#define cli_fail(code, ...) ((void)(cli_fail)((code), __VA_ARGS__), (code))
#endif
/** Print "rcbtool: warning: <message>" to stderr (control bytes escaped, as
 * in every message of cli_fail and cli_usage). */
void cli_warn(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/** A usage error: message plus a pointer to --help; returns CLI_EXIT_USAGE. */
int cli_usage(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
#ifdef __clang_analyzer__ /* as cli_fail */
#define cli_usage(cmd, ...) ((void)(cli_usage)((cmd), __VA_ARGS__), CLI_EXIT_USAGE)
#endif
/** @p msg if it says something, else the status text. */
const char *cli_msg(const char *msg, rcb_status st);
/** All of standard input, NUL-terminated (*len bytes before the terminator);
 * NULL after a printed message when it cannot be read. */
char *cli_read_stdin(size_t *len);
/** Exit code of a failed file operation with errno @p e: 4 for ENOMEM (out of
 * memory, as everywhere), else 5. */
int cli_errno_exit(int e);
/** Exit code for a failed analysis call (numerical failure unless it is the input). */
int cli_status_exit(rcb_status st);
/**
 * Print "rcbtool: warning: CMD: ill-conditioned ..." to stderr when a sweep had
 * solves below the condition threshold, naming where the worst one was (in rpm
 * when @p by_speed, else in Hz and rpm); nothing otherwise.
 */
void cli_warn_condition(const char *cmd, const rcb_frf_condition *c, int by_speed);

/* ---- options (cli_args.c) ---- */

/**
 * @brief Parse "rcbtool CMD [MODEL] [options]" (argv[0] is CMD). Common options
 * (-o/--output, --json, --progress, --help) are handled here, command
 * options go to @p opts. Accepts "--opt value" and "--opt=value".
 * @return 0, or CLI_EXIT_USAGE after printing what is wrong.
 */
int cli_parse(int argc, char **argv, cli_opt *opts, size_t nopts, cli_args *a);
/** cli_parse for a command taking up to @p max_files positional files (at
 * most CLI_FILES_MAX; estimate: one signals file per hit), each declared an
 * input of the run. */
int cli_parse_files(int argc, char **argv, cli_opt *opts, size_t nopts, size_t max_files,
                    cli_args *a);
/** The option's value, NULL if not given. */
const char *cli_opt_value(const cli_args *a, const char *name);
/** A finite number from option @p name (default @p def when absent). */
int cli_opt_double(const cli_args *a, const char *name, const char *unit, double def,
                   double *out);
/** A whole number >= 1 from option @p name (default @p def when absent). */
int cli_opt_count(const cli_args *a, const char *name, size_t def, size_t *out);
/**
 * @brief The noise model option (--noise A,S[,P] of fit, diagnose, simulate,
 * monitor): A, S the eq. 19 factors in %, P a phase noise in degrees
 * (uniform in +-P; 0 when not given). 0 when absent (outputs untouched), 2
 * (usage) on a malformed value.
 */
int cli_noise_opt(const cli_args *a, const char *opt, double *beta_a, double *beta_s,
                  double *phase_deg);
/** Like cli_opt_double, also requires the value to be >= 0. */
int cli_opt_nonneg(const cli_args *a, const char *name, const char *unit, double def,
                   double *out);
/**
 * @brief One of @p n words from option @p name: *out is its index (@p def when
 * absent); anything else is a usage error listing the choices.
 */
int cli_opt_choice(const cli_args *a, const char *name, const char *const *choices, size_t n,
                   int def, int *out);
/** The option must be present: usage error naming what is expected otherwise. */
int cli_opt_require(const cli_args *a, const char *name, const char *what);
/** Evenly spaced grid: x_i = lo + i (hi - lo)/(n - 1) (x_0 = lo when n = 1). */
void cli_linspace(double lo, double hi, size_t n, double *x);

/* ---- model and channels (cli_model.c) ---- */

/** Load and finalize MODEL.ini; on failure print the library message, exit 3. */
int cli_load_model(const cli_args *a, rcb_model **out);

/** A list of channels "STATION.DIR,..." resolved against a model. */
typedef struct cli_channels {
  char *buf;     /**< one copy of the list, split in place */
  char **names;  /**< n channel names (point into buf) */
  rcb_dof *dofs; /**< n resolved DOFs */
  size_t n;
} cli_channels;

/** Resolve option @p opt's channel list; unknown channel = usage error (exit 2). */
int cli_channels_parse(const cli_args *a, rcb_model *m, const char *opt, cli_channels *ch);
void cli_channels_free(cli_channels *ch);

/* ---- output (cli_output.c) ---- */

/* ---- the run's input/output plan (cli_plan.c) ----
 * Every input and output of a run is declared before anything is read or
 * written; cli_plan_check refuses, before the work, an output that is an input
 * (device and inode, so links and other spellings count), two outputs that are
 * one file, an output that is a directory or whose directory is missing or not
 * writable (exit 5). Outputs are opened only through cli_out_open and
 * cli_tmpfile_open, which refuse a path the plan does not hold; each is written
 * to a temporary in its own directory, and all are renamed by cli_plan_finish
 * only when the run succeeded (removed otherwise, and on a signal). */

/** Name the run's first positional argument from the command's help text
 * ("usage: rcbtool estimate SIGNALS ..." -> "signals"); called once, from main. */
void cli_plan_begin(const char *help);
/** What the command's first positional argument is ("model", "signals", "input"). */
const char *cli_plan_positional(void);
/** Declare @p path an input ("model", "measurement", "--sd", ...); "-" is ignored. */
void cli_plan_input(const char *path, const char *what);
/** Declare @p path an output (@p what: "-o", "--stats", ...; @p io: CLI_IO_MKDIR or 0). */
void cli_plan_output(const char *path, const char *what, unsigned io);
/** The verb's file options (a static table; called before cli_parse). */
void cli_plan_options(const cli_file_opt *files, size_t n);
/** Declare the positional argument, -o and every file option given in @p a
 * (those of cli_plan_options), then cli_plan_check (cli_parse does this). */
int cli_plan_args(const cli_args *a);
/** The one check of the plan (see above); 0, exit 5, or 4 when out of memory. */
int cli_plan_check(void);
/** A file @p tmp written by another program (the plotting script) for the
 * declared output @p path: renamed onto it by cli_plan_finish like our own
 * temporaries, or removed. 0 or an exit code. */
int cli_plan_adopt(const char *tmp, const char *path);
/** End of the run (main): when @p rc is 0 rename every output's temporary onto
 * it, else remove them all; returns @p rc or exit 5. */
int cli_plan_finish(int rc);
/** SIGINT, SIGTERM, SIGHUP remove the registered temporary files, then end the
 * process by the same signal (called once, from main). */
void cli_signals_install(void);
/** Add a temporary file to the list the signal handler removes; returns its
 * slot (-1 if the list is full or the path too long). For temporary copies of
 * inputs (standard input); outputs get theirs from the plan. */
int cli_tmp_register(const char *path);
/** mkstemp(@p tmpl) and its entry on the list (*slot) as one step for the signal
 * handler (the signals held in between); the descriptor, or -1 with errno. */
int cli_mkstemp(char *tmpl, int *slot);
/** Take slot @p slot off the list (after the rename or the removal); -1 is ignored. */
void cli_tmp_release(int slot);

/** Where results go: stdout, or a temporary file renamed onto -o FILE at the end. */
typedef struct cli_out {
  FILE *fp;
  const char *path; /**< final path, NULL for stdout */
  char *tmp;        /**< temporary path while writing */
  int slot;         /**< its entry in the signal handler's list (-1: none) */
} cli_out;

/** Default of --max-output: the largest output accepted, MB (10^6 bytes). */
#define CLI_MAX_OUTPUT_MB 2000.0
/**
 * @brief Refuse, before any work, an output of @p rows rows of @p numbers
 * numbers each whose size (~25 bytes a number as text, "%.17g" and a
 * separator) is above --max-output MB; 0 or a usage error (exit 2).
 */
int cli_check_size(const cli_args *a, double rows, double numbers);
/** Open the destination -o (a->output): stdout, a device in place, or a temporary
 * beside a declared output (an undeclared path is refused). 0 or exit 5. */
int cli_out_open(cli_out *o, const cli_args *a);
/** Flush and close the temporary file, not yet renamed (cli_out_close or
 * cli_out_abort follows); on error remove it, exit 5. */
int cli_out_flush(cli_out *o);
/** Flush and hand the temporary to the plan (renamed when the run succeeded);
 * on any error remove it, exit 5. */
int cli_out_close(cli_out *o);
/** Abandon the output: the temporary file is removed, nothing is left. */
void cli_out_abort(cli_out *o);

/** A file written by a library call (which makes its own temporary beside the
 * path it is given): the call writes write_path, a temporary of ours. */
typedef struct cli_tmpfile {
  const char *path;       /**< final path */
  const char *write_path; /**< what to give the writer (path itself for a device) */
  char *tmp;
  int slot[2];
} cli_tmpfile;
/** Make the temporary of a declared output (on the signal handler's list); 0 or exit 5. */
int cli_tmpfile_open(cli_tmpfile *t, const char *path);
/** If @p ok hand the temporary to the plan (renamed when the run succeeded),
 * else remove it; 0 or an exit code. */
int cli_tmpfile_close(cli_tmpfile *t, int ok);

/** @p msg with every mention of the temporary @p tmp (and of the library's
 * "<tmp>.tmp000") replaced by the output @p path, into @p buf: a message names
 * the user's file, never our temporary. */
void cli_path_subst(const char *msg, const char *tmp, const char *path, char *buf,
                    size_t size);

/** A rotation channel ("STATION.rx" or ".ry")? */
int cli_is_rotation(const char *channel);
/**
 * @brief SI unit of a channel for CSV headers: the FRF @p resp / @p ref of
 * kind @p kind (rcb_frf_kind: m/N, m/(N s), m/(N s^2); rad and N m for
 * rotations), or with @p ref NULL the response itself (m or rad).
 */
const char *cli_channel_unit(const char *resp, const char *ref, int kind, char *buf,
                             size_t size);

/** Number as CSV field: "%.17g" ("nan", "inf" as printf spells them). */
void cli_csv_num(FILE *fp, double x);
/** Number as JSON: "%.17g", null for NaN and infinities. */
void cli_json_num(FILE *fp, double x);
/* ---- the one escaping rule (cli_text.c): every printed field goes through one ---- */
/** String as a JSON string literal: '"', '\\' escaped, controls and each byte of
 * invalid UTF-8 as \u00XX: always valid JSON. */
void cli_json_str(FILE *fp, const char *s);
/** Terminal text (tables, messages, CSV comments, logs): control bytes (C0, DEL,
 * C1) and invalid UTF-8 shown as \xNN, valid UTF-8 as it is. */
void cli_put_text(FILE *fp, const char *s);
/** cli_put_text into @p buf (cut to @p size, never in an escape); returns buf,
 * for a padded printf field. */
const char *cli_text(const char *s, char *buf, size_t size);
/** JSON array of n numbers x[0], x[stride], ... */
void cli_json_nums(FILE *fp, const double *x, size_t n, size_t stride);
/** JSON list of the model's nodes: [{"node", "shaft", "z", "dof": [4]}, ...]. */
void cli_json_nodes(FILE *fp, const rcb_model *m);
/** "forward", "backward" or "mixed". */
const char *cli_whirl_name(rcb_whirl w);

/* ---- progress line on stderr (cli_output.c) ---- */

typedef struct cli_progress {
  int on;
  int tty; /**< stderr is a terminal: update the line in place */
  const char *label; /**< e.g. "frf" */
  const char *unit;  /**< e.g. "frequencies" */
  size_t total;
  size_t shown; /**< last count printed */
} cli_progress;

/** On when --progress is given, or when stderr is a terminal and the sweep is long. */
void cli_progress_start(cli_progress *p, const cli_args *a, const char *label,
                        const char *unit, size_t total);
void cli_progress_step(cli_progress *p, size_t done);
void cli_progress_end(cli_progress *p);

/* ---- measurements (cmd_convert.c; used by simulate) ---- */

/** UFF node map from --map NODE=STATION,... (stations added by cli_uff_automap). */
typedef struct cli_uff_map {
  rcb_uff_node *nodes;
  size_t n;
  char *buf;     /**< the option's text, split in place */
  char **owned;  /**< station names added by cli_uff_automap */
  size_t nowned;
} cli_uff_map;
/** Parse option @p opt, added to the model's [uff] map when @p m is given (an
 * option entry replaces the model's entry for the same node or station); usage
 * error (2) when malformed. */
int cli_uff_map_parse(const cli_args *a, const char *opt, const rcb_model *m,
                      cli_uff_map *mp);
void cli_uff_map_free(cli_uff_map *mp);
/** Give every station of @p ms without a map entry the next free node number
 * (printed on stderr). */
int cli_uff_automap(const char *cmd, const rcb_meas *ms, cli_uff_map *mp);
/** *is_uff from the file name's extension (.uff/.unv/.uf or .csv); else usage error. */
int cli_meas_format(const char *cmd, const char *path, int *is_uff);
/** Write @p ms to @p path as UFF (binary 58b if @p binary) or CSV by extension;
 * exit code 0, 2, 3 or 5. */
int cli_meas_write(const char *cmd, const rcb_meas *ms, const char *path, int binary,
                   cli_uff_map *mp);

/* ---- model + measurement commands (cli_meas.c) ---- */

/** cli_parse knows one positional argument (the model): take the second one
 * (the measurement) out of argv; returns the number of positionals. */
int cli_split_meas(int argc, char **argv, const cli_opt *opts, size_t nopts, char **args,
                   int *nargs, const char **meas);
/** The start of every MODEL MEAS command: take the measurement out of argv,
 * parse the rest into a, print @p help when asked. Returns 0 to go on, -1
 * when the help was printed, or an exit code (a missing measurement is a
 * usage error saying @p expected). *args (free it after the command: a
 * points into it) is set in every case, NULL when out of memory. */
int cli_parse_meas_cmd(int argc, char **argv, cli_opt *opts, size_t nopts, const char *help,
                       const char *expected, cli_args *a, const char **meas, char ***args);
/** Record the model and @p meas as inputs and refuse, before any work, an
 * output (-o, --history, the --plot files) that is one of them or a history
 * file that is not one; 0 or exit 5. */
int cli_guard_outputs(const cli_args *a, const char *meas);
/** Read a measurement by extension ("-": standard input, CSV or UFF by content) (UFF with --map or the model's [uff] map,
 * or CSV); exit code 0, 2, 3 or 4 with the message printed. */
int cli_meas_read(const cli_args *a, const char *path, const rcb_model *m, rcb_meas **out);
/** 0 when every channel of @p ms has its phase; else a usage error (2) naming
 * the file @p path, a magnitude-only channel and @p what needs the phase
 * ("--scale complex", "the monitor"; issue #35 item 4). */
int cli_meas_need_phase(const cli_args *a, const rcb_meas *ms, const char *path,
                        const char *what);

/* ---- fitted parameters (cmd_fit.c; used by sensitivity) ---- */

/** One --params item "NAME" or "NAME:LO:HI" (parameter units). */
typedef struct cli_param_spec {
  const char *name;
  double lo, hi;
  int has_bounds;
} cli_param_spec;
typedef struct cli_params {
  char *buf; /**< the option's text, split in place */
  cli_param_spec *items;
  size_t n;
} cli_params;
/** Parse option @p opt (required; usage error 2 when absent or malformed). */
int cli_params_parse(const cli_args *a, const char *opt, cli_params *ps);
void cli_params_free(cli_params *ps);
/** Bounds of one parameter: given, or [start/1000, start*1000] (start > 0), or any
 * bounds around the start if @p any; else a usage error (2). */
int cli_param_bounds(const cli_args *a, const cli_param_spec *p, double start, int any,
                     double *lo, double *hi);
/** 0 if @p path may take history records: new, empty, or history lines only,
 * and no input of this run; else a message and exit 5 (nothing written). */
int cli_history_check(const char *path);
/** Append a step to a history file (JSON lines, rewritten atomically): the
 * command, the model, its error % (and the noise floor, NaN if unknown), the
 * number of parameters fitted so far, and a note; exit code 0 or 5. */
int cli_history_append(const char *path, const char *command, const char *model,
                       double error_pct, double floor_pct, size_t nparams, const char *note);
/** Add the parameters to @p f: unknown name exit 3, bad bounds exit 2; without
 * bounds [start/1000, start*1000] (start > 0), or any bounds if @p any_bounds. */
int cli_params_add(const cli_args *a, rcb_fit *f, const rcb_model *m, const cli_params *ps,
                   int log_all, int any_bounds);

/* ---- the measurement chain: --sensor, --swap (cli_chain.c) ---- */

/** One --sensor item: the response read as gain e^{i phase} times the model. */
typedef struct cli_sensor_edit {
  const char *response;
  double gain, phase; /**< dimensionless (sign included), rad */
} cli_sensor_edit;
typedef struct cli_chain {
  char *buf; /**< the options' text, split in place */
  cli_sensor_edit *sens;
  size_t nsens;
  const char **swap; /**< pairs: swap[2k] with swap[2k + 1] */
  size_t nswap;
} cli_chain;
/** Parse --sensor RESP:KEY=V[,KEY=V][,RESP2:...] and --swap A,B[,C,D...] (both
 * optional); usage error 2 when malformed. */
int cli_chain_parse(const cli_args *a, cli_chain *ch);
void cli_chain_free(cli_chain *ch);
/** Carry the corrections into a fit / a diagnosis: a sensor no channel
 * measures, or probes that cannot be swapped, exit 3 with the library's
 * message (which lists the measured responses). */
int cli_chain_fit(const cli_args *a, const cli_chain *ch, rcb_fit *f);
int cli_chain_diag(const cli_args *a, const cli_chain *ch, rcb_diag *d);
/** Start, bounds and log flag of one --params item: a model parameter from
 * the model (bounds as cli_param_bounds, log as @p log_all); a sensor's
 * (sensor.RESP.gain | .phase) from rcb_fit_sensor_param_defaults (bounds
 * given or its defaults; log for a gain with LO > 0, whatever @p log_all).
 * Unknown model parameter exit 3, bad bounds exit 2. */
int cli_param_setup(const cli_args *a, const rcb_model *m, const cli_param_spec *p, int log_all,
                    int any_bounds, double *lo, double *hi, int *logp);

/* ---- plots (cli_plot.c) ---- */

/** Make the directories of a --plot path (mkdir -p of its dirname); 0 or exit 5. */
int cli_plot_mkdir(const char *path);
/** Run rcb_plots.py KIND JSON OUT (RCB_PYTHON, RCB_PLOTS; messages to stderr);
 * [FORMAT] (the picture's format when OUT has no telling suffix, or NULL);
 * 0, or exit 5 with a message ending in @p kept (what became of the outputs). */
int cli_plot_run(const char *kind, const char *json, const char *out, const char *format,
                 const char *kept);
typedef void (*cli_plot_json_fn)(FILE *fp, const void *ctx);
/** --plot @p png (estimate, order): the data as JSON (@p json) in a temporary
 * file, rcb_plots.py KIND draws a temporary picture renamed onto @p png on
 * success; nothing is left on failure. 0 or exit 5. */
int cli_plot_write(const char *kind, const char *png, cli_plot_json_fn json, const void *ctx,
                   const char *kept);

/* ---- per-point standard deviations (cli_sd.c; used by fit and diagnose) ---- */

/**
 * The standard deviations of a --stats file of rcbtool estimate ('RESP/REF
 * sd') or order ('RESP 1X sd') matching @p ms point by point, channel-major
 * (for rcb_fit_set_sd / rcb_diag_set_sd; *sd is the caller's to free).
 */
int cli_sd_read(const char *path, const rcb_meas *ms, double **sd);

/** Read SIGNALS (a->model) by extension: .csv, .uff/.unv (UFF58 time records,
 * --map), .wav (--wav-names, --wav-units, --wav-scale); --units CH=UNIT and
 * --allow-truncated (the command declares them); the reader's warnings
 * printed; exit code 0, 2, 3, 4. */
int cli_signals_read(const cli_args *a, rcb_signals *s);
/** cli_signals_read of the file @p path (estimate's further hit files). */
int cli_signals_read_path(const cli_args *a, const char *path, rcb_signals *s);
/** The index of channel @p name of the signals, else exit 3 with the channels
 * the file holds listed. */
int cli_signals_find(const cli_args *a, const rcb_signals *s, const char *name, size_t *idx);
/** 0 when @p model (the model channel that file channel @p name stands for:
 * NAME=STATION.DIR, else the name itself) is STATION.DIR with DIR x, y, rx or
 * ry; else a usage error naming the --outputs item or the --map entry that
 * names it ("#1.z": --map 1.z=STATION.DIR; issue #35). */
int cli_signals_model_channel(const cli_args *a, const char *name, const char *model);

/* ---- subcommands (one file each) ---- */

int cmd_check(int argc, char **argv);
int cmd_matrices(int argc, char **argv);
int cmd_frf(int argc, char **argv);
int cmd_unbalance(int argc, char **argv);
int cmd_modes(int argc, char **argv);
int cmd_campbell(int argc, char **argv);
int cmd_simulate(int argc, char **argv);
int cmd_estimate(int argc, char **argv);
int cmd_order(int argc, char **argv);
int cmd_convert(int argc, char **argv);
int cmd_fit(int argc, char **argv);
int cmd_sensitivity(int argc, char **argv);
int cmd_transient(int argc, char **argv);
int cmd_timecheck(int argc, char **argv);
int cmd_compare(int argc, char **argv);
int cmd_diagnose(int argc, char **argv);
int cmd_plan(int argc, char **argv);
int cmd_history(int argc, char **argv);
int cmd_monitor(int argc, char **argv);

extern const char cli_help_check[];
extern const char cli_help_matrices[];
extern const char cli_help_frf[];
extern const char cli_help_unbalance[];
extern const char cli_help_modes[];
extern const char cli_help_campbell[];
extern const char cli_help_simulate[];
extern const char cli_help_estimate[];
extern const char cli_help_order[];
extern const char cli_help_convert[];
extern const char cli_help_fit[];
extern const char cli_help_sensitivity[];
extern const char cli_help_transient[];
extern const char cli_help_timecheck[];
extern const char cli_help_compare[];
extern const char cli_help_diagnose[];
extern const char cli_help_plan[];
extern const char cli_help_history[];
extern const char cli_help_monitor[];

/** Print a command's help text to stdout; returns 0 (or 5 if stdout fails). */
int cli_print_help(const char *text);

/* ---- sweep options shared by simulate and sensitivity (cli_sweep.c) ---- */

/** "receptance", "mobility", "inertance", in rcb_frf_kind order. */
extern const char *const cli_kind_names[3];
/** --frf options: --in (required, described by in_what), --fmin/--fmax (Hz),
 * --rpm (rpm), --kind; rejects --rpm-min/--rpm-max. 0 or an exit code. */
int cli_sweep_frf(const cli_args *a, const char *in_what, double *fmin_hz, double *fmax_hz,
                  double *rpm, int *kind);
/** --unbalance options: --rpm-min/--rpm-max (rpm); rejects the FRF options
 * with the message frf_only. 0 or an exit code. */
int cli_sweep_unbalance(const cli_args *a, const char *frf_only, double *rpm_min,
                        double *rpm_max);

#endif /* RCBTOOL_CLI_H */
