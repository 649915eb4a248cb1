"""ctypes declarations of the librcb C API (include/rcb/*.h).

Only the shared library does physics; this module finds it, declares the
prototypes it uses and turns a failing status into an RcbError carrying the
owning object's message (with FILE:LINE for INI and measurement files).

Where the library is looked for, in order:
  1. $LIBRCB_PATH: the library file itself, or a directory holding it;
  2. next to this package (librcb/librcb.so, or the folder above it);
  3. the standard names, through the dynamic loader (librcb.so.0, librcb.so,
     as installed by `cmake --install`, or found through LD_LIBRARY_PATH).
"""

import ctypes
import ctypes.util
import os
from pathlib import Path

_NAMES = ("librcb.so", "librcb.so.0", "librcb.dylib", "rcb.dll")

c_double_p = ctypes.POINTER(ctypes.c_double)
c_size_t_p = ctypes.POINTER(ctypes.c_size_t)
c_void_p = ctypes.c_void_p
c_char_p = ctypes.c_char_p
c_int = ctypes.c_int
c_size_t = ctypes.c_size_t
c_double = ctypes.c_double
c_long = ctypes.c_long


class LibraryNotFound(OSError):
    """The shared library librcb.so could not be located or loaded."""


class RcbError(RuntimeError):
    """A librcb call failed: status code, its text, and the object's message."""

    def __init__(self, status, message, call=""):
        self.status = int(status)
        self.status_text = status_str(self.status)
        self.message = message or self.status_text
        self.call = call
        super().__init__(f"{self.message} ({self.status_text}, status {self.status})")


# ---- value types of the public headers ---------------------------------------

class Dof(ctypes.Structure):
    _fields_ = [("node", c_size_t), ("dir", c_int)]


class NodeInfo(ctypes.Structure):
    _fields_ = [("shaft", c_char_p), ("z", c_double), ("dof", c_long * 4)]


class ElementInfo(ctypes.Structure):
    _fields_ = [("shaft", c_char_p), ("index", c_size_t), ("node0", c_size_t),
                ("node1", c_size_t), ("z0", c_double), ("z1", c_double),
                ("outer_d", c_double), ("inner_d", c_double), ("stiffness", c_double),
                ("mass", c_double)]


class StationInfo(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("kind", c_int), ("node", c_size_t)]


class Mode(ctypes.Structure):
    _fields_ = [("lam", c_double * 2), ("wn", c_double), ("wd", c_double),
                ("zeta", c_double), ("logdec", c_double), ("whirl", c_int)]


class MeasChannelInfo(ctypes.Structure):
    _fields_ = [("response", c_char_p), ("reference", c_char_p), ("kind", c_int),
                ("data", c_void_p), ("magnitude_only", c_int)]


class UffNode(ctypes.Structure):
    _fields_ = [("node", c_long), ("station", c_char_p), ("dir", c_char_p),
                ("model_dir", c_char_p)]


class FitReport(ctypes.Structure):
    _fields_ = [("iterations", c_size_t), ("evaluations", c_size_t),
                ("residuals", c_size_t), ("objective0", c_double),
                ("objective", c_double), ("error0_pct", c_double),
                ("error_pct", c_double), ("sigma", c_double), ("converged", c_int),
                ("floor_pct", c_double), ("unsure", c_int), ("starts", c_size_t)]


class FitParam(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("start", c_double), ("value", c_double),
                ("stderr_", c_double), ("ci_lo", c_double), ("ci_hi", c_double),
                ("identifiable", c_int)]


class DiagCandidate(ctypes.Structure):
    _fields_ = [("effect", c_int), ("place", c_char_p), ("description", c_char_p),
                ("params", c_char_p), ("predicted_pct", c_double), ("refitted", c_int),
                ("error_pct", c_double), ("objective_drop_pct", c_double),
                ("delta_bic", c_double), ("significant", c_int), ("fitted", c_char_p),
                ("claim", c_int), ("adequate", c_int), ("chi2", c_double),
                ("chi2_limit", c_double), ("chain", c_int), ("screened_only", c_int),
                ("dispersion", c_double), ("white_z", c_double), ("white", c_int),
                ("beyond", c_int), ("carry", c_char_p)]


class FitAdequacy(ctypes.Structure):
    _fields_ = [("known", c_int), ("chi2", c_double), ("dof", c_double),
                ("expected", c_double), ("sd", c_double), ("limit", c_double),
                ("adequate", c_int), ("white_z", c_double), ("white", c_int),
                ("dispersion", c_double)]


class DiagMisfit(ctypes.Structure):
    _fields_ = [("sensor", c_char_p), ("chi2", c_double), ("expected", c_double),
                ("sd", c_double), ("excess_pct", c_double), ("concentrated", c_int),
                ("z_even", c_double), ("uneven", c_int)]


class DiagPlace(ctypes.Structure):
    _fields_ = [("node", c_size_t), ("shaft", c_char_p), ("z", c_double),
                ("share_pct", c_double), ("chi2", c_double), ("dof", c_double),
                ("adequate", c_int), ("in_span", c_int), ("at_drive", c_int)]


class PlanResult(ctypes.Structure):
    _fields_ = [("angle_deg", c_double), ("size", c_double), ("chi2_sep", c_double),
                ("separable", c_int), ("residuals", c_size_t), ("candidates", c_size_t)]


class PlanParam(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("side", c_int), ("value", c_double),
                ("change", c_double)]


class PlanCandidate(ctypes.Structure):
    _fields_ = [("response", c_char_p), ("reference", c_char_p), ("speed", c_double),
                ("gain", c_double), ("chi2_after", c_double), ("level_db", c_double)]


class Evidence(ctypes.Structure):
    _fields_ = [("delta_bic", c_double), ("error_before_pct", c_double),
                ("error_after_pct", c_double), ("chi2", c_double), ("chi2_limit", c_double),
                ("params", c_double), ("residuals", c_double), ("dispersion", c_double),
                ("tried", c_double), ("white", c_int), ("beyond", c_int)]


class CompareChannel(ctypes.Structure):
    _fields_ = [("response", c_char_p), ("reference", c_char_p), ("kind", c_int),
                ("error_pct", c_double), ("frac", c_double), ("log_rms", c_double),
                ("phase_rms_deg", c_double), ("meas", c_void_p), ("model", c_void_p),
                ("floor_pct", c_double), ("chi2_dof", c_double), ("magnitude_only", c_int)]


class CompareOutlier(ctypes.Structure):
    _fields_ = [("response", c_char_p), ("reference", c_char_p), ("error_pct", c_double),
                ("others_lo", c_double), ("others_hi", c_double), ("by_chi2", c_int),
                ("chi2_dof", c_double), ("chi2_lo", c_double), ("chi2_hi", c_double),
                ("threshold", c_double)]


class CompareSummary(ctypes.Structure):
    _fields_ = [("error_pct", c_double), ("frac_mean", c_double), ("log_rms", c_double),
                ("phase_rms_deg", c_double), ("csac_mean", c_double),
                ("csf_mean", c_double), ("floor_pct", c_double), ("chi2_dof", c_double)]


# rcb_monitor.h (issue #16); the array sizes are RCB_MONITOR_MAX_TRACKED,
# RCB_MONITOR_TOP and RCB_MONITOR_MAXP
MONITOR_MAX_TRACKED, MONITOR_TOP, MONITOR_MAXP = 8, 8, 3
# rcb_monitor.h's level of the naming rule's test half (rcb_monitor_named)
MONITOR_APART_ALPHA = 0.001
# rcb_effect (include/rcb/rcb_diagnose.h): the monitor's catalogue ends before the
# shaft elements; the measurement chain (a sensor's gain and phase, a swap) is asked
# for: RCB_MONITOR_EFFECTS_SENSORS of rcb_monitor.h
EFFECT_ELEMENT_STIFFNESS, EFFECT_SENSOR_GAIN, EFFECT_SENSOR_SWAP = 12, 14, 16
MONITOR_EFFECTS_SENSORS = (((1 << EFFECT_ELEMENT_STIFFNESS) - 1) | (1 << EFFECT_SENSOR_GAIN)
                           | (1 << EFFECT_SENSOR_SWAP))


class MonitorParam(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("lo", c_double), ("hi", c_double)]


class MonitorOpts(ctypes.Structure):
    _fields_ = [("ntracked", c_size_t), ("tracked", ctypes.POINTER(MonitorParam)),
                ("alpha", c_double), ("cusum_k", c_double), ("cusum_h", c_double),
                ("beta_a", c_double), ("beta_s", c_double), ("sd", c_void_p),
                ("setup_averages", c_double), ("effects", ctypes.c_uint), ("top", c_size_t),
                ("relinearise", c_size_t), ("reweight", c_int), ("phase_deg", c_double),
                ("baseline_cov", c_void_p), ("image", c_void_p), ("image_size", c_size_t),
                ("noise_scale", c_double)]


class MonitorNoise(ctypes.Structure):
    _fields_ = [("scale", c_double), ("chi2", c_double), ("dof", c_double)]


class MonitorCandidate(ctypes.Structure):
    _fields_ = [("index", c_size_t), ("effect", c_int), ("np", c_size_t),
                ("size", c_double * MONITOR_MAXP), ("ci_lo", c_double * MONITOR_MAXP),
                ("ci_hi", c_double * MONITOR_MAXP), ("score", c_double), ("dof", c_size_t),
                ("p_value", c_double), ("implausible", c_int)]


class MonitorTracked(ctypes.Structure):
    _fields_ = [("value", c_double), ("ci_lo", c_double), ("ci_hi", c_double),
                ("stderr_", c_double), ("z", c_double), ("u", c_double),
                ("cusum_up", c_double),
                ("cusum_down", c_double), ("cusum_alarm", c_int), ("out_of_range", c_int),
                ("abs_stderr", c_double), ("change", c_double), ("change_lo", c_double),
                ("change_hi", c_double), ("named", c_int), ("rival", c_size_t),
                ("rival_dof", c_size_t), ("rival_rate", c_double * MONITOR_MAXP),
                ("cusum_allow", c_double), ("rival2", c_size_t), ("rival2_dof", c_size_t),
                ("rivals_open", c_size_t)]


class MonitorSeparator(ctypes.Structure):
    _fields_ = [("found", c_int), ("present_separable", c_int), ("chi2_present", c_double),
                ("angle_deg", c_double), ("response", ctypes.c_char * 64),
                ("reference", ctypes.c_char * 64), ("speed", c_double),
                ("chi2_after", c_double), ("level_db", c_double)]


class MonitorResult(ctypes.Structure):
    _fields_ = [("update", c_size_t), ("error_pct", c_double), ("change_pct", c_double),
                ("floor_pct", c_double), ("T", c_double), ("dof", c_size_t),
                ("threshold", c_double), ("p_value", c_double), ("alarm", c_int),
                ("cusum_alarm", c_int), ("ntop", c_size_t),
                ("top", MonitorCandidate * MONITOR_TOP), ("ntracked", c_size_t),
                ("tracked", MonitorTracked * MONITOR_MAX_TRACKED),
                ("drift_glr", c_double), ("drift_dof", c_size_t), ("drift_p", c_double),
                ("drift_alarm", c_int), ("drift_index", c_size_t), ("drift_onset", c_size_t),
                ("drift_rate", c_double * MONITOR_MAXP), ("apart_p", c_double)]


class MonitorCandidateInfo(ctypes.Structure):
    _fields_ = [("effect", c_int), ("place", c_char_p), ("description", c_char_p),
                ("params", c_char_p), ("np", c_size_t)]


PP = ctypes.POINTER(c_void_p)  # out-parameter for an opaque handle

# name: (restype, argtypes); restype c_int is an rcb_status.
_PROTOTYPES = {
    "rcb_version_string": (c_char_p, []),
    "rcb_version_number": (c_int, []),
    "rcb_status_str": (c_char_p, [c_int]),
    # model
    "rcb_model_create": (c_int, [PP, c_void_p]),
    "rcb_model_destroy": (None, [c_void_p]),
    "rcb_model_errmsg": (c_char_p, [c_void_p]),
    "rcb_model_load_file": (c_int, [c_void_p, c_char_p]),
    "rcb_model_load_string": (c_int, [c_void_p, c_char_p, c_char_p]),
    "rcb_model_warning_count": (c_size_t, [c_void_p]),
    "rcb_model_warning": (c_char_p, [c_void_p, c_size_t]),
    "rcb_model_node_count": (c_size_t, [c_void_p]),
    "rcb_model_dof_count": (c_size_t, [c_void_p]),
    "rcb_model_element_count": (c_size_t, [c_void_p]),
    "rcb_model_node_info": (c_int, [c_void_p, c_size_t, ctypes.POINTER(NodeInfo)]),
    "rcb_model_element_info": (c_int, [c_void_p, c_size_t, ctypes.POINTER(ElementInfo)]),
    "rcb_model_station_count": (c_size_t, [c_void_p]),
    "rcb_model_station_info": (c_int, [c_void_p, c_size_t, ctypes.POINTER(StationInfo)]),
    "rcb_model_find_dof": (c_int, [c_void_p, c_char_p, ctypes.POINTER(Dof)]),
    "rcb_model_dof_index": (c_int, [c_void_p, Dof, c_size_t_p]),
    "rcb_model_matrices": (c_int, [c_void_p, c_double, c_void_p, c_void_p, c_void_p,
                                   c_void_p]),
    "rcb_model_unbalance_force": (c_int, [c_void_p, c_double, c_void_p]),
    "rcb_model_get_param": (c_int, [c_void_p, c_char_p, c_double_p]),
    "rcb_model_set_param": (c_int, [c_void_p, c_char_p, c_double]),
    "rcb_model_param_count": (c_size_t, [c_void_p]),
    "rcb_model_param_name": (c_int, [c_void_p, c_size_t, c_char_p, c_size_t]),
    "rcb_model_write_ini": (c_int, [c_void_p, c_char_p, c_size_t, c_size_t_p]),
    "rcb_model_uff_node_count": (c_size_t, [c_void_p]),
    "rcb_model_uff_node": (c_int, [c_void_p, c_size_t, ctypes.POINTER(c_long),
                                   ctypes.POINTER(c_char_p)]),
    # FRF and unbalance
    "rcb_frf_create": (c_int, [PP, c_void_p, c_size_t, c_void_p, c_size_t, c_void_p, c_int,
                               c_void_p]),
    "rcb_frf_destroy": (None, [c_void_p]),
    "rcb_frf_errmsg": (c_char_p, [c_void_p]),
    "rcb_frf_eval": (c_int, [c_void_p, c_double, c_double, c_int, c_void_p]),
    "rcb_frf_unbalance": (c_int, [c_void_p, c_double, c_void_p]),
    # modes and Campbell
    "rcb_modes_create": (c_int, [PP, c_void_p, c_void_p]),
    "rcb_modes_destroy": (None, [c_void_p]),
    "rcb_modes_errmsg": (c_char_p, [c_void_p]),
    "rcb_modes_set_max_zeta": (c_int, [c_void_p, c_double]),
    "rcb_modes_compute": (c_int, [c_void_p, c_double, c_size_t, ctypes.POINTER(Mode),
                                  c_size_t_p, c_void_p]),
    "rcb_campbell": (c_int, [c_void_p, c_size_t, c_void_p, c_size_t, c_void_p, c_void_p,
                             c_void_p]),
    "rcb_critical_speeds": (c_int, [c_size_t, c_void_p, c_size_t, c_void_p, c_double,
                                    c_size_t, c_void_p, c_void_p, c_size_t_p]),
    # measurements
    "rcb_meas_create": (c_int, [PP, c_void_p]),
    "rcb_meas_destroy": (None, [c_void_p]),
    "rcb_meas_errmsg": (c_char_p, [c_void_p]),
    "rcb_meas_set_grid": (c_int, [c_void_p, c_int, c_size_t, c_void_p, c_double]),
    "rcb_meas_add_channel": (c_int, [c_void_p, c_char_p, c_char_p, c_int, c_void_p]),
    "rcb_meas_get_type": (c_int, [c_void_p]),
    "rcb_meas_point_count": (c_size_t, [c_void_p]),
    "rcb_meas_channel_count": (c_size_t, [c_void_p]),
    "rcb_meas_grid": (c_double_p, [c_void_p]),
    "rcb_meas_speed": (c_double, [c_void_p]),
    "rcb_meas_channel": (c_int, [c_void_p, c_size_t, ctypes.POINTER(MeasChannelInfo)]),
    "rcb_meas_convert": (c_int, [c_void_p, c_int]),
    "rcb_meas_add_noise": (c_int, [c_void_p, c_double, c_double, ctypes.c_uint64]),
    "rcb_meas_read_uff": (c_int, [c_void_p, c_char_p, c_size_t, c_void_p]),
    "rcb_meas_write_uff": (c_int, [c_void_p, c_char_p, c_int, c_size_t, c_void_p]),
    "rcb_meas_read_csv": (c_int, [c_void_p, c_char_p]),
    "rcb_meas_read_csv_map": (c_int, [c_void_p, c_char_p, c_size_t, c_void_p]),
    "rcb_meas_write_csv": (c_int, [c_void_p, c_char_p]),
    # identification
    "rcb_fit_create": (c_int, [PP, c_void_p, c_void_p, c_void_p]),
    "rcb_fit_destroy": (None, [c_void_p]),
    "rcb_fit_errmsg": (c_char_p, [c_void_p]),
    "rcb_fit_add_param": (c_int, [c_void_p, c_char_p, c_double, c_double, c_int]),
    "rcb_fit_set_scale": (c_int, [c_void_p, c_int]),
    "rcb_fit_set_band": (c_int, [c_void_p, c_double, c_double]),
    "rcb_fit_set_noise_model": (c_int, [c_void_p, c_double, c_double]),
    "rcb_fit_set_method": (c_int, [c_void_p, c_int, c_char_p]),
    "rcb_fit_set_limits": (c_int, [c_void_p, c_size_t, c_double, c_double]),
    "rcb_fit_set_starts": (c_int, [c_void_p, c_size_t, ctypes.c_uint64]),
    "rcb_fit_run": (c_int, [c_void_p]),
    "rcb_fit_get_report": (c_int, [c_void_p, ctypes.POINTER(FitReport)]),
    "rcb_fit_param_count": (c_size_t, [c_void_p]),
    "rcb_fit_get_param": (c_int, [c_void_p, c_size_t, ctypes.POINTER(FitParam)]),
    "rcb_fit_correlation": (c_int, [c_void_p, c_void_p]),
    "rcb_fit_error": (c_int, [c_void_p, c_double_p]),
    # diagnosis
    "rcb_effect_name": (c_char_p, [c_int]),
    "rcb_diag_create": (c_int, [PP, c_void_p, c_void_p, c_void_p]),
    "rcb_plan_create": (c_int, [PP, c_void_p, c_void_p, c_void_p]),
    "rcb_plan_destroy": (None, [c_void_p]),
    "rcb_plan_errmsg": (c_char_p, [c_void_p]),
    "rcb_plan_add_param": (c_int, [c_void_p, c_int, c_char_p]),
    "rcb_plan_set_noise_model": (c_int, [c_void_p, c_double, c_double]),
    "rcb_plan_set_size": (c_int, [c_void_p, c_double]),
    "rcb_plan_add_speed": (c_int, [c_void_p, c_double]),
    "rcb_plan_run": (c_int, [c_void_p]),
    "rcb_plan_get_result": (c_int, [c_void_p, ctypes.POINTER(PlanResult)]),
    "rcb_plan_param_count": (c_size_t, [c_void_p]),
    "rcb_plan_get_param": (c_int, [c_void_p, c_size_t, ctypes.POINTER(PlanParam)]),
    "rcb_plan_get_candidate": (c_int, [c_void_p, c_size_t, ctypes.POINTER(PlanCandidate)]),
    "rcb_diag_destroy": (None, [c_void_p]),
    "rcb_diag_errmsg": (c_char_p, [c_void_p]),
    "rcb_diag_add_fitted_param": (c_int, [c_void_p, c_char_p, c_double, c_double, c_int]),
    "rcb_diag_set_scale": (c_int, [c_void_p, c_int]),
    "rcb_diag_set_noise_model": (c_int, [c_void_p, c_double, c_double]),
    "rcb_diag_set_band": (c_int, [c_void_p, c_double, c_double]),
    "rcb_diag_set_refits": (c_int, [c_void_p, c_size_t]),
    "rcb_diag_run": (c_int, [c_void_p]),
    "rcb_diag_candidate_count": (c_size_t, [c_void_p]),
    "rcb_diag_candidate_get": (c_int, [c_void_p, c_size_t, ctypes.POINTER(DiagCandidate)]),
    "rcb_diag_baseline": (c_int, [c_void_p, c_double_p, c_double_p, c_double_p]),
    "rcb_diag_apply_model": (c_int, [c_void_p, c_size_t, c_void_p, PP]),
    "rcb_diag_explain": (c_int, [c_void_p, c_char_p, c_size_t, c_size_t_p]),
    "rcb_diag_adequacy": (c_int, [c_void_p, ctypes.POINTER(FitAdequacy)]),
    "rcb_diag_misfit_count": (c_size_t, [c_void_p]),
    "rcb_diag_place_count": (c_size_t, [c_void_p]),
    "rcb_diag_place_get": (c_int, [c_void_p, c_size_t, ctypes.POINTER(DiagPlace)]),
    "rcb_diag_misfit_get": (c_int, [c_void_p, c_size_t, ctypes.POINTER(DiagMisfit)]),
    "rcb_evidence_claim": (c_int, [ctypes.POINTER(Evidence)]),
    "rcb_evidence_significant": (c_int, [ctypes.POINTER(Evidence)]),
    "rcb_evidence_adequate": (c_int, [ctypes.POINTER(Evidence)]),
    "rcb_claim_str": (c_char_p, [c_int]),
    # comparison
    "rcb_compare_create": (c_int, [PP, c_void_p]),
    "rcb_compare_destroy": (None, [c_void_p]),
    "rcb_compare_errmsg": (c_char_p, [c_void_p]),
    "rcb_compare_run": (c_int, [c_void_p, c_void_p, c_void_p]),
    "rcb_compare_channel_count": (c_size_t, [c_void_p]),
    "rcb_compare_get_channel": (c_int, [c_void_p, c_size_t, ctypes.POINTER(CompareChannel)]),
    "rcb_compare_get_summary": (c_int, [c_void_p, ctypes.POINTER(CompareSummary)]),
    "rcb_compare_point_count": (c_size_t, [c_void_p]),
    "rcb_compare_outlier_count": (c_size_t, [c_void_p]),
    "rcb_compare_get_outlier": (c_int, [c_void_p, c_size_t, ctypes.POINTER(CompareOutlier)]),
    "rcb_compare_grid": (c_double_p, [c_void_p]),
    # monitoring
    "rcb_monitor_create": (c_int, [PP, c_void_p, c_void_p, ctypes.POINTER(MonitorOpts),
                                   c_void_p]),
    "rcb_monitor_destroy": (None, [c_void_p]),
    "rcb_monitor_noise_scale": (c_int, [c_void_p, c_void_p, c_size_t, ctypes.POINTER(MonitorOpts),
                                        ctypes.POINTER(MonitorNoise)]),
    "rcb_monitor_errmsg": (c_char_p, [c_void_p]),
    "rcb_monitor_update": (c_int, [c_void_p, c_void_p, c_void_p,
                                   ctypes.POINTER(MonitorResult)]),
    "rcb_monitor_reset_cusum": (None, [c_void_p]),
    "rcb_monitor_state_size": (c_size_t, [c_void_p]),
    "rcb_monitor_save": (c_int, [c_void_p, c_void_p, c_size_t, ctypes.POINTER(c_size_t)]),
    "rcb_monitor_load": (c_int, [c_void_p, c_void_p, c_size_t]),
    "rcb_monitor_point_count": (c_size_t, [c_void_p]),
    "rcb_monitor_memory": (c_size_t, [c_void_p]),
    "rcb_monitor_candidate_count": (c_size_t, [c_void_p]),
    "rcb_monitor_rank": (c_int, [c_void_p, ctypes.POINTER(c_size_t), ctypes.POINTER(c_size_t)]),
    "rcb_monitor_named": (c_int, [c_void_p, c_void_p]),
    "rcb_monitor_separating": (c_int, [c_void_p, c_size_t, c_size_t, c_void_p, c_size_t,
                                       ctypes.POINTER(MonitorSeparator)]),
    "rcb_monitor_candidate_info_get": (c_int, [c_void_p, c_size_t,
                                               ctypes.POINTER(MonitorCandidateInfo)]),
    "rcb_monitor_tracked_info": (c_int, [c_void_p, c_size_t, ctypes.POINTER(c_char_p),
                                         c_double_p]),
    "rcb_chi2_sf": (c_double, [c_double, c_double]),
    "rcb_chi2_quantile": (c_double, [c_double, c_double]),
}


def _candidates():
    env = os.environ.get("LIBRCB_PATH")
    if env:
        p = Path(env)
        if p.is_dir():
            yield from (str(p / n) for n in _NAMES if (p / n).exists())
        yield env  # a file, or a name for the loader: tried as given
        return
    here = Path(__file__).resolve().parent
    for d in (here, here.parent):
        for n in _NAMES:
            if (d / n).exists():
                yield str(d / n)
    for n in _NAMES:
        yield n
    found = ctypes.util.find_library("rcb")
    if found:
        yield found


def _load():
    tried = []
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append(f"{path}: {e}")
            continue
        if not hasattr(lib, "rcb_version_string"):
            tried.append(f"{path}: not librcb (no rcb_version_string)")
            continue
        return lib, path
    where = "\n  ".join(tried) if tried else "(nothing to try)"
    hint = ("set LIBRCB_PATH to the shared library built by CMake, e.g. "
            "LIBRCB_PATH=build/src/librcb.so (configure with RCB_BUILD_SHARED=ON, the "
            "default), or install it with `cmake --install build`")
    if os.environ.get("LIBRCB_PATH"):
        hint = f"LIBRCB_PATH={os.environ['LIBRCB_PATH']!r} does not load; " + hint
    raise LibraryNotFound(f"librcb shared library not found: {hint}. Tried:\n  {where}")


def _declare(lib):
    for name, (res, args) in _PROTOTYPES.items():
        fn = getattr(lib, name)
        fn.restype = res
        fn.argtypes = args
    return lib


_LIB = None
LIB_PATH = None


def lib():
    """The loaded library (loaded and declared on first use)."""
    global _LIB, LIB_PATH
    if _LIB is None:
        handle, LIB_PATH = _load()
        _LIB = _declare(handle)
    return _LIB


def status_str(status):
    return lib().rcb_status_str(int(status)).decode()


def text(b):
    """A C string owned by the library as a Python str (None stays None)."""
    return None if b is None else b.decode("utf-8", "replace")


def check(status, errmsg=None, obj=None, call=""):
    """Raise RcbError unless status is RCB_OK; errmsg(obj) gives the message."""
    if status != 0:
        msg = ""
        if errmsg is not None and obj:
            msg = text(errmsg(obj))
        raise RcbError(status, msg, call)
    return status


def two_call_string(fn, *args):
    """Two-call sizing (RCB_ERR_WORKSPACE then RCB_OK): the whole string."""
    need = c_size_t(0)
    st = fn(*args, None, 0, ctypes.byref(need))
    if st not in (0, -11):
        return st, None
    buf = ctypes.create_string_buffer(need.value)
    st = fn(*args, buf, need.value, ctypes.byref(need))
    return st, (buf.value.decode() if st == 0 else None)
