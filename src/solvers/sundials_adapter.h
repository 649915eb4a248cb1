/*
 * The one place that knows the SUNDIALS major version. SUNDIALS 7 changed
 * SUNContext_Create (a SUNComm instead of void *) and replaced the per-module
 * error handlers (CVodeSetErrHandlerFn) by handlers on the context; the rest
 * of the CVODE / N_Vector / SUNMatrix / SUNLinearSolver calls the transient
 * analysis uses are the same in 6.x and 7.x.
 */
#ifndef RCB_SUNDIALS_ADAPTER_H
#define RCB_SUNDIALS_ADAPTER_H

#include "rcb/rcb_config.h"

#if RCB_WITH_SUNDIALS
#include <sundials/sundials_context.h>

/* Receives every SUNDIALS error or warning instead of stderr (the library
 * never prints). @p code is the module's return flag (negative), or 0 for a
 * warning. */
typedef void (*rcb_sun_msg_fn)(void *user, int code, const char *func, const char *msg);

/* Where messages go; owned by the caller's object, must outlive the solver. */
typedef struct rcb_sun_route_s {
  rcb_sun_msg_fn fn;
  void *user;
} rcb_sun_route;

/* A context for one object: 0 on success. */
int rcb_sun_context_create(SUNContext *ctx);
void rcb_sun_context_free(SUNContext *ctx);

/* Route the messages of a CVODE instance (and its context) to @p route.
 * 0 on success. */
int rcb_sun_cvode_messages(void *cvode_mem, SUNContext ctx, rcb_sun_route *route);
#endif

#endif
