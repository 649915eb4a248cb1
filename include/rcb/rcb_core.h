/**
 * @file rcb_core.h
 * @brief librcb basics: version, status codes, allocator hooks, complex type.
 *
 * Conventions used by the whole library (SI units throughout):
 *  - 4 degrees of freedom per node, ordered [x, y, rot_x, rot_y]
 *    (m, m, rad, rad); the rotor spins at +Omega about +z.
 *  - Equation of motion M q'' + (C + Omega G) q' + K q = f.
 *  - Phasors q(t) = Re(Q e^{i w t}), so H(w) = [K - w^2 M + i w (C + Omega G)]^-1.
 *  - Speeds and frequencies in rad/s inside the library; rpm and Hz only at
 *    the command-line edge.
 */
#ifndef RCB_CORE_H
#define RCB_CORE_H

#include <stddef.h>

#include "rcb/rcb_export.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RCB_VERSION_MAJOR 0
#define RCB_VERSION_MINOR 1
#define RCB_VERSION_PATCH 0
#define RCB_VERSION_NUMBER \
  (RCB_VERSION_MAJOR * 10000 + RCB_VERSION_MINOR * 100 + RCB_VERSION_PATCH)

/** @brief Runtime version, RCB_VERSION_NUMBER of the library actually linked. */
RCB_API int rcb_version_number(void);
/** @brief Runtime version string "MAJOR.MINOR.PATCH". */
RCB_API const char *rcb_version_string(void);

/**
 * Status codes: 0 success, negative error. One X-macro list generates both the
 * enum and rcb_status_str().
 */
#define RCB_STATUS_LIST(X)                                                  \
  X(RCB_OK, 0, "success")                                                   \
  X(RCB_ERR_NOMEM, -1, "out of memory")                                     \
  X(RCB_ERR_ARG, -2, "invalid argument")                                    \
  X(RCB_ERR_PARSE, -3, "malformed model description")                       \
  X(RCB_ERR_MODEL, -4, "inconsistent model")                                \
  X(RCB_ERR_NOT_FOUND, -5, "name not found")                                \
  X(RCB_ERR_STATE, -6, "call out of order")                                 \
  X(RCB_ERR_SINGULAR, -7, "singular system matrix")                         \
  X(RCB_ERR_LAPACK, -8, "LAPACK routine failed")                            \
  X(RCB_ERR_IO, -9, "input/output error")                                   \
  X(RCB_ERR_UNSUPPORTED, -10, "feature not built into this library")        \
  X(RCB_ERR_WORKSPACE, -11, "caller workspace too small")                  \
  X(RCB_ERR_NOT_CONVERGED, -12, "iteration did not converge")              \
  X(RCB_ERR_CORRUPT, -13, "saved data corrupt (checksum or layout)")        \
  X(RCB_ERR_VERSION, -14, "saved data of another format version")          \
  X(RCB_ERR_OTHER_MODEL, -15, "saved state of another model")              \
  X(RCB_ERR_OTHER_SETUP, -16, "saved state of another set-up or settings")

#define RCB_STATUS_ENUM_(name, value, text) name = (value),
typedef enum rcb_status { RCB_STATUS_LIST(RCB_STATUS_ENUM_) } rcb_status;
#undef RCB_STATUS_ENUM_

/** @brief Short English text for a status code (never NULL). */
RCB_API const char *rcb_status_str(rcb_status s);

/**
 * @brief Allocator hooks, one set per object. A NULL rcb_allocator pointer, or
 * NULL members, mean malloc/free. @c alloc returns NULL on failure.
 */
typedef struct rcb_allocator {
  void *(*alloc)(void *user, size_t size);
  void (*free)(void *user, void *ptr);
  void *user;
} rcb_allocator;

/* Complex numbers: C99 double _Complex (layout double[2], as LAPACK and KLU
 * expect), with a struct fallback for C++ and compilers without complex. */
#if defined(__cplusplus) || defined(__STDC_NO_COMPLEX__)
typedef struct rcb_complex {
  double re, im;
} rcb_complex;
#else
typedef double _Complex rcb_complex;
#endif

/** @brief Degree-of-freedom direction within a node. */
typedef enum rcb_dir {
  RCB_DIR_X = 0,  /**< translation x, m */
  RCB_DIR_Y = 1,  /**< translation y, m */
  RCB_DIR_RX = 2, /**< rotation about x, rad */
  RCB_DIR_RY = 3  /**< rotation about y, rad */
} rcb_dir;

/** @brief A model degree of freedom: node index (0-based) and direction. */
typedef struct rcb_dof {
  size_t node;
  rcb_dir dir;
} rcb_dof;

#ifdef __cplusplus
}
#endif

#endif /* RCB_CORE_H */
