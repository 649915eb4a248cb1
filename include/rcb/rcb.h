/**
 * @file rcb.h
 * @brief librcb umbrella header: lateral dynamics of rotor-coupling-bearing
 * systems (model, FRFs, unbalance response, modes, Campbell,
 * measurements, signals -> FRFs, identification, diagnosis, condition
 * monitoring).
 */
#ifndef RCB_H
#define RCB_H

#include "rcb/rcb_core.h"
#include "rcb/rcb_model.h"
#include "rcb/rcb_analysis.h"
#include "rcb/rcb_measure.h"
#include "rcb/rcb_identify.h"
#include "rcb/rcb_compare.h"
#include "rcb/rcb_diagnose.h"
#include "rcb/rcb_monitor.h"
#include "rcb/rcb_transient.h"
#include "rcb/rcb_signal.h"

#endif /* RCB_H */
