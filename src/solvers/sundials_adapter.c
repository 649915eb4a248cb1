/*
 * SUNDIALS 6 / 7 differences, isolated (see sundials_adapter.h). Built only
 * with RCB_WITH_SUNDIALS. Checked against 6.4 (Debian 12); the 7.x branch
 * follows the 7.0 API (SUNComm, SUNContext error handlers, logger) and has
 * not been compiled here.
 */
#include "solvers/sundials_adapter.h"

#if RCB_WITH_SUNDIALS
#include <cvode/cvode.h>
#include <stddef.h>
#include <sundials/sundials_config.h>

#if SUNDIALS_VERSION_MAJOR >= 7
#include <sundials/sundials_errors.h>
#include <sundials/sundials_logger.h>
#endif

int rcb_sun_context_create(SUNContext *ctx) {
#if SUNDIALS_VERSION_MAJOR >= 7
  return SUNContext_Create(SUN_COMM_NULL, ctx) == 0 ? 0 : -1;
#else
  return SUNContext_Create(NULL, ctx) == 0 ? 0 : -1;
#endif
}

void rcb_sun_context_free(SUNContext *ctx) {
  if (ctx && *ctx) SUNContext_Free(ctx);
}

#if SUNDIALS_VERSION_MAJOR >= 7
/* SUNDIALS 7: one handler per context; CVODE's return flag reaches the
 * caller through the CVode() return value, the handler gives the text. */
static int sun7_handler(int line, const char *func, const char *file, const char *msg,
                        SUNErrCode code, void *data, SUNContext ctx) {
  const rcb_sun_route *r = data;
  (void)line;
  (void)file;
  (void)ctx;
  if (r && r->fn) r->fn(r->user, code < 0 ? (int)code : 0, func, msg);
  return 0;
}
#else
/* CVODE 6: error_code is the CV_ flag (negative), CV_WARNING (99) for
 * warnings. */
static void cv6_handler(int error_code, const char *module, const char *function, char *msg,
                        void *eh_data) {
  const rcb_sun_route *r = eh_data;
  (void)module;
  if (r && r->fn) r->fn(r->user, error_code < 0 ? error_code : 0, function, msg);
}
#endif

int rcb_sun_cvode_messages(void *cvode_mem, SUNContext ctx, rcb_sun_route *route) {
#if SUNDIALS_VERSION_MAJOR >= 7
  SUNLogger logger = NULL;
  (void)cvode_mem;
  SUNContext_ClearErrHandlers(ctx);
  if (SUNContext_GetLogger(ctx, &logger) == 0 && logger) {
    SUNLogger_SetErrorFilename(logger, "");
    SUNLogger_SetWarningFilename(logger, "");
  }
  return SUNContext_PushErrHandler(ctx, sun7_handler, route) == 0 ? 0 : -1;
#else
  (void)ctx;
  return CVodeSetErrHandlerFn(cvode_mem, cv6_handler, route) == 0 ? 0 : -1;
#endif
}
#endif
