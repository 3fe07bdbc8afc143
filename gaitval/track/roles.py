"""The tracker roles' parts, by name: the one table that fills the role registries.

Each role's registry (``FILTERS`` in :mod:`gaitval.track.kalman`, ``GATES`` in
:mod:`gaitval.track.gate`, …) names this module as its table and imports it the first
time it is read, so a registry holds every part whatever was imported before.  Adding a
part is one class and one line below.  (The people tracker's kind ``people`` registers
itself in :mod:`gaitval.track.people`, imported here for that.)

:data:`ROLE_REGISTRIES` maps a method entry's role keys to their registries
(:mod:`gaitval.methods`).
"""
from __future__ import annotations

from gaitval.track import people  # noqa: F401  (registers the kind "people" itself)
from gaitval.track.associate import (ASSOCIATORS, AssignmentGNN, GaitPhaseAssociator,
                                     GNNAssociator)
from gaitval.track.gate import (GATES, ChiSquareGate, FixedRadiusGate,
                                VariableValidationRegion)
from gaitval.track.init import INITIALISERS, ClosestMovingPair
from gaitval.track.init_annotated import AnnotatedPair
from gaitval.track.init_mtst import MatLaneParticipant
from gaitval.track.kalman import (FILTERS, AnisotropicKalmanFilter, AxisKalmanFilter,
                                  MatrixKalmanFilter)
from gaitval.track.kinds import TRACKER_KINDS, DetectThenTrack
from gaitval.track.motion import MOTION_MODELS, ConstantVelocity, GaitPhaseAcceleration
from gaitval.track.occlusion import OCCLUSION_HANDLERS, CatmullRomInterpolation, PredictOnly
from gaitval.track.occlusion_mtst import PseudoObservation
from gaitval.track.pf import ParticleFilterTracker
from gaitval.track.phase import PHASE_MODELS, SpeedThresholdPhases
from gaitval.track.reinit import FacingPair, ReinitialiseAfterLost
from gaitval.track.ukf import UKF_TRACKERS, ToaUkf

#: registry -> {config name: part}
TABLE = {
    FILTERS: {"kf": AxisKalmanFilter,                 # seed 000 §3.1, per axis
              "kf_aniso": AnisotropicKalmanFilter,    # seed 002 §II
              "kf_matrix": MatrixKalmanFilter},       # the 4×4 reference
    MOTION_MODELS: {"gait_phase_accel": GaitPhaseAcceleration,   # seed000 eq. (18)–(20)
                    "constant_velocity": ConstantVelocity},      # seed001 eq. (2)
    PHASE_MODELS: {"speed_thresholds": SpeedThresholdPhases},    # seed000 eq. (3)–(5)
    GATES: {"chi2": ChiSquareGate,                    # seed000 eq. (13)
            "fixed_radius": FixedRadiusGate,          # seed001 eq. (5)
            "variable_region": VariableValidationRegion},        # seed001 Table 1
    ASSOCIATORS: {"gnn": GNNAssociator,               # seed000 eq. (9)–(10)
                  "gait_phase": GaitPhaseAssociator,  # seed 000 §5.2
                  "gnn_assignment": AssignmentGNN},   # seed001 eq. (6)–(8)
    OCCLUSION_HANDLERS: {"predict_only": PredictOnly,            # seed 000 §5.3
                         "catmull_rom": CatmullRomInterpolation,  # seed000 eq. (17)
                         "reinit_after_lost": ReinitialiseAfterLost,   # seed 002 §II
                         "uo_pseudo_update": PseudoObservation},  # seed 001 §2.4.3
    INITIALISERS: {"closest_pair": ClosestMovingPair,
                   "facing_pair": FacingPair,                     # seed 002
                   "mtst_participant": MatLaneParticipant,        # seed 001
                   "annotated_pair": AnnotatedPair},
    TRACKER_KINDS: {"detect_then_track": DetectThenTrack,
                    "rollator_pf": ParticleFilterTracker},        # seed 002 §III
    UKF_TRACKERS: {"toa_ukf": ToaUkf},                            # seed 003
}

for _registry, _parts in TABLE.items():
    for _name, _cls in _parts.items():
        _registry.add(_name, _cls)

#: every role registry, by the role's key in a method entry
ROLE_REGISTRIES = {"filter": FILTERS, "motion": MOTION_MODELS, "phase": PHASE_MODELS,
                   "gate": GATES, "associator": ASSOCIATORS, "occlusion": OCCLUSION_HANDLERS,
                   "init": INITIALISERS}
