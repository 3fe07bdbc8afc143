"""The named tracking methods of the seed papers, as configuration.

A method is a dict naming one part per role (each a registry spec: a name or
``{"name": ..., **params}``) plus tracker parameters.  Adding a method is adding an entry
here or in the workflow config; adding a part is one class plus one registry line.

The roles (:data:`ROLES`): ``detector`` (scan → leg observations), ``filter`` (one leg's
state), ``motion`` (the input u), ``phase`` (gait-phase identification), ``gate``,
``associator``, ``occlusion`` and ``init``; ``tracker`` holds the loop's own parameters
(``dt_s``, ``sides``).  An optional ``kind`` chooses how the parts are run
(:mod:`gaitval.track.kinds`): the default ``detect_then_track``, or a tracker that reads
raw scans (e.g. a particle filter), which then needs no per-scan roles.

Seed 000 (TUG), Table 3 definitions, Table 2 parameters as defaults:

=========  =======================  ====================  ===========================
method     data association         occlusion             everything else
=========  =======================  ====================  ===========================
tug_m1     GNN                      predict only          five-pattern detector, KF
tug_m2     gait phase (§5.2)        predict only          with the gait-phase input
tug_m3     gait phase (§5.2)        Catmull–Rom (eq. 17)  (eq. 18–20), χ² gate G=13.82
=========  =======================  ====================  ===========================

Table 2: Δt = 25 ms (here inferred from the scan timestamps unless ``dt_s`` is set),
Q = diag(15.0², 15.0²), R = diag(0.04², 0.04²), v_st_th = 0.47 m/s, v_sw_th = 0.93 m/s,
G = 13.82 (P_G = 0.999), N_ac = 40.  N_bo, N_ao: not given; "match" (see
:mod:`gaitval.track.occlusion`).

Nested parameters can be overridden by path, gaitmap style::

    build_tracker("tug_m3", {"occlusion__n_bo": 5, "gate__g": 9.21})

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import copy
from typing import Any

import pandas as pd

from gaitval.detect import DETECTORS
from gaitval.errors import ConfigError
from gaitval.track.kinds import TRACKER_KINDS, DetectThenTrack, TrackerKind
from gaitval.track.tracker import Tracker
from gaitval.types import ScanSeries

ROLES = ("detector", "filter", "motion", "phase", "gate", "associator", "occlusion", "init")
DEFAULT_KIND = "detect_then_track"

_TUG_COMMON: dict[str, Any] = {
    "paper": "seed 000 (Yorozu et al., Sensors 2015, 15, 22451)",
    "detector": {"name": "leg_patterns", "use_fs_u": True, "max_occluder_m": 0.15,
                 "background": {"name": "percentile", "q": 95.0, "margin_m": 0.10}},
    "filter": {"name": "kf", "q_accel_sd_mps2": 15.0, "r_sd_m": 0.04,
               "p0_pos_sd_m": 0.04, "p0_vel_sd_mps": 0.5},
    "motion": {"name": "gait_phase_accel", "n_ac": 40, "limit_braking": True},
    "phase": {"name": "speed_thresholds", "v_st_th": 0.47, "v_sw_th": 0.93},
    "gate": {"name": "chi2", "g": 13.82},
    "init": {"name": "closest_pair", "max_pair_m": 0.8, "min_leg_widths": 0.7},
    "tracker": {"dt_s": None, "sides": "walking_direction"},
}


def _method(label: str, associator: str, occlusion: dict | str) -> dict[str, Any]:
    m = copy.deepcopy(_TUG_COMMON)
    m["label"] = label
    m["associator"] = {"name": associator, "d_max": 13.82 ** 0.5}
    m["occlusion"] = occlusion
    return m


#: name → method definition (deep-copied by :func:`get_method`)
METHODS: dict[str, dict[str, Any]] = {
    "tug_m1": _method("Method 1 (GNN)", "gnn", {"name": "predict_only"}),
    "tug_m2": _method("Method 2 (gait-phase association)", "gait_phase",
                      {"name": "predict_only"}),
    "tug_m3": _method("Method 3 (gait phase + Catmull-Rom, proposal)", "gait_phase",
                      {"name": "catmull_rom", "n_bo": "match", "n_ao": "match",
                       "max_n": 20, "min_n_uo": 1}),
}

#: seed 000 Table 3 definitions, for tables
METHOD_DEFINITIONS = {
    "tug_m1": {"gait_phase_association": False, "catmull_rom_interpolation": False},
    "tug_m2": {"gait_phase_association": True, "catmull_rom_interpolation": False},
    "tug_m3": {"gait_phase_association": True, "catmull_rom_interpolation": True},
}

# -- seed 002 (robotic rollator), see docs/rollator.md --------------------------------------
# The paper's axes: y is the direction of travel (σ_ay = 5.24 > σ_ax = 1.63 m/s², and every
# v_y error of its Table I exceeds the v_x one), x is lateral.  gaitval's laser frame on the
# rollator has x forward from the laser (towards the user: the direction of travel) and y
# to the laser's left, so the paper's (x, y) noise values become gaitval's (y, x).  The
# measurement noise 0.059 m (paper x) / 0.02 m (paper y) is read as standard deviations.
_SEED002 = "seed 002 (Chalvatzaki et al., ICRA 2017)"
METHODS["rollator_kf"] = {
    "label": "KF (seed 002 §II)",
    "paper": _SEED002,
    "detector": {"name": "rollator_window", "window_x_m": [0.10, 1.00],
                 "window_y_m": [-0.40, 0.40], "n_sigma": 3.0, "group_gap_leg_widths": 0.5,
                 "min_points": 5, "min_leg_widths": 0.7, "n_init": 1, "random_state": 0},
    "filter": {"name": "kf_aniso", "q_accel_sd_mps2": [5.24, 1.63], "r_sd_m": [0.02, 0.059],
               "p0_pos_sd_m": 0.05, "p0_vel_sd_mps": 0.5},
    "motion": {"name": "constant_velocity"},
    "phase": {"name": "speed_thresholds", "v_st_th": 0.47, "v_sw_th": 0.93},
    "gate": {"name": "chi2", "g": 13.82},
    "associator": {"name": "gnn", "d_max": 13.82 ** 0.5},
    "occlusion": {"name": "reinit_after_lost", "n_lost": 15,
                  "init": {"name": "facing_pair", "max_pair_m": 0.8, "min_leg_widths": 0.7}},
    "init": {"name": "facing_pair", "max_pair_m": 0.8, "min_leg_widths": 0.7},
    "tracker": {"dt_s": None, "sides": "as_initialised"},
}
# The PF (seed 002 §III) reads raw scans: its parts are its own parameters.  ``model`` is
# learned leave-one-subject-out by the workflow (rule rollator_train, passed in as
# kind__model); None gives geometric placeholders (gaitval.track.pf_model).
METHODS["rollator_pf"] = {
    "label": "PF (seed 002 §III)",
    "paper": _SEED002,
    "kind": {"name": "rollator_pf", "n_particles": 500, "seed": 0, "best_fraction": 0.8,
             "resample_fraction": 0.5, "model": None, "dt_s": None,
             "detector": METHODS["rollator_kf"]["detector"],
             "init": METHODS["rollator_kf"]["init"]},
}

# -- seed 001 (MTST), Table 3 definitions; everything but the detector's FS_U pattern and the
# validation region is shared.  Δt = 0.05 s (§3.1): the loop's Δt is the period of the scans
# it is given (dt_s None), and the MTST steps keep every n-th scan of a log so that the
# period is mtst.scan_period_s = 0.05 s (gaitval.pipeline.mtst).  P0 is not given (GAP): the
# first observation's own noise w_l/2 ≈ 0.05 m, and 0.5 m/s for a participant who stands.
_SEED001 = "seed 001 (Yorozu et al., Sensors 2015, 15, 11151)"


def _mtst_method(label: str, use_fs_u: bool, gate: dict[str, Any]) -> dict[str, Any]:
    return {
        "label": label, "paper": _SEED001,
        "detector": {"name": "leg_patterns", "use_fs_u": use_fs_u, "max_occluder_m": 0.15,
                     "background": {"name": "percentile", "q": 95.0, "margin_m": 0.10}},
        # seed001 eq. (2)-(3): Q = diag(5.0², 5.0²), R = diag((w_l/2)², (w_l/2)²)
        "filter": {"name": "kf", "q_accel_sd_mps2": 5.0, "r_sd_leg_widths": 0.5,
                   "p0_pos_sd_m": 0.05, "p0_vel_sd_mps": 0.5},
        "motion": {"name": "constant_velocity"},
        "phase": {"name": "speed_thresholds", "v_st_th": 0.18, "v_sw_th": 0.37},  # eq. (9)-(10)
        "gate": gate,
        "associator": {"name": "gnn_assignment", "cost": "mahalanobis2"},        # eq. (6)-(8)
        "occlusion": {"name": "uo_pseudo_update"},                                # §2.4.3
        "init": {"name": "mtst_participant", "half_width_m": 0.675, "margin_before_m": 1.5,
                 "max_pair_m": 0.8, "min_leg_widths": 0.7},
        "tracker": {"dt_s": None, "sides": "walking_direction"},
    }


METHODS.update({
    "mtst_m1": _mtst_method("Method 1 (no FS_U, r = 1.5 w_l)", False,
                            {"name": "fixed_radius", "radius_leg_widths": 1.5}),
    "mtst_m2": _mtst_method("Method 2 (FS_U, r = 1.5 w_l)", True,
                            {"name": "fixed_radius", "radius_leg_widths": 1.5}),
    "mtst_m3": _mtst_method("Method 3 (FS_U, r = w_l)", True,
                            {"name": "fixed_radius", "radius_leg_widths": 1.0}),
    "mtst_proposed": _mtst_method("Proposed (FS_U, variable region)", True,
                                  {"name": "variable_region", "v_sw": 1.1, "v_st": 0.55}),
})


def set_params(method: dict[str, Any], overrides: dict[str, Any] | None) -> dict[str, Any]:
    """Copy of ``method`` with ``role__param`` (or ``tracker__param``) overrides applied."""
    m = copy.deepcopy(method)
    for key, val in (overrides or {}).items():
        role, sep, param = key.partition("__")
        if not sep or role not in m:
            raise ConfigError(f"cannot set {key!r}: use <role>__<param> with role one of "
                              f"{', '.join(k for k in m if isinstance(m[k], dict))}")
        if isinstance(m[role], str):
            m[role] = {"name": m[role]}
        m[role][param] = val
    return m


def _leaves(d: Any, prefix: str = "") -> dict[str, Any]:
    if not isinstance(d, dict):
        return {prefix: d}
    out = {}
    for k, v in d.items():
        out.update(_leaves(v, f"{prefix}.{k}" if prefix else str(k)))
    return out


#: What a method variant may change without being a modified method: its label, and the
#: reading of seed000 eq. (3)-(4) that its name already says (``<method>_<reading>``).
_NOT_A_CHANGE = ("label", "paper", "phase.reading")


def changed_parameters(definition: Any, base: str) -> dict[str, Any]:
    """``{"role.param": value}`` where ``definition`` differs from the built-in method
    ``base`` (the overrides it was run with); {} when ``base`` is no built-in method."""
    if base not in METHODS or definition is None:
        return {}
    mine = _leaves(get_method(definition) if isinstance(definition, str) else definition)
    paper = _leaves(METHODS[base])
    return {k: v for k, v in sorted(mine.items())
            if k not in _NOT_A_CHANGE and (k not in paper or paper[k] != v)}


def display_name(name: str, definition: Any = None, base: str | None = None) -> str:
    """A method's name as tables show it: ``tug_m3`` when it ran as built in, else with
    what was changed, ``tug_m3 (occlusion.max_n = 10)``: the paper's values beside it are
    no longer those of the method that ran (``tracking.overrides``)."""
    changes = changed_parameters(definition, base or name)
    if not changes:
        return name
    parts = [f"{k} = {v}" for k, v in changes.items() if len(repr(v)) <= 40]
    more = len(changes) - len(parts)
    parts += [f"{more} more"] if more else []
    return f"{name} ({', '.join(parts)})"


def kind_name(method: dict[str, Any]) -> str:
    kind = method.get("kind", DEFAULT_KIND)
    return kind if isinstance(kind, str) else kind.get("name", DEFAULT_KIND)


def get_method(method: str | dict[str, Any]) -> dict[str, Any]:
    """The method definition for a name in :data:`METHODS` or a full dict."""
    if isinstance(method, str):
        try:
            return copy.deepcopy(METHODS[method])
        except KeyError:
            raise ConfigError(f"unknown tracking method {method!r}",
                              hint=f"choose one of: {', '.join(sorted(METHODS))}") from None
    if kind_name(method) != DEFAULT_KIND:
        return copy.deepcopy(method)          # a raw-scan tracker: its parameters are its own
    missing = [r for r in ROLES if r not in method]
    if missing:
        raise ConfigError(f"tracking method is missing the role(s) {', '.join(missing)}",
                          hint=f"a method names one part for each of: {', '.join(ROLES)}")
    return copy.deepcopy(method)


def build_tracker(method: str | dict[str, Any], overrides: dict[str, Any] | None = None
                  ) -> tuple[Any, Tracker]:
    """Build ``(detector, tracker)`` of a detect-then-track method.

    Parameters
    ----------
    method : str or dict
        A key of :data:`METHODS` or a dict with one spec per role in :data:`ROLES` and an
        optional ``tracker`` dict of :class:`~gaitval.track.tracker.Tracker` parameters.
    overrides : dict, optional
        ``{"role__param": value}`` applied on top.
    """
    m = set_params(get_method(method), overrides)
    if kind_name(m) != DEFAULT_KIND:
        raise ConfigError(f"method {method if isinstance(method, str) else ''!r} is a "
                          f"{kind_name(m)!r} tracker, not detect-then-track",
                          hint="use build_method() for it")
    detector = DETECTORS.build(m["detector"])
    tracker = Tracker(**{r: m[r] for r in ROLES if r != "detector"}, **m.get("tracker", {}))
    return detector, tracker


def build_method(method: str | dict[str, Any], overrides: dict[str, Any] | None = None
                 ) -> TrackerKind:
    """The runnable tracker of a method: its ``kind`` built from its parts.

    A detect-then-track method gives :class:`~gaitval.track.kinds.DetectThenTrack` of its
    detector and :class:`Tracker`; any other kind is built from the ``kind`` spec
    (``{"name": ..., **params}``) through :data:`~gaitval.track.kinds.TRACKER_KINDS`.
    """
    m = set_params(get_method(method), overrides)
    if kind_name(m) == DEFAULT_KIND:
        return DetectThenTrack(*build_tracker(m), detector_spec=m["detector"])
    return TRACKER_KINDS.build(m["kind"])


def trial_detector(method: str | dict[str, Any], overrides: dict[str, Any] | None = None
                   ) -> str | dict[str, Any] | None:
    """The spec of the detector a method runs once over all of a trial's scans before it
    tracks, or None when it has none (a tracker of raw scans, a detector that looks scan
    by scan where the tracker predicts the legs).  Two methods with the same spec make
    the same observation table of a trial, so a workflow detects once for both and hands
    the table to each (``observations`` of :func:`track_trial`; docs/speed.md)."""
    m = set_params(get_method(method), overrides)
    if kind_name(m) == DEFAULT_KIND:
        spec = m["detector"]
    else:
        kind = m["kind"] if isinstance(m["kind"], dict) else {"name": m["kind"]}
        if not getattr(TRACKER_KINDS[kind["name"]], "accepts_observations", False):
            return None
        spec = kind.get("detector")
        if spec is None:                # the kind's own default detector: not shared
            return None
    name = spec if isinstance(spec, str) else spec["name"]
    if getattr(DETECTORS[name], "windowed", False):
        return None
    return copy.deepcopy(spec)


def track_trial(scans: ScanSeries, method: str | dict[str, Any], leg_width_m: float,
                cfg: dict[str, Any] | None = None, observations: pd.DataFrame | None = None
                ) -> pd.DataFrame:
    """Detect and track both legs of one trial.

    Parameters
    ----------
    scans : ScanSeries
        The trial's LRS scans (sensor clock).
    method : str or dict
        Method name (``tug_m1``, ``tug_m2``, ``tug_m3``) or definition.
    leg_width_m : float
        The subject's shank width at sensor height, w_l (subjects.csv ``leg_width_m``).
    cfg : dict, optional
        ``{"overrides": {"role__param": value}}`` (e.g. from the workflow config).
    observations : DataFrame, optional
        The method's detector's observation table of these scans, made earlier (the
        same detector spec, :func:`trial_detector`, and leg width); None: detect.

    Returns
    -------
    DataFrame
        One row per scan and side, in the sensor frame: ``k, t_sensor_s, side (L|R), x_m,
        y_m, vx_mps, vy_mps, observed (bool: a real observation was associated), pattern
        (SL, LT, FS_O, FS_U, or UO), phase (0–5, −1 before initialisation), swing (bool),
        interpolated (bool: a Catmull–Rom virtual observation was used)``.  Positions are
        NaN before the track is initialised.
    """
    cfg = cfg or {}
    kind = build_method(method, cfg.get("overrides"))
    if observations is None:
        return kind.track(scans, leg_width_m).to_frame()
    return kind.track(scans, leg_width_m, observations=observations).to_frame()

# -- a people tracker (several persons, two legs each, with a life cycle) -------
# Not a paper's method: the seed papers' leg model (seed 000's KF and χ² gate, Table 2;
# seed 001's constant-velocity input and GNN assignment) inside a tracker that starts,
# confirms, coasts and ends person hypotheses (gaitval/track/people.py, lifecycle.py;
# docs/people.md says where every value comes from).
METHODS["people"] = {
    "label": "People tracker (life cycle, several persons)",
    "paper": "gaitval (issue 36); leg model of seeds 000/001, life cycle after Leigh et al. "
             "ICRA 2015",
    "kind": {"name": "people",
             "detector": copy.deepcopy(_TUG_COMMON["detector"]),
             "filter": {"name": "kf", "q_accel_sd_mps2": 15.0, "r_sd_m": 0.04,
                        "p0_pos_sd_m": 0.04, "p0_vel_sd_mps": 0.5},
             "motion": {"name": "gait_phase_accel", "n_ac": 40, "limit_braking": True},
             "tentative_motion": {"name": "constant_velocity"},
             "phase": {"name": "speed_thresholds", "v_st_th": 0.47, "v_sw_th": 0.93},
             "gate": {"name": "chi2", "g": 13.82},
             # seed 001's variable validation region (Table 1) while a person is tentative
             "tentative_gate": {"name": "variable_region", "v_sw": 1.1, "v_st": 0.55},
             "birth": {"name": "unexplained_pairs", "max_pair_m": 0.8,
                       "min_leg_widths": 0.7},
             # M of N scans with a leg pair that walks (docs/people.md); a scan counts
             # only when no surface runs through both legs (separate_legs)
             "confirmer": {"name": "m_of_n_moving", "window_s": 1.4, "m_fraction": 0.5,
                           "min_relative_travel_m": 0.5, "pass_leg_widths": 1.0,
                           "min_travel_m": 0.5, "evidence": "observations",
                           "separate_legs": True, "min_apart_leg_widths": 1.0},
             "deleter": {"name": "unsupported_time", "max_unsupported_s": 3.0,
                         "tentative_unsupported_s": 0.2},
             "area": {"name": "field_of_view", "margin_m": 0.25},
             # an ended person found again near where it was last seen (leg_tracker's person
             # gate and deletion bound, lifecycle.LegTrackerGate)
             "refind": {"name": "leg_tracker_gate", "max_std_m": 0.9, "percentile": 0.90,
                        "std_obs_m": 0.1, "assoc_extra_m": 0.4, "coasting": True},
             # no odometry in the recordings: the sensor's motion from its scans, and a map
             # of what stays put (leg_tracker's local occupancy grid), both online
             "ego_motion": {"name": "scan_matching", "max_pair_m": 0.5, "trim": 0.8,
                            "iterations": 20, "beam_step": 2, "min_pairs": 20,
                            "fallback_every_beam": True, "max_speed_mps": 2.0,
                            "max_turn_rps": 1.5},
             "static_map": {"name": "recent_hits", "cell_m": 0.1, "min_static_s": 1.4,
                            "tau_s": 5.0, "neighbourhood": 1},
             # no confirmation by arrival in free space (it confirmed furniture from a
             # moving robot; docs/history/people.md); written out, not left to the default
             "arrival": {"name": "none"},
             # a tentative pair's legs associated as a pair: beside a standing leg the
             # other swings ahead at up to twice a brisk walker's body speed (2 x 1.5 m/s)
             "pair_swing_mps": 3.0,
             "init": None, "max_leg_separation_m": 0.8, "person_points_m": 0.13, "dt_s": None,
             "sides": "walking_direction"},
}

# The same tracker reading the recording forwards and backwards (docs/people.md, "Two
# passes"; gaitval/track/passes.py): an offline method, since the backward
# pass uses scans after the one it reports.  Not comparable with an online tracker
# (leg_tracker); `people` stays the online one.
METHODS["people_offline"] = copy.deepcopy(METHODS["people"])
METHODS["people_offline"]["label"] = ("People tracker, offline (forward and backward passes "
                                      "joined)")
METHODS["people_offline"]["kind"]["passes"] = {
    "name": "forward_backward", "max_std_m": 0.9, "percentile": 0.90, "std_obs_m": 0.1,
    "assoc_extra_m": 0.4, "extend_only": True, "splice_window_s": 1.4}


def reads_later_scans(definition: dict[str, Any]) -> bool:
    """Does a method (its definition, :func:`get_method`) report a scan using scans recorded
    after it — an offline method: the people tracker's ``forward_backward`` passes?"""
    kind = definition.get("kind")
    passes = kind.get("passes") if isinstance(kind, dict) else None
    return (passes.get("name") if isinstance(passes, dict) else passes) == "forward_backward"
