/* Measurement channels -> model DOFs, for the fit and the comparison. */
#include "io/io.h"

/* Index of dof in list[0 .. *n), appending it when new. */
static size_t dof_slot(rcb_dof *list, size_t *n, rcb_dof d) {
  size_t i;
  for (i = 0; i < *n; i++)
    if (list[i].node == d.node && list[i].dir == d.dir) return i;
  list[*n] = d;
  return (*n)++;
}

rcb_status rcb_meas_resolve_dofs(const rcb_meas *ms, const rcb_model *m, rcb_meas_dofs *d,
                                 char *errmsg) {
  size_t c, nch;
  int unbalance;
  if (!ms || !m || !d) return RCB_ERR_ARG;
  nch = rcb_meas_channel_count(ms);
  unbalance = rcb_meas_get_type(ms) == RCB_MEAS_UNBALANCE;
  d->nout = d->nin = 0;
  for (c = 0; c < nch; c++) {
    rcb_meas_channel_info ci;
    rcb_dof dof;
    if (rcb_meas_channel(ms, c, &ci))
      return rcb_set_error(errmsg, RCB_ERR_ARG, "measurement channel %zu: not readable", c + 1);
    if (rcb_model_find_dof(m, ci.response, &dof))
      return rcb_set_error(errmsg, RCB_ERR_NOT_FOUND, "measurement channel %zu: %s", c + 1,
                           rcb_model_errmsg(m));
    d->ch_out[c] = dof_slot(d->outs, &d->nout, dof);
    if (unbalance) continue;
    if (!ci.reference || rcb_model_find_dof(m, ci.reference, &dof))
      return rcb_set_error(errmsg, RCB_ERR_NOT_FOUND, "measurement channel %zu (%s): %s", c + 1,
                           ci.response,
                           ci.reference ? rcb_model_errmsg(m) : "an FRF channel needs a reference");
    d->ch_in[c] = dof_slot(d->ins, &d->nin, dof);
  }
  return RCB_OK;
}
