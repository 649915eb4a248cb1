/*
 * rcb_monitor_separating: which measurement would tell a tracked parameter
 * from the candidate effect the monitor cannot separate from it (issue #24
 * item 3). Not a second rule: the diagnosis' plan (rcb_diagnose.h, rcb_plan)
 * answers it on the monitor's baseline model and set-up, and its verdict
 * (rcb_evidence_separable on the separating chi-square) decides.
 */
#include <stdio.h>
#include <string.h>

#include "monitor/monitor_internal.h"

static rcb_status plan_err(rcb_monitor *mon, rcb_plan *p, rcb_status st, const char *what) {
  return rcb_mon_fail(mon, st, "separating measurement: %s: %s", what,
                      p ? rcb_plan_errmsg(p) : rcb_status_str(st));
}

rcb_status rcb_monitor_separating(rcb_monitor *mon, size_t tracked, size_t cand,
                                  const double *speeds, size_t nspeeds,
                                  rcb_monitor_separator *out) {
  rcb_plan *p = NULL;
  rcb_plan_result pr;
  rcb_plan_candidate pc;
  const mon_cand *c;
  size_t a;
  rcb_status st;
  if (!mon) return RCB_ERR_ARG;
  if (!out || !mon->y || !mon->k || tracked >= mon->nt || cand >= mon->ncand ||
      (nspeeds && !speeds))
    return rcb_mon_fail(mon, RCB_ERR_ARG, "rcb_monitor_separating: tracked %zu (of %zu), "
                        "candidate %zu (of %zu), an output and the speeds are required",
                        tracked, mon->nt, cand, mon->ncand);
  memset(out, 0, sizeof *out);
  c = &mon->cand[cand];
  if (!c->settable)
    return rcb_mon_fail(mon, RCB_ERR_ARG, "separating measurement: the %s at %s is not a "
                        "parameter of the baseline model (the plan varies the model's own "
                        "parameters only)", c->desc, c->place);
  if (!(mon->beta_a > 0 || mon->beta_s > 0))
    return rcb_mon_fail(mon, RCB_ERR_ARG, "separating measurement: the plan needs the eq. 19 "
                        "noise model (opts.beta_a, beta_s); this monitor was given per-point "
                        "sd only");
  if ((st = rcb_plan_create(&p, mon->model, mon->setup, &mon->alloc)))
    st = plan_err(mon, p, st, "plan");
  for (a = 0; !st && a < c->np; a++)
    if ((st = rcb_plan_add_param(p, 0, c->pname[a]))) st = plan_err(mon, p, st, c->pname[a]);
  /* the tracked parameter first, the others free beside it */
  if (!st && (st = rcb_plan_add_param(p, 1, mon->tname[tracked])))
    st = plan_err(mon, p, st, mon->tname[tracked]);
  for (a = 0; !st && a < mon->nt; a++)
    if (a != tracked && (st = rcb_plan_add_param(p, 1, mon->tname[a])))
      st = plan_err(mon, p, st, mon->tname[a]);
  if (!st && (st = rcb_plan_set_noise_model(p, mon->beta_a, mon->beta_s)))
    st = plan_err(mon, p, st, "noise model");
  for (a = 0; !st && a < nspeeds; a++)
    if ((st = rcb_plan_add_speed(p, speeds[a]))) st = plan_err(mon, p, st, "speed");
  if (!st && (st = rcb_plan_run(p))) st = plan_err(mon, p, st, "plan");
  if (!st && (st = rcb_plan_get_result(p, &pr))) st = plan_err(mon, p, st, "result");
  if (!st) {
    out->present_separable = pr.separable;
    out->chi2_present = pr.chi2_sep;
    out->angle_deg = pr.angle_deg;
    /* the plan ranks by gain: its first candidate separates them if any does */
    if (!pr.separable && pr.candidates && rcb_plan_get_candidate(p, 0, &pc) == RCB_OK &&
        rcb_evidence_separable(pc.chi2_after, 0.0)) {
      out->found = 1;
      snprintf(out->response, sizeof out->response, "%s", pc.response);
      snprintf(out->reference, sizeof out->reference, "%s", pc.reference);
      out->speed = pc.speed;
      out->chi2_after = pc.chi2_after;
      out->level_db = pc.level_db;
    }
  }
  rcb_plan_destroy(p);
  return st;
}
