/*
 * rcb_monitor: commissioning (create) and the allocation-free update.
 * (Stub: the API is fixed, the implementation follows.)
 */
#include <string.h>

#include "monitor/monitor_internal.h"

struct rcb_monitor {
  rcb_allocator alloc;
  char errmsg[RCB_ERRMSG_MAX];
};

rcb_status rcb_monitor_create(rcb_monitor **out, const rcb_model *baseline,
                              const rcb_meas *setup, const rcb_monitor_opts *opts,
                              const rcb_allocator *alloc) {
  rcb_allocator a;
  rcb_monitor *mon;
  (void)baseline, (void)setup, (void)opts;
  if (!out) return RCB_ERR_ARG;
  *out = NULL;
  rcb_allocator_init(&a, alloc);
  if (!(mon = rcb_alloc(&a, sizeof *mon))) return RCB_ERR_NOMEM;
  mon->alloc = a;
  *out = mon;
  return rcb_fail(mon, RCB_ERR_UNSUPPORTED, "rcb_monitor_create: not implemented yet");
}

void rcb_monitor_destroy(rcb_monitor *mon) {
  if (mon) rcb_free(&mon->alloc, mon);
}

const char *rcb_monitor_errmsg(const rcb_monitor *mon) { return mon ? mon->errmsg : "no monitor"; }

rcb_status rcb_monitor_update(rcb_monitor *mon, const rcb_complex *values, const double *sd,
                              rcb_monitor_result *res) {
  (void)values, (void)sd, (void)res;
  if (!mon) return RCB_ERR_ARG;
  return rcb_fail(mon, RCB_ERR_UNSUPPORTED, "rcb_monitor_update: not implemented yet");
}

void rcb_monitor_reset_cusum(rcb_monitor *mon) { (void)mon; }
size_t rcb_monitor_point_count(const rcb_monitor *mon) { (void)mon; return 0; }
size_t rcb_monitor_memory(const rcb_monitor *mon) { (void)mon; return 0; }
rcb_status rcb_monitor_rank(const rcb_monitor *mon, size_t *k, size_t *k_tracked) {
  (void)mon, (void)k, (void)k_tracked;
  return RCB_ERR_UNSUPPORTED;
}
size_t rcb_monitor_candidate_count(const rcb_monitor *mon) { (void)mon; return 0; }
rcb_status rcb_monitor_candidate_info_get(const rcb_monitor *mon, size_t i,
                                          rcb_monitor_candidate_info *out) {
  (void)mon, (void)i, (void)out;
  return RCB_ERR_UNSUPPORTED;
}
rcb_status rcb_monitor_tracked_info(const rcb_monitor *mon, size_t k, const char **name,
                                    double *baseline) {
  (void)mon, (void)k, (void)name, (void)baseline;
  return RCB_ERR_UNSUPPORTED;
}
