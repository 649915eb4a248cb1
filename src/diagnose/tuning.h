/*
 * The tuning constants of the diagnosis flow (rcb_diag_run), in one table:
 * each constant's value and unit, grouped by the stage file that reads it
 * (another file that reads one is named beside it); below the table, the
 * reason for each value and the measurement behind it, in the same order.
 * A constant of the public API (RCB_BIC_SIGNIFICANT,
 * RCB_DIAG_PLACE_LOCAL, RCB_DIAG_MAX_THREADS: include/rcb/rcb_diagnose.h;
 * RCB_ADEQUACY_Z: include/rcb/rcb_identify.h) stays in its header.
 *
 * "8 x 151" and "32 x 1101" are the measurement sizes of bench_diagnose
 * (channels x frequency lines) without and with --large; "the subset" is
 * the frequency subset of rcb_diag_subset_weights, taken where it keeps at
 * most half of the points (32 x 1101, not 8 x 151). An "iteration" is one
 * step of the fit (rcb_fit_set_limits' max_iter); a "sweep" one evaluation
 * of the model over every measured frequency.
 */
#ifndef RCB_DIAG_TUNING_H
#define RCB_DIAG_TUNING_H

#include <stddef.h>

/* constant                         value              unit */
/* the fit of the model as it is: baseline.c */
#define RCB_DIAG_FAR                10.0               /* ratio, fitted / nominal value */
#define RCB_DIAG_SCREEN_ITER        25                 /* iterations (refit.c, placed.c too) */
#define RCB_DIAG_MISFIT_SHARE       80.0               /* % of F's excess over the noise */
#define RCB_DIAG_MISFIT_RATIO       3.0                /* ratio of chi2 / expected ratios */
#define RCB_DIAG_UNEVEN_RATIO       1.25               /* ratio of chi2 / expected ratios */
/* the score test: score.c */
#define RCB_DIAG_BATCH              128                /* parameters a sweep, at most */
#define RCB_DIAG_BATCH_MIN          32                 /* parameters a sweep, at least */
#define RCB_DIAG_BATCH_VALUES       ((size_t)1 << 22)  /* doubles in J (32 MB) */
/* a candidate's refit: refit.c */
#define RCB_DIAG_BIC_RESOLUTION     0.1                /* BIC an iteration */
#define RCB_DIAG_SCREEN_RESOLUTION  1.0                /* BIC an iteration */
#define RCB_DIAG_STARTS_SUBSET      1                  /* starts */
#define RCB_DIAG_POLISH_ITER        12                 /* iterations (placed.c too) */
#define RCB_DIAG_POLISH_WITHIN      0.1                /* fraction of the lowest F */
#define RCB_DIAG_GN_SLACK           1.25               /* factor on the promised fall of F */
/* pre-fits at the nominal model (a run-off baseline), the place walk: prefit.c */
#define RCB_DIAG_PREFIT_ITER        8                  /* iterations */
#define RCB_DIAG_PREFIT_ITER_SUBSET 4                  /* iterations (refit.c too) */
#define RCB_DIAG_PREFIT_FTOL        1e-2               /* fraction of F an iteration */
#define RCB_DIAG_PRE_RATIO          10.0               /* ratio of objectives (refit.c, rank.c) */
#define RCB_DIAG_FLOOR_FACTOR       1.5                /* ratio, error % / noise floor % */
/* which candidates are pre-fitted and refitted: rank.c */
#define RCB_DIAG_NOM_PREFITS        16                 /* candidates */
#define RCB_DIAG_NOM_REFITS         3                  /* candidates */
/* large effects named where the misfit is placed: placed.c */
#define RCB_DIAG_PLACED_GRID        13                 /* grid points */
#define RCB_DIAG_PLACED_SPAN        3                  /* nodes */
/* the neighbours of a local candidate: neighbours.c */
#define RCB_DIAG_NEIGHBOURS         6                  /* candidates a round */
#define RCB_DIAG_NEIGHBOUR_WALK     3                  /* rounds */
/* a span of a shaft: span.c */
#define RCB_DIAG_SPAN_ITER          8                  /* iterations */
#define RCB_DIAG_SPAN_STEPS         12                 /* moves of an end */
/* the words: words.c */
#define RCB_DIAG_SPAN_RANKS         6                  /* ranks */

/*
 * Why each value.
 *
 * RCB_DIAG_FAR. A baseline fit that a missing effect has pulled far from the
 * nominal model is itself a finding: a parameter moved by more than this
 * factor from its nominal value (or onto a bound that far away). With
 * 0.07 kg per hub hidden at coupling C (32 x 1101, and 8 x 151 too) kr falls
 * 1000 x onto its bound and kt halves; so it does with 1.3 kg at DB and with
 * the two-effect case (tests/python/diag_cases.py); in every other case of
 * the success table no parameter moves by 2 x or more.
 *
 * RCB_DIAG_SCREEN_ITER. The fit of the model as it is runs at most this many
 * iterations on the subset first (baseline_screen); a fit that has run off
 * by then stops there, with no polish on all points: capped at 12 iterations
 * it crawled on for 4-5 s; the 0.15 kg hub case converges on the subset in
 * 15 and its polish took one iteration of 15 sweeps on all points, 0.3 s.
 * With 0.07 kg per hub hidden at C (32 x 1101) the fit crawled 94 iterations
 * and 1228 subset sweeps (about 4 s of the 5.3 s before the refits) to kr's
 * bound, 1000 x below nominal; it is 10 x below within the first 25. The
 * cases whose fit does not run off converge in a few iterations (kcross at
 * B2: 3). A refit's screen on the subset (rcb_diag_screen) stops after as
 * many: it ranks the starts and brings the polish near its end.
 *
 * RCB_DIAG_MISFIT_SHARE, RCB_DIAG_MISFIT_RATIO. The misfit concentrates on a
 * sensor when one sensor, or two of one station (a swapped pair), hold
 * RCB_DIAG_MISFIT_SHARE % of the excess, each failing its own test beyond
 * the Bonferroni limit and RCB_DIAG_MISFIT_RATIO x the median chi2 /
 * expected of the rest (rcb_diag_misfit_get states the rule: a fault of a
 * sensor, not an effect every sensor sees). No measurement behind the two
 * values is recorded.
 *
 * RCB_DIAG_UNEVEN_RATIO (issue #33). A white residual is not even over the
 * sensors when one sensor's chi2 / expected stands out of the others' by
 * more than the Bonferroni limit (z over the sensors at 1 %) and by this
 * ratio: with 4400 residuals a sensor, z alone flagged the paper's literal
 * eq. 19 (its excess gathers at weak points: DA.x at 1.12 against 1.07 for
 * the rest, a ratio of 1.05), which is noise of another form everywhere,
 * not one noisy sensor; a probe with 10 % more random noise (DB.y, 91 % of
 * the excess) stands at about 1.4.
 *
 * RCB_DIAG_BATCH, RCB_DIAG_BATCH_MIN, RCB_DIAG_BATCH_VALUES. Candidates are
 * scored in batches of parameters whose columns share one sweep of the base
 * model (fit_score.c): as many as a J of 2^22 values (32 MB) holds, at least
 * 32 and at most 128 (the paper system's 70 batched parameters on
 * 32 x 1101: one sweep instead of three).
 *
 * RCB_DIAG_BIC_RESOLUTION. Another coupling model (no neutral value, no
 * score) is fitted to the resolution the ranking prints, 0.1 of BIC per
 * step: the fit stops when a step gains or promises less than that, instead
 * of 1e-10 of the objective. With noise-aware weights BIC changes as F
 * itself (ftol_rel F = 0.1 at F = F0), else as N ln F (ftol_rel N = 0.1). A
 * slow descent can stop a few units of BIC early, so the scored candidates,
 * whose BICs are compared with each other, keep the default on 8 x 151; a
 * wrong coupling model ends far above F0 (32 x 1101: BIC +5.9e5 and more),
 * and stops two or three iterations earlier. On the subset (screened,
 * 32 x 1101) every refit gets it: there a screen stops after 25 iterations
 * and a polish after 12 anyway, and candidates that explain nothing crawl to
 * those caps gaining about 0.1 of BIC an iteration at 11 sweeps each
 * (large_null, seed 4: five added masses and inertias, 289 subset sweeps
 * each and 123-140 sweeps on all points, to lower F by 1.5 in all; 2254
 * sweeps, 18 s).
 *
 * RCB_DIAG_SCREEN_RESOLUTION. A screen on the subset (32 x 1101) stops at an
 * iteration that gains, or a step that promises, less than 1 of BIC (its F
 * on the subset scaled to all points): it only ranks the refits and brings
 * them near their end, and the polish of those that can lead goes on to
 * RCB_DIAG_BIC_RESOLUTION. On large_null (seed 4) three added masses and
 * inertias, at their bound of 0, took 20-22 iterations of 11-12 subset
 * sweeps each to gain 0.5 of F on the subset (about 0.18 of BIC an
 * iteration).
 *
 * RCB_DIAG_STARTS_SUBSET. On the subset (32 x 1101) a refit's random starts
 * come after every candidate's first start has been screened, and only when
 * none of those screens reached the noise floor (rcb_diag_refit_restart):
 * once one did, a candidate explains the data, and random starts would only
 * look for a rival, as the pedestals' grids did in the run-off screen
 * (rcb_diag_prefit_selected). Measured on the ROSS large_* sets, seed 1
 * (rcbtool diagnose, 8 refits): the random starts never gave the best point
 * of a refit there and took 2/3 of the screen's sweeps of the candidates
 * that ended far from the data (the added mass at DB on large_pedestal_B4:
 * 625 of 640; the dampings at B1 and B4 on large_cr_C: 436 of 598).
 *
 * RCB_DIAG_POLISH_ITER. The polish of a screened fit on all points stops
 * after this many iterations: a candidate that fits converges in a few (the
 * hub mass of the 0.15 kg hub case: 14 sweeps), while a wrong one can crawl
 * along a valley to the fit's own limit (the hub's diametral inertia there:
 * 1001 sweeps, 15.6 s, for an error of 39 %, far from any significant
 * rival).
 *
 * RCB_DIAG_POLISH_WITHIN. On the subset (32 x 1101) a refit is polished on
 * all points only when, evaluated there where its screen ended, its
 * objective is within this fraction of the lowest refit's; the others keep
 * that evaluation, their BIC an upper bound
 * (rcb_diag_candidate.screened_only). A polish lowers a screened objective
 * by little: on bench_diagnose --large (kcross at B2) by 0.001-1.7 %
 * (34738.5 -> 34738.1 for the cross-coupling, the rest 5.8-390 x above it),
 * while the six polishes behind it took 71 of the 78 sweeps on all points,
 * 2 s of the 3.6 s.
 *
 * RCB_DIAG_GN_SLACK. A polish gains about what the Gauss-Newton step at its
 * start promises: the linearised objective's minimum, || P_J r ||^2 with J
 * the Jacobian of all its parameters (the base's and its own, bounds
 * ignored: an upper bound of the clipped step). On the 0.15 kg hub case
 * (bench_diagnose --large --hub-mass 0.15) the hub's mass and inertia were
 * promised 44.24 and gained 44.12 in 10 iterations and 40 sweeps on all
 * points (1.4 s), the hub mass alone 17.30 and 17.27. A polish is left out
 * (the candidate keeps its evaluation, its BIC an upper bound) when even
 * this factor times the promise cannot bring its BIC below that of the
 * first candidate, once that one has been polished and explains the data.
 *
 * RCB_DIAG_PREFIT_ITER. A pre-fit (prefit.c) runs at most this many
 * iterations: on all points (8 x 151), and on the subset for an added mass
 * or inertia while no pre-fit has ended at the noise floor. No measurement
 * behind 8 itself is recorded; RCB_DIAG_PREFIT_ITER_SUBSET compares 4 with
 * it.
 *
 * RCB_DIAG_PREFIT_ITER_SUBSET. On the subset (32 x 1101) 4: a candidate that
 * explains the data gets there in a few (the 0.15 kg hub mass: the same
 * joint refit after 4 as after 8), the rest crawl (dampings: 52-83 sweeps in
 * 8); 8 x 151 keeps 8. Not for an added mass or inertia
 * (rcb_diag_place_search). A refit from a run-off fit on the subset runs
 * these iterations first (rcb_diag_refit_screen).
 *
 * RCB_DIAG_PREFIT_FTOL. On the subset a pre-fit (but for an added mass or
 * inertia) also stops at an iteration that gains, or a step that promises,
 * less than this fraction of its objective: pre-fits are compared within a
 * factor RCB_DIAG_PRE_RATIO, which RCB_DIAG_PREFIT_ITER_SUBSET such steps
 * cannot bridge. On the 0.15 kg hub case the bearing and shaft dampings
 * gained 0.003-0.3 % of F in their second iteration and under 0.001 % in the
 * next two, at 4-12 sweeps each (damping at B1: 39 sweeps in all).
 *
 * RCB_DIAG_PRE_RATIO. On the subset (32 x 1101), a pre-fit is refitted only
 * when its objective is within this factor of the best pre-fit's: on the
 * 0.15 kg hub case the hub mass ends its pre-fit at F = 4528, the hub's
 * inertia at 4.7e5 and the rest at 2e6-3e6; the inertia's joint refit took
 * 3.1 s (352 sweeps) to end at 38 %, far behind. 8 x 151 refits the 3 best
 * as before. A refit from a run-off fit on the subset goes on past its
 * first RCB_DIAG_PREFIT_ITER_SUBSET iterations only within this factor of
 * the best pre-fit: there the other coupling models of the 0.15 kg hub case
 * took 54 and 86 subset sweeps to end 650-810 x above the hub mass's
 * pre-fit, far behind (rcb_diag_refit_screen).
 *
 * RCB_DIAG_FLOOR_FACTOR. A pre-fit whose error ends below this factor of the
 * noise floor (the fit's own "unsure" limit) explains the data: nothing is
 * left for a place search to find (rcb_diag_place_search).
 *
 * RCB_DIAG_NOM_PREFITS, RCB_DIAG_NOM_REFITS. With the baseline run off, the
 * RCB_DIAG_NOM_PREFITS candidates the score test ranks first at the nominal
 * model are pre-fitted alone there (prefit), and the RCB_DIAG_NOM_REFITS
 * best pre-fits are refitted jointly from where they ended (from both starts
 * when they are also among the best at the fitted model). Sixteen: the hub
 * of the 0.15 kg case scores 14th.
 *
 * RCB_DIAG_PLACED_GRID. Grid points of a candidate's one parameter across
 * its bounds: the score at the neutral value cannot see an effect tens of
 * times larger (B2 kyy 9e7 -> 2e6 N/m scored 5 %, rank 35, on 8 x 151).
 *
 * RCB_DIAG_PLACED_SPAN. Placed refits run only when the placement's span
 * holds at most this many nodes. A wider span places nothing one can name
 * (two effects at once: round 1 of the crack and B2 cross-coupling on
 * 32 x 1101 spans nodes #0-#10, whose 40 candidates took 33 s of CPU to name
 * none).
 *
 * RCB_DIAG_NEIGHBOURS, RCB_DIAG_NEIGHBOUR_WALK. A leading local candidate's
 * neighbours (neighbours.c): its kind at one place either way and in the
 * placement's span, at most 6 a round, the nearest first; a round more from
 * a neighbour that took the lead, at most 3 rounds. On ROSS's shaft B
 * element 8 at 0.6 (8 x 151) the span was nodes #17-#21 (elements 6-10
 * around the lead, element 7): four refits, 257 sweeps (412 for the rest of
 * the diagnosis), element 8 took the lead at 0.5999 and its own
 * neighbours were refitted already, so one round; on 32 x 1101 (element 8
 * leading already) elements 7, 9, 10 took 330 sweeps, 0.95 s of CPU. Six
 * covers a span of five nodes either side of an element; a wider span
 * places nothing one can name (RCB_DIAG_PLACED_SPAN). Three rounds bound a
 * walk along a shaft whose objective keeps falling; none was measured to
 * need a second.
 *
 * RCB_DIAG_SPAN_ITER, RCB_DIAG_SPAN_STEPS. The span search (span.c) fits
 * each span alone (its factor; the base parameters where they are) for at
 * most 8 iterations, from the factor of the span it moved from, and moves
 * an end at most 12 times. On ROSS's E and G x 0.85 on elements 3-7 of
 * shaft B (32 x 1101, a run-off baseline) it walked from the placement's
 * run (elements 1-7) to 3-7 in 11-15 spans, 95-127 subset sweeps, 0.3-0.4 s;
 * the refit of the best span 25 sweeps, 0.35 s. Twelve moves cover a shaft
 * of 13 elements from one end to the other; none was measured to need more
 * than 5.
 *
 * RCB_DIAG_SPAN_RANKS. The words name the span of the significant
 * candidates that sit at nodes among the first this many ranks. No
 * measurement behind 6 is recorded.
 */

#endif
