/*
 * The monitor object (rcb_monitor.h), private to monitor/. monitor/ comes
 * after diagnose/ in the data flow and uses the public API and the
 * documented internal interfaces only (identify/identify.h,
 * diagnose/diagnose.h, core).
 */
#ifndef RCB_MONITOR_INTERNAL_H
#define RCB_MONITOR_INTERNAL_H

#include "core/rcb_internal.h"
#include "rcb/rcb_monitor.h"

#endif
