/*
 * Measurement container internals shared by the I/O files (meas.c, csv.c,
 * uff58.c, noise.c). Not installed.
 */
#ifndef RCB_MEAS_INTERNAL_H
#define RCB_MEAS_INTERNAL_H

#include <stdio.h>

#include "core/rcb_internal.h"
#include "rcb/rcb_measure.h"

/* "STATION.DIR": station names may be "C.A" (coupling side), up to
 * 2 RCB_NAME_MAX + 2, plus ".rx". */
#define RCB_MEAS_CH_MAX (2 * RCB_NAME_MAX + 8)

typedef struct rcb_meas_ch {
  char resp[RCB_MEAS_CH_MAX];
  char ref[RCB_MEAS_CH_MAX]; /* "" for unbalance responses */
  rcb_frf_kind kind;
  rcb_complex *data; /* n values (magnitude only: |H| + 0i) */
  int mag_only;      /* magnitudes without phase (rcb_meas_add_channel_mag) */
} rcb_meas_ch;

struct rcb_meas {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  rcb_meas_type type;
  size_t n;     /* points */
  double *x;    /* rad/s, n of them */
  double speed; /* rad/s (FRF test speed, < 0 synchronous) */
  int speed_given; /* the file or the caller stated the speed (not a default 0) */
  rcb_meas_ch *ch;
  size_t nch, capch;
  rcb_warning_t *warnings; /* of the last read (rcb_meas_warning) */
  size_t n_warnings, cap_warnings;
  size_t speed_warning; /* 1 + index of the "speed not stated" warning, 0: none */
  rcb_phase_convention phase; /* how a CSV presents the phase (rcb_meas_set_phase) */
  char phase_ref[84];         /* what it is measured from ("keyphasor rising edge") */
};

/* The error message of rcb_meas (core/rcb_internal.h; ms may be NULL: no
 * message, st returned). */
#define rcb_meas_fail(ms, st, ...) rcb_set_error((ms) ? (ms)->errmsg : NULL, (st), __VA_ARGS__)

/* Record a warning of a read (valid but likely misread input); RCB_ERR_NOMEM
 * with the message set when it cannot be stored. */
rcb_status rcb_meas_warn(rcb_meas *ms, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Forget the warnings (at the start of every read). */
void rcb_meas_clear_warnings(rcb_meas *ms);
/* uff58_warn.c: after a UFF read, warn on channels at "#N" (a node the map
 * of @p nmap entries does not name) and, for FRFs, on a z axis of type
 * @p ztype other than 19 (the speed is not stated); sets ms->speed_given. */
rcb_status rcb_uff_read_warnings(rcb_meas *ms, const char *path, size_t nmap, long ztype);

/* Drop grid and channels (the object stays usable). */
void rcb_meas_clear(rcb_meas *ms);

/*
 * Set the grid / add a channel with the errors reported as coming from
 * @p where (e.g. "f.uff: record 3 (line 40)"; NULL for API calls) and the
 * status @p bad used for invalid data (RCB_ERR_ARG from the API,
 * RCB_ERR_PARSE from a file).
 */
rcb_status rcb_meas_set_grid_at(rcb_meas *ms, rcb_meas_type type, size_t n, const double *x,
                                double speed, const char *where, rcb_status bad);
rcb_status rcb_meas_add_channel_at(rcb_meas *ms, const char *response, const char *reference,
                                   rcb_frf_kind kind, const rcb_complex *data,
                                   const char *where, rcb_status bad);
/* The same for magnitudes only (values |H| + 0i, each >= 0; issue #35 item 4). */
rcb_status rcb_meas_add_mag_at(rcb_meas *ms, const char *response, const char *reference,
                               rcb_frf_kind kind, const rcb_complex *data, const char *where,
                               rcb_status bad);

/* Split "STATION.DIR": dir index 0..3 (x, y, rx, ry) or -1 if the suffix is
 * not one of them; *stlen = length of the station part. */
int rcb_meas_channel_dir(const char *name, size_t *stlen);
/* "receptance" / "mobility" / "inertance" */
const char *rcb_meas_kind_name(rcb_frf_kind k);
int rcb_meas_kind_parse(const char *s, rcb_frf_kind *k);

/* Atomic output: write to a temporary file next to @p path, then rename. */
typedef struct rcb_atomic_file {
  FILE *fp;
  char tmp[4096];
} rcb_atomic_file;
rcb_status rcb_atomic_open(rcb_meas *ms, rcb_atomic_file *af, const char *path, int binary);
/* Close and rename onto @p path; on any error the temporary file is removed. */
rcb_status rcb_atomic_commit(rcb_meas *ms, rcb_atomic_file *af, const char *path);
void rcb_atomic_abort(rcb_atomic_file *af);

/* UFF dataset 58 time records (uff58_read.c), for the signal readers
 * (src/signals/): each record of function type 1 with a time abscissa
 * (type 17), real and evenly spaced, goes to @p fn in file order with its
 * values in SI (dataset 164 and the record-9 label applied, a negative
 * direction flipped). Errors (and a file without such a record) land in
 * ms's message; a nonzero return of fn stops the read with that status. */
typedef struct rcb_uff_time_rec {
  char name[RCB_MEAS_CH_MAX]; /* "STATION.DIR" (DIR x, y, z, rx, ry, rz), or the
                                 station for direction 0 (scalar); a direction entry
                                 of the map ("1.z=DA.x") gives its model channel */
  long node;                  /* the record's response node */
  long dir;                   /* the record's direction code (0 scalar, 3 z, 6 rz, ...) */
  double t0, dt;              /* s */
  size_t n;
  size_t claimed;             /* ASCII record cut short: the points record 7 claims
                                 (n were read, up to its '-1'); 0 when whole */
  const rcb_complex *y;       /* n values, SI, imaginary parts 0 (file units when
                                 label_unknown) */
  rcb_quantity q;             /* from the data type or the label; unknown if neither */
  char label[24];             /* the record-9 units label as written */
  int label_unknown;          /* a label rcb_unit_parse does not know: the caller
                                 scales (or refuses) */
  long spec;                  /* record 9's ordinate data type */
  size_t index, line;         /* dataset ordinal, line of its id line */
} rcb_uff_time_rec;
typedef rcb_status (*rcb_uff_time_fn)(void *user, const rcb_uff_time_rec *rec);
rcb_status rcb_uff58_read_time(rcb_meas *ms, const char *path, size_t nmap,
                               const rcb_uff_node *map, rcb_uff_time_fn fn, void *user);

/* What a UFF dataset 58 function type is and which rcbtool verb reads it
 * ("9 (power spectral density): no rcbtool command reads it"), for messages
 * (uff58_warn.c); @p abscissa: record 8's data type (17 time). */
void rcb_uff_function_text(long func_type, long abscissa, char *buf, size_t size);

/* Longest station a node map may give: "STATION.rx" must fit a channel
 * (RCB_MEAS_CH_MAX with its NUL), so a name is refused, never cut. */
#define RCB_MEAS_STATION_MAX (RCB_MEAS_CH_MAX - 4)
/* A reader's node map (@p who names the call in the message): NULL with
 * entries, an entry without a station or with one longer than
 * RCB_MEAS_STATION_MAX, a direction entry whose dir is not a UFF direction
 * name or whose model_dir is not x, y, rx, ry (or a model_dir without dir),
 * and two entries for one node (or one node and direction) are RCB_ERR_ARG
 * with the entry named. */
rcb_status rcb_meas_check_map(rcb_meas *ms, const char *who, size_t nmap,
                              const rcb_uff_node *map);

/* A UFF direction code's name in a map entry ("1.z=DA.x"): 0 "s" (scalar),
 * 1 to 6 "x", "y", "z", "rx", "ry", "rz", the sign dropped; NULL beyond. */
const char *rcb_uff_dir_name(long code);
/* The map entry a channel at @p node in file direction @p code reads
 * through: the node's direction entry for that direction, else the node's
 * entry (dir NULL), else NULL. */
const rcb_uff_node *rcb_uff_map_find(size_t nmap, const rcb_uff_node *map, long node,
                                     long code);

/* Whole file into memory (NUL-terminated), through the object's allocator. */
rcb_status rcb_meas_slurp(rcb_meas *ms, const char *path, char **buf, size_t *len);

#endif /* RCB_MEAS_INTERNAL_H */
