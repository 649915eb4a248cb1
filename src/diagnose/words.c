/*
 * The words of a diagnosis (rcb_diag_explain): what the best candidate
 * claims, or that nothing is needed or found; the rival the data cannot
 * separate; where the misfit concentrates (a sensor) or is placed (a node, a
 * span); and a baseline that ran off from the nominal model. Also the one
 * rule on the model as it is (rcb_diag_base_adequate), which locate.c asks
 * too.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "diagnose/diag_internal.h"
#include "diagnose/tuning.h"

static rcb_status put_text(const char *text, char *buf, size_t size, size_t *needed) {
  size_t n = strlen(text) + 1;
  if (needed) *needed = n;
  if (!buf || size < n) {
    if (buf && size) buf[0] = '\0';
    return RCB_ERR_WORKSPACE;
  }
  memcpy(buf, text, n);
  return RCB_OK;
}

/* Where the misfit of the model as it is concentrates, in words (appended
 * to text at n; nothing without a known noise). */
static size_t say_where(const rcb_diag *d, char *text, size_t size, size_t n) {
  size_t k, shown = 0;
  if (!d->nmis || n >= size) return n;
  if (d->mis[0].concentrated) {
    const rcb_diag_misfit *s = &d->mis[0];
    char nm[RCB_DIAG_NAME + 16], carry[RCB_DIAG_CARRY] = "";
    snprintf(nm, sizeof nm, "sensor.%s.gain", s->sensor);
    if (!rcb_diag_is_base(d, nm)) /* its gain not fitted already: say how */
      rcb_diag_carry_text(d, RCB_EFFECT_SENSOR_GAIN, s->sensor, NULL, carry, sizeof carry);
    n += (size_t)snprintf(text + n, size - n,
                          " The misfit concentrates on sensor %s (chi-square %.3g x what the "
                          "noise leaves there, %.0f %% of the excess): check this sensor (gain, "
                          "phase, sign, direction, mounting) before the model%s%s.",
                          s->sensor, s->chi2 / s->expected, s->excess_pct,
                          carry[0] ? ", or fit its gain with " : "", carry);
    return n < size ? n : size - 1;
  }
  n += (size_t)snprintf(text + n, size - n, " The misfit is spread over the sensors; the "
                        "largest excesses over the noise:");
  for (k = 0; k < d->nmis && shown < 3 && n < size; k++, shown++)
    n += (size_t)snprintf(text + n, size - n, "%s %s (%.0f %%)", shown ? "," : "",
                          d->mis[k].sensor, d->mis[k].excess_pct);
  if (n < size) n += (size_t)snprintf(text + n, size - n, ".");
  return n < size ? n : size - 1;
}

/* Where along a shaft the local candidates point (appended to text at n):
 * the significant candidates that sit at nodes (DIAG_FAM_PLACE_WALK) among
 * the first RCB_DIAG_SPAN_RANKS ranks, on the shaft of the best of them, as
 * a span of z. Nothing when none is significant. */
static size_t say_span(const rcb_diag *d, char *text, size_t size, size_t n) {
  const rcb_model *m = d->base_model;
  size_t k, shaft = 0, lo = 0, hi = 0, found = 0;
  for (k = 0; k < d->ncand && k < RCB_DIAG_SPAN_RANKS; k++) {
    const diag_cand *c = &d->cand[d->order[k]];
    if (!(c->fam->flags & DIAG_FAM_PLACE_WALK) || !c->node || !c->refitted ||
        c->claim == RCB_CLAIM_NONE || c->node > m->n_nodes)
      continue;
    if (!found) shaft = c->shaft, lo = hi = c->node - 1;
    if (c->shaft != shaft) continue;
    if (c->node - 1 < lo) lo = c->node - 1;
    if (c->node - 1 > hi) hi = c->node - 1;
    found++;
  }
  if (!found || n >= size) return n;
  if (lo == hi)
    n += (size_t)snprintf(text + n, size - n,
                          " The local candidates point to shaft %s at z = %.3g m (node #%zu): "
                          "an effect there that the catalogue lacks is possible.",
                          m->shafts[shaft].name, m->nodes[lo].z, lo);
  else
    n += (size_t)snprintf(text + n, size - n,
                          " The local candidates point to shaft %s between z = %.3g and %.3g m "
                          "(nodes #%zu-#%zu): an effect there that the catalogue lacks is "
                          "possible.",
                          m->shafts[shaft].name, m->nodes[lo].z, m->nodes[hi].z, lo, hi);
  return n < size ? n : size - 1;
}

/* Where the equivalent loads place the misfit of the model as it is
 * (locate.c), appended to text at n: the best node, its share, whether a
 * load there alone accounts for it, and the runs of neighbouring nodes the
 * data cannot separate from it; or that no one node takes
 * RCB_DIAG_PLACE_LOCAL % of it. */
static const rcb_diag_place *span_at(const rcb_diag *d, size_t node, const char *shaft) {
  size_t j;
  for (j = 0; j < d->nplace; j++)
    if (d->place[j].in_span && d->place[j].node == node &&
        (!shaft || strcmp(d->place[j].shaft, shaft) == 0))
      return &d->place[j];
  return NULL;
}
static size_t say_place(const rcb_diag *d, char *text, size_t size, size_t n) {
  const rcb_diag_place *b = d->place;
  size_t runs = 0, lo, hi;
  if (!d->nplace || n >= size) return n;
  if (b->share_pct < RCB_DIAG_PLACE_LOCAL) {
    n += (size_t)snprintf(text + n, size - n,
                          " No one place takes most of the misfit: a force at one node takes at "
                          "most %.0f %% of its excess over the noise (shaft %s, z = %.3g m, node "
                          "#%zu), so the missing effect is not local to one node, or there are "
                          "several.",
                          b->share_pct, b->shaft, b->z, b->node);
    return n < size ? n : size - 1;
  }
  if (b->at_drive) { /* one excitation point, and the misfit placed at it: no evidence */
    n += (size_t)snprintf(text + n, size - n,
                          " The equivalent loads cannot place it: the data hold one excitation "
                          "point (shaft %s, z = %.3g m, node #%zu), and a force there, where it "
                          "takes %.0f %% of the misfit's excess over the noise, takes any misfit "
                          "shaped like the response to the drive, as a mode moved by an effect "
                          "anywhere gives it. A second excitation point (another node) would "
                          "place it.",
                          b->shaft, b->z, b->node, b->share_pct);
    return n < size ? n : size - 1;
  }
  if (b->adequate)
    n += (size_t)snprintf(text + n, size - n,
                          " Placed by equivalent loads, whatever the effect: a force at shaft %s, "
                          "z = %.3g m (node #%zu) takes %.0f %% of the misfit's excess over the "
                          "noise and leaves the noise alone (chi-square %.6g within its 1 %% "
                          "limit): the missing effect sits there",
                          b->shaft, b->z, b->node, b->share_pct, b->chi2);
  else
    n += (size_t)snprintf(text + n, size - n,
                          " Placed by equivalent loads, whatever the effect: a force at one node "
                          "takes at most %.0f %% of the misfit's excess over the noise (shaft %s, "
                          "z = %.3g m, node #%zu) and leaves more than the noise (chi-square "
                          "%.6g for %.0f degrees of freedom), so the data place it along a span, "
                          "not at one node",
                          b->share_pct, b->shaft, b->z, b->node, b->chi2, b->dof);
  /* the nodes the data cannot separate from it, in node order, as runs of
   * neighbours on one shaft */
  for (lo = 0; lo < d->nplace && n < size && runs < 4; lo++) {
    const rcb_diag_place *pl = span_at(d, lo, NULL), *ph;
    if (!pl) continue;
    for (hi = lo, ph = pl; span_at(d, hi + 1, pl->shaft);) ph = span_at(d, ++hi, NULL);
    if (!runs && lo == hi && lo == b->node) break; /* the best node alone */
    n += (size_t)snprintf(text + n, size - n, "%s",
                          runs ? ","
                          : b->adequate ? "; these data cannot separate it from the nodes of"
                                        : "; the nodes that leave at most twice as much:");
    if (lo == hi)
      n += (size_t)snprintf(text + n, size - n, " shaft %s z = %.3g m (#%zu)", pl->shaft, pl->z,
                            lo);
    else
      n += (size_t)snprintf(text + n, size - n, " shaft %s z = %.3g-%.3g m (#%zu-#%zu)",
                            pl->shaft, pl->z, ph->z, lo, hi);
    runs++, lo = hi;
  }
  for (lo = 0; lo < d->nplace && n < size; lo++)
    if (d->place[lo].in_span && d->place[lo].at_drive) {
      n += (size_t)snprintf(text + n, size - n,
                            "; the span holds the only excitation point (node #%zu), where a "
                            "force takes any misfit shaped like the response to the drive",
                            d->place[lo].node);
      break;
    }
  if (n < size)
    n += (size_t)snprintf(text + n, size - n, ". The kind of effect there is left open.");
  return n < size ? n : size - 1;
}

/* A parameter list "a, b" as "a,b" (one shell word). */
static void no_spaces(const char *in, char *out) {
  for (; *in; in++)
    if (*in != ' ') *out++ = *in;
  *out = '\0';
}

/* When the second candidate has the first's claim and the data cannot tell
 * them apart (rcb_evidence_separable), say so and name the plan that would
 * (appended to text at n). Sensor candidates are left out: their rival is
 * a check of the sensor, not a test campaign. */
static size_t say_rival(const rcb_diag *d, char *text, size_t size, size_t n) {
  const diag_cand *a, *b;
  if (!d->cand || !d->order || d->ncand < 2 || n >= size) return n;
  a = &d->cand[d->order[0]], b = &d->cand[d->order[1]];
  if (!a->refitted || !b->refitted || a->claim == RCB_CLAIM_NONE || b->claim != a->claim ||
      rcb_evidence_separable(a->dbic, b->dbic) ||
      ((a->fam->flags | b->fam->flags) & DIAG_FAM_CHAIN) ||
      (a->effect == b->effect && strcmp(a->place, b->place) == 0)) /* one effect, two forms */
    return n;
  {
    char pa[sizeof a->params], pb[sizeof b->params];
    no_spaces(a->params, pa), no_spaces(b->params, pb);
    n += (size_t)snprintf(text + n, size - n,
                          " These data cannot separate it from %s (BIC %+.1f, within %g of it): "
                          "rcb_plan (rcbtool plan --between %s %s) names the measurement that "
                          "would.",
                          b->desc, b->dbic, -RCB_BIC_SIGNIFICANT, pa, pb);
  }
  return n < size ? n : size - 1;
}

/* The evidence of the adequacy test alone (F, its limit, whiteness and
 * dispersion), for the one rule's words on it. */
static rcb_evidence test_evidence(double F, double limit, int white, double phi) {
  rcb_evidence e;
  memset(&e, 0, sizeof e);
  e.chi2 = F, e.chi2_limit = limit, e.white = white, e.dispersion = phi;
  return e;
}

/* Whether the model as it is fits the data to their noise, by the one rule
 * (diag_internal.h; locate.c asks it too). */
int rcb_diag_base_adequate(const rcb_diag *d) {
  rcb_evidence e;
  if (!d->adeq0.known) return -1;
  e = test_evidence(d->adeq0.chi2, d->adeq0.limit, d->adeq0.white, d->adeq0.dispersion);
  return rcb_evidence_adequate(&e);
}

/* What a white residual too far above the declared noise leaves open. */
#define OPEN_QUESTION                                                                    \
  "either the noise is declared too low or the model misses something these lines cannot " \
  "localise; the data cannot tell which"

/* The adequacy test in words: F against its limit, and when above it
 * with a white residual, what the one rule lets that mean
 * (rcb_evidence_white_noise): noise of another level, or an open question. */
static void say_test(char *t, size_t size, double F, double limit, int white, double phi) {
  rcb_evidence e = test_evidence(F, limit, white, phi);
  if (F <= limit || !white)
    snprintf(t, size, "chi-square %.6g %s the adequacy limit %.6g at 1 %%", F,
             F <= limit ? "within" : "above", limit);
  else if (rcb_evidence_white_noise(&e))
    snprintf(t, size, "chi-square %.6g above the adequacy limit %.6g at 1 %%, and what is left is "
             "white along frequency: noise about %.3g x the declared level, not a missing effect",
             F, limit, rcb_evidence_level(&e));
  else
    snprintf(t, size, "chi-square %.6g above the adequacy limit %.6g at 1 %%; what is left is "
             "white along frequency but about %.3g x the declared noise, more than the %g x a "
             "misdeclared level may be: " OPEN_QUESTION,
             F, limit, rcb_evidence_level(&e), RCB_WHITE_LEVEL_MAX);
}

static const char *trend(double before, double after) {
  return after < before ? "falls" : after > before ? "rises" : "stays";
}

rcb_status rcb_diag_explain(const rcb_diag *d, char *buf, size_t size, size_t *needed) {
  char text[3072], test[320], floor_txt[96] = "";
  const diag_cand *c;
  int base_ok;
  size_t n;
  if (!d || !d->ran) return RCB_ERR_STATE;
  base_ok = rcb_diag_base_adequate(d);
  c = d->ncand ? &d->cand[d->order[0]] : NULL;
  if (isfinite(d->floor0))
    snprintf(floor_txt, sizeof floor_txt, " (noise floor %.3g %%)", d->floor0);
  if (c && c->refitted && c->claim == RCB_CLAIM_EXPLAINS) {
    say_test(test, sizeof test, c->adeq_chi2, c->chi2_limit, c->white_z <= RCB_ADEQUACY_Z,
             c->dispersion);
    if (c->fam->flags & DIAG_FAM_CHAIN)
      snprintf(text, sizeof text,
               "The measurement chain, not the model: %s (%s). Read through it, the data fit "
               "the model as it is: the error %s from %.3g %% to %.3g %%%s, BIC %+.1f, %s. "
               "Check or recalibrate this sensor, or read the data through the correction in "
               "the next round (rcbtool fit or diagnose with %s); the model is not changed.",
               c->desc, c->fitted, trend(d->err0, c->err), d->err0, c->err, floor_txt, c->dbic,
               test, c->carry ? c->carry : "");
    else
      snprintf(text, sizeof text,
               "Missing: %s. Adding it (%s) explains the misfit: the error %s from %.3g %% "
               "to %.3g %%%s, BIC %+.1f, and the model with it passes the adequacy test (%s).",
               c->desc, c->fitted, trend(d->err0, c->err), d->err0, c->err, floor_txt, c->dbic,
               test);
  } else if (c && c->refitted && c->claim == RCB_CLAIM_IMPROVES) {
    if (c->beyond) {
      say_test(test, sizeof test, c->adeq_chi2, c->chi2_limit, c->white_z <= RCB_ADEQUACY_Z,
               c->dispersion);
      snprintf(text, sizeof text,
               "The best candidate, %s (%s), lowers the misfit by %.1f %% (the error %s from "
               "%.3g %% to %.3g %%%s; %s), but its fitted %s = %.4g is beyond what the part can "
               "be (%.4g at most): it stands in for an effect of another kind, or one outside "
               "the catalogue, and does not explain the data.",
               c->desc, c->fitted, 100.0 * (d->F0 - c->F) / d->F0, trend(d->err0, c->err),
               d->err0, c->err, floor_txt, isfinite(c->chi2_limit) ? test : "noise unknown",
               c->pname[c->beyond_k], c->beyond_v, c->phi[c->beyond_k]);
    } else if (isfinite(c->chi2_limit) && c->white_z <= RCB_ADEQUACY_Z) {
      /* white, but too far above the declared noise to be called noise */
      snprintf(text, sizeof text,
               "The best candidate, %s (%s), improves the fit: it accounts for %.1f %% of the "
               "misfit, the error %s from %.3g %% to %.3g %%%s, BIC %+.1f, chi-square %.6g above "
               "the adequacy limit %.6g at 1 %%. What is left is white along frequency (lag-1 "
               "statistic %.3g, 1 %% limit %.3g) but about %.3g x the declared noise, more than "
               "the %g x a misdeclared level may be: " OPEN_QUESTION ".",
               c->desc, c->fitted, 100.0 * (d->F0 - c->F) / d->F0, trend(d->err0, c->err),
               d->err0, c->err, floor_txt, c->dbic, c->adeq_chi2, c->chi2_limit, c->white_z,
               RCB_ADEQUACY_Z, rcb_evidence_level(&c->ev), RCB_WHITE_LEVEL_MAX);
    } else if (isfinite(c->chi2_limit)) {
      say_test(test, sizeof test, c->adeq_chi2, c->chi2_limit, 0, 1.0);
      snprintf(text, sizeof text,
               "The best candidate, %s (%s), accounts for %.1f %% of the misfit but leaves "
               "%.1f %%: the error %s from %.3g %% to %.3g %%, %.2g x the noise floor of "
               "%.3g %% (%s), and what is left is structured along frequency (lag-1 statistic "
               "%.3g above %.3g), not noise. Another effect is missing, possibly outside the "
               "catalogue.",
               c->desc, c->fitted, 100.0 * (d->F0 - c->F) / d->F0, 100.0 * c->F / d->F0,
               trend(d->err0, c->err), d->err0, c->err, c->err / d->floor0, d->floor0, test,
               c->white_z, RCB_ADEQUACY_Z);
    } else {
      snprintf(text, sizeof text,
               "The best candidate, %s (%s), lowers the misfit by %.1f %%: the error %s "
               "from %.3g %% to %.3g %%, BIC %+.1f. Whether the model then fits the data to their "
               "noise cannot be tested: the noise is unknown (give --noise or --sd).",
               c->desc, c->fitted, 100.0 * (d->F0 - c->F) / d->F0, trend(d->err0, c->err),
               d->err0, c->err, c->dbic);
    }
    if ((c->fam->flags & DIAG_FAM_CHAIN) && c->carry && c->carry[0]) /* a sensor: how */
      snprintf(text + strlen(text), sizeof text - strlen(text),
               " Read the data through this correction in the next round: rcbtool fit or "
               "diagnose with %s.", c->carry);
  } else if (base_ok == 1 && d->adeq0.chi2 <= d->adeq0.limit) {
    say_test(test, sizeof test, d->adeq0.chi2, d->adeq0.limit, 0, 1.0);
    snprintf(text, sizeof text,
             "No candidate is significant, and none is needed: the model as it is passes the "
             "adequacy test (%s; error %.3g %%%s).",
             test, d->err0, floor_txt);
  } else if (base_ok == 1) {
    size_t k, nu = 0, w = 0;
    char even[512];
    for (k = 0; k < d->nmis; k++) nu += d->mis[k].uneven != 0;
    if (nu) { /* white, but not even: the sensors that stand out */
      w = (size_t)snprintf(even, sizeof even, "white along frequency (lag-1 statistic %.3g, "
                           "1 %% limit %.3g) but not even over the sensors: ",
                           d->adeq0.white_z, RCB_ADEQUACY_Z);
      for (k = 0; k < d->nmis && w < sizeof even; k++)
        if (d->mis[k].uneven)
          w += (size_t)snprintf(even + w, sizeof even - w,
                                "%s%s (%.0f %% of the excess, its noise about %.3g x the "
                                "declared)",
                                even[w - 1] == ')' ? ", " : "", d->mis[k].sensor,
                                d->mis[k].excess_pct,
                                sqrt(d->mis[k].chi2 / fmax(d->mis[k].expected, 1e-300)));
      if (w < sizeof even)
        snprintf(even + w, sizeof even - w, " %s noisier than the rest",
                 nu > 1 ? "are" : "is");
    } else
      snprintf(even, sizeof even, "white along frequency and even over the sensors (lag-1 "
               "statistic %.3g, 1 %% limit %.3g; no sensor stands out)",
               d->adeq0.white_z, RCB_ADEQUACY_Z);
    snprintf(text, sizeof text,
             "No candidate is significant, and none is needed: the model as it is leaves a "
             "chi-square of %.6g, above the adequacy limit %.6g of the declared noise, but what "
             "it leaves is %s: the noise is about %.3g x the declared level, and nothing is "
             "shown missing (error %.3g %%%s). Declare the noise as measured to test to its "
             "level.",
             d->adeq0.chi2, d->adeq0.limit, even, sqrt(d->adeq0.dispersion), d->err0,
             floor_txt);
  } else if (base_ok == 0 && d->adeq0.white) { /* white, too far above the declared */
    snprintf(text, sizeof text,
             "No candidate is significant: the model as it is leaves an error of %.3g %%%s and "
             "a chi-square of %.6g, above the adequacy limit %.6g at 1 %%, and no effect of the "
             "catalogue is significant (BIC lower by more than %g on the noise's dispersion, "
             "counting the %zu candidates tried). What is left is white along frequency (lag-1 "
             "statistic %.3g, 1 %% limit %.3g) but about %.3g x the declared noise, more than "
             "the %g x a misdeclared level may be: " OPEN_QUESTION ".",
             d->err0, floor_txt, d->adeq0.chi2, d->adeq0.limit, -RCB_BIC_SIGNIFICANT, d->ncand,
             d->adeq0.white_z, RCB_ADEQUACY_Z, sqrt(d->adeq0.dispersion), RCB_WHITE_LEVEL_MAX);
  } else if (base_ok == 0) {
    say_test(test, sizeof test, d->adeq0.chi2, d->adeq0.limit, 0, 1.0);
    snprintf(text, sizeof text,
             "No candidate is significant: the model as it is leaves an error of %.3g %%%s "
             "(%s; structured along frequency, lag-1 statistic %.3g), and no effect of the "
             "catalogue is significant (BIC lower by more than %g on the noise's dispersion, "
             "counting the %zu candidates tried): the missing effect may not be in the "
             "catalogue, or a sensor is at fault.",
             d->err0, floor_txt, test, d->adeq0.white_z, -RCB_BIC_SIGNIFICANT, d->ncand);
  } else {
    snprintf(text, sizeof text,
             "No candidate is significant: no effect of the catalogue lowers BIC by more than "
             "%g while lowering the error (%.3g %%). Whether the model as it is fits the data to their "
             "noise cannot be tested: the noise is unknown (give --noise or --sd).",
             -RCB_BIC_SIGNIFICANT, d->err0);
  }
  n = strlen(text);
  n = say_rival(d, text, sizeof text, n);
  if (!(c && c->refitted && c->claim == RCB_CLAIM_EXPLAINS) && base_ok != 1) {
    n = say_where(d, text, sizeof text, n);
    if (d->nplace && !(d->nmis && d->mis[0].concentrated)) n = say_place(d, text, sizeof text, n);
    else if (!d->nplace) n = say_span(d, text, sizeof text, n);
  }
  if (d->place_no_phase && n < sizeof text)
    n += (size_t)snprintf(text + n, sizeof text - n,
                          " The misfit was not placed along the shaft: placement fits "
                          "equivalent loads on the complex scale and so needs the phase, and "
                          "%zu of the %zu measured channels hold magnitudes only.",
                          rcb_meas_magnitude_only_count(d->meas),
                          rcb_meas_channel_count(d->meas));
  if (n > sizeof text) n = sizeof text;
  if (d->far) /* the run-off baseline is a finding of its own */
    snprintf(text + n, sizeof text - n,
             " The fit of the model as it is ran far from the nominal model (%s): a missing "
             "effect pulls it there; the candidates were also scored at the nominal model, the "
             "best there fitted alone and refitted from where that ended.",
             d->drift);
  return put_text(text, buf, size, needed);
}
