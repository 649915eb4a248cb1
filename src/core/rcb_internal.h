/*
 * Internal definitions shared by the library's stages. Not installed.
 * Layers (each uses only those below it):
 *   analyses -> solvers -> assembly -> elements -> model -> core
 */
#ifndef RCB_INTERNAL_H
#define RCB_INTERNAL_H

#include <complex.h>
#include <stdarg.h>
#include <stddef.h>

#include "rcb/rcb.h"

/* glibc defines CMPLX only for GCC >= 4.7, so clang (which reports itself
 * as GCC 4.2) lacks it; clang has the same builtin. */
#if !defined(CMPLX) && defined(__clang__)
#define CMPLX(x, y) __builtin_complex((double)(x), (double)(y))
#endif

#define RCB_ERRMSG_MAX 512
#define RCB_PI 3.14159265358979323846
/* The imaginary unit as double complex (complex.h's I is a float complex). */
#define RCB_J CMPLX(0.0, 1.0)

/* ---- core/alloc.c ---- */
void *rcb_alloc(const rcb_allocator *a, size_t size);   /* zeroed, NULL on failure */
void rcb_free(const rcb_allocator *a, void *p);
void rcb_allocator_init(rcb_allocator *dst, const rcb_allocator *src);
/* Grow a dynamic array to hold at least need items: 0 or -1. */
int rcb_grow(const rcb_allocator *a, void **items, size_t *cap, size_t need, size_t item_size);

/* ---- core/errmsg.c: the library's one error-message helper ---- */
/* Show control bytes (C0, DEL) of a message as \xNN, in place, truncated to
 * @p size bytes with the NUL: a token echoed from a file cannot drive a terminal. */
void rcb_escape_controls(char *buf, size_t size);
/* printf into an object's error buffer (RCB_ERRMSG_MAX bytes; NULL: nothing
 * written), control bytes escaped, and return st, so that a failure reads
 * "return rcb_fail(obj, RCB_ERR_ARG, "...", ...)". Every folder writes its
 * messages through it: rcb_fail on any object with a char
 * errmsg[RCB_ERRMSG_MAX] member, or rcb_set_error on a caller's buffer. The
 * folders' short names (rcb_model_fail, rcb_fit_fail, rcb_diag_fail,
 * rcb_cmp_fail, rcb_meas_fail, rcb_signals_fail) are rcb_fail on their object. */
rcb_status rcb_set_error(char *buf, rcb_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
#ifdef __clang_analyzer__
/* The clang static analyzer (clang-tidy, `dev.sh lint`) never follows a call
 * into a variadic function, so it cannot see that this returns st and it
 * explores "failed, yet returned RCB_OK" paths. This macro states the return
 * value for the analysis only (a compiler never defines __clang_analyzer__);
 * the other *_fail helpers do the same. */
#define rcb_set_error(buf, st, ...) ((void)(rcb_set_error)((buf), (st), __VA_ARGS__), (st))
#endif
#define rcb_fail(obj, st, ...) rcb_set_error((obj)->errmsg, (st), __VA_ARGS__)

/* ---- core/numparse.c ---- */
/* strtod(str, endp) as in the "C" locale, bit for bit (value, *endp, errno),
 * fast on plain decimals of up to 19 significant digits: the text readers'
 * number parser (no allocation, no copy). */
double rcb_strtod(const char *str, char **endp);
/* The same, reading eight bytes at a time where they lie before lim: the
 * end of the memory readable from str (past the string's NUL; NULL: none). */
double rcb_strtod_in(const char *str, const char *lim, char **endp);

/* ---- core/text.c ---- */
/* Case-insensitive Levenshtein distance of two names ((size_t)-1 beyond 160
 * characters), for "did you mean" suggestions. */
size_t rcb_edit_distance(const char *a, const char *b);

/* ---- model/ ---- */
typedef struct rcb_material_s {
  char name[RCB_NAME_MAX];
  double rho, E, nu; /* kg/m^3, Pa, - */
} rcb_material_t;

typedef struct rcb_segment_s {
  double L, od, id; /* m */
  int nel;
} rcb_segment_t;

typedef struct rcb_shaft_s {
  char name[RCB_NAME_MAX];
  size_t material;
  double z0;          /* m */
  double kappa;       /* shear factor */
  double qz_m, qz_k;  /* proportional damping 1/s, s */
  rcb_segment_t *seg;
  size_t nseg, capseg;
  /* Per-element factors (issue #23), two per element in z order, grown with
   * the segments (model.c) and owned like them: ef[2 k] multiplies element
   * k's E and G (its whole K), ef[2 k + 1] its density (M and G); neutral 1.
   * Parameters shaft.NAME.e<k+1>.stiffness | mass (element_params.c). */
  double *ef;
  size_t nef, capef; /* nef: elements of the shaft so far; capef: doubles allocated */
  /* Shaft-wide factors (issue #33): sf[0] multiplies E and G of every element
   * of the shaft, sf[1] its density, on top of ef; neutral 1. Parameters
   * shaft.NAME.stiffness | mass (params.c); INI stiffness_factor | mass_factor. */
  double sf[2];
  size_t first_node, nnodes; /* after finalize */
} rcb_shaft_t;

/* A position on a shaft, resolved to a node by finalize. */
typedef struct rcb_place_s {
  size_t shaft;
  double z;   /* m */
  size_t node;
} rcb_place_t;

typedef struct rcb_disk_s {
  char name[RCB_NAME_MAX];
  rcb_place_t at;
  double m, Id, Ip; /* kg, kg m^2, kg m^2 */
} rcb_disk_t;

typedef struct rcb_bearing_s {
  char name[RCB_NAME_MAX];
  rcb_place_t at;
  size_t n;             /* table rows (1 = constant) */
  double *speeds;       /* rad/s, n of them */
  rcb_bearing_coefs *c; /* n of them */
  /* Flexible support: with has_ped the bearing joins the shaft node to a
   * pedestal (x, y DOFs, mass ped_m) that springs/dampers hold to ground;
   * without it the bearing goes to ground. ped_node is the pedestal's
   * virtual node (n_nodes + k), ped_dof its matrix rows (after finalize). */
  int has_ped;
  double ped_m;              /* kg, on x and y */
  double ped_k[2], ped_c[2]; /* N/m, N s/m: x, y, pedestal to ground */
  size_t ped_node;
  long ped_dof[2];
} rcb_bearing_t;

typedef struct rcb_coupling_s {
  char name[RCB_NAME_MAX];
  rcb_coupling_model type;
  rcb_place_t at[2];
  rcb_coupling_params p;
} rcb_coupling_t;

typedef struct rcb_unbalance_s {
  char name[RCB_NAME_MAX];
  rcb_place_t at;
  double amount, phase; /* kg m, rad */
} rcb_unbalance_t;

typedef struct rcb_probe_s {
  char name[RCB_NAME_MAX];
  rcb_place_t at;
} rcb_probe_t;

/* One station name -> node (built by finalize, definition order). */
typedef struct rcb_station_s {
  char name[2 * RCB_NAME_MAX + 2];
  rcb_station_kind kind;
  size_t index; /* into the owning array */
  size_t node;
} rcb_station_t;

/* UFF node number -> station name (INI [uff] map). */
typedef struct rcb_uffmap_s {
  long node;
  char station[2 * RCB_NAME_MAX + 2];
} rcb_uffmap_t;

/* A finalize warning (implausible value, unconnected shafts): the text starts
 * "KIND 'NAME'" so the INI loader can prefix the item's file:line. */
#define RCB_WARNING_MAX 384
typedef struct rcb_warning_s {
  char text[RCB_WARNING_MAX];
} rcb_warning_t;

typedef struct rcb_node_s {
  size_t shaft;
  double z;     /* m */
  long dof[4];  /* reduced matrix row of each DOF */
} rcb_node_t;

typedef struct rcb_element_s {
  size_t shaft, node0; /* element joins node0 and node0+1 */
  size_t k;            /* 0-based index within its shaft, z order (factors: ef[2 k]) */
  double L, od, id;    /* m */
} rcb_element_t;

#define RCB_ARRAY(type, name) \
  type *name;                 \
  size_t n_##name, cap_##name

struct rcb_model {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
  int finalized;
  RCB_ARRAY(rcb_material_t, materials);
  RCB_ARRAY(rcb_shaft_t, shafts);
  RCB_ARRAY(rcb_disk_t, disks);
  RCB_ARRAY(rcb_bearing_t, bearings);
  RCB_ARRAY(rcb_coupling_t, couplings);
  RCB_ARRAY(rcb_unbalance_t, unbalances);
  RCB_ARRAY(rcb_probe_t, probes);
  RCB_ARRAY(rcb_uffmap_t, uffmap);
  /* built by finalize */
  RCB_ARRAY(rcb_station_t, stations);
  RCB_ARRAY(rcb_node_t, nodes);
  RCB_ARRAY(rcb_element_t, elements);
  RCB_ARRAY(rcb_warning_t, warnings); /* model/warnings.c */
  size_t n_peds;    /* bearings with a pedestal (virtual nodes after n_nodes) */
  double speed_factor; /* real rotor speed / stated speed in the gyroscopic and
                          bearing terms (1: as stated; [model] speed_factor) */
  size_t ndof;      /* independent DOFs */
  size_t bandwidth; /* max |row - col| of any nonzero (kl = ku) */
  int has_test_speed; /* [test] rpm given (model/test_speed.c) */
  double test_speed;  /* rad/s: rotor speed of the measurements to compare with */
};

/* model/warnings.c: rebuild m->warnings (called by finalize once the mesh
 * exists); RCB_ERR_NOMEM only. */
rcb_status rcb_model_collect_warnings(rcb_model *m);
/* model/plausibility.c: refuse magnitudes that overflow (finalize, before the
 * mesh); warn on layouts that are legal but likely wrong (from
 * collect_warnings); add one warning. */
rcb_status rcb_model_check_magnitudes(rcb_model *m);
rcb_status rcb_model_check_plausible(rcb_model *m);
rcb_status rcb_model_add_warning(rcb_model *m, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* ---- model/coupling_models.c: the one table of the five coupling models ---- */
#define RCB_COUPLING_MODEL_COUNT 5
/* Coefficient bits of rcb_coupling_uses, in the order kt, kr, ct, cr (the
 * order of rcb_coupling_coef_key and rcb_coupling_coef). */
#define RCB_CPL_KT 0x1u
#define RCB_CPL_KR 0x2u
#define RCB_CPL_CT 0x4u
#define RCB_CPL_CR 0x8u
/* Which of kt, kr, ct, cr model t uses (0 for an invalid t). */
unsigned rcb_coupling_uses(rcb_coupling_model t);
/* DOFs of station a tied to those of station b, first ones first: 0, 2
 * (x, y: Kramer) or 4 (rigid). */
int rcb_coupling_tied(rcb_coupling_model t);
/* INI key of coefficient k (0..3: "kt", "kr", "ct", "cr"), NULL otherwise. */
const char *rcb_coupling_coef_key(int k);
/* Storage of coefficient k (0..3) in p. */
double *rcb_coupling_coef(rcb_coupling_params *p, int k);

/* ---- elements/ : local matrices, 8x8 column-major on
 * [x0, y0, rx0, ry0, x1, y1, rx1, ry1] for shafts, 4x4 on [x, y, rx, ry]. ---- */
typedef struct rcb_beam_props_s {
  double L, od, id;      /* m */
  double rho, E, nu;     /* kg/m^3, Pa, - */
  double kappa;          /* shear factor (0 disables shear: Rayleigh beam) */
} rcb_beam_props;
void rcb_shaft_element(const rcb_beam_props *p, double Me[64], double Ge[64], double Ke[64]);
void rcb_disk_element(double m, double Id, double Ip, double Md[16], double Gd[16]);

/* elements/coupling.c: the coupling's springs and dampers between station a
 * and station b, 8x8 on [a: x, y, rx, ry, b: x, y, rx, ry]: [k -k; -k k]
 * with k = diag(t, t, r, r), t = kt (Ke) or ct (Ce), r = kr or cr, each 0
 * unless model t uses it (rcb_coupling_uses; paper section 3). The hubs are
 * rigid disks (rcb_disk_element); tied DOFs share a matrix row, where the
 * block's terms of a tied pair cancel. */
void rcb_coupling_element(rcb_coupling_model t, const rcb_coupling_params *p, double Ke[64],
                          double Ce[64]);

/* elements/bearing.c. Coefficients of a bearing table at a rotor speed
 * (rad/s): linear interpolation between the rows (speeds strictly
 * increasing, n >= 1; speeds unused when n == 1), held constant outside. */
void rcb_bearing_interp(size_t n, const double *speeds, const rcb_bearing_coefs *rows,
                        double speed, rcb_bearing_coefs *out);
/* The same for a model's bearing. */
void rcb_bearing_eval(const rcb_bearing_t *b, double speed, rcb_bearing_coefs *out);
/* A bearing's stiffness and damping blocks, column-major nd x nd with nd the
 * return value: on [shaft x, y] (nd = 2, the bearing to ground) or, with a
 * pedestal, on [shaft x, y, pedestal x, y] (nd = 4): [B -B; -B B] with
 * B = [kxx kxy; kyx kyy] (rows: force x, y; columns: displacement x, y).
 * Only the first nd * nd entries of Kb and Cb are written. */
int rcb_bearing_element(const rcb_bearing_coefs *c, int pedestal, double Kb[16], double Cb[16]);
/* A pedestal's own mass, springs and dampers to ground, 2x2 diagonal on its
 * [x, y]: M = m I, K = diag(kx, ky), C = diag(cx, cy). */
void rcb_pedestal_element(double mass, const double k[2], const double c[2], double Mp[4],
                          double Cp[4], double Kp[4]);

#endif /* RCB_INTERNAL_H */
