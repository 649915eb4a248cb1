/* Helpers shared by the model builder, the finalizer and the INI loader. */
#ifndef RCB_MODEL_UTIL_H
#define RCB_MODEL_UTIL_H

#include "core/rcb_internal.h"

/* Write the model's error message, return st. */
rcb_status rcb_model_fail(rcb_model *m, rcb_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
#ifdef __clang_analyzer__ /* returns st: see rcb_set_error in core/rcb_internal.h */
#define rcb_model_fail(o, st, ...) ((void)(rcb_model_fail)((o), (st), __VA_ARGS__), (st))
#endif

/* Check a numeric input: finite always; sign > 0 requires v > 0, sign == 0
 * requires v >= 0, sign < 0 accepts any finite value. */
rcb_status rcb_model_check_value(rcb_model *m, const char *kind, const char *name,
                                 const char *what, double v, int sign);

#endif
