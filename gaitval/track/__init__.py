"""Leg tracking: one module per role, and the :class:`Tracker` that wires them.

Roles and their registries: ``FILTERS`` (kalman), ``MOTION_MODELS`` (motion),
``PHASE_MODELS`` (phase), ``GATES`` (gate), ``ASSOCIATORS`` (associate),
``OCCLUSION_HANDLERS`` (occlusion), ``INITIALISERS`` (init), and ``TRACKER_KINDS`` (kinds:
detect-then-track, or a tracker that reads raw scans such as a particle filter); and
``UKF_TRACKERS`` (ukf: trackers of an ultrasonic log's ranges, seed 003).
"""
from gaitval.track.associate import ASSOCIATORS  # noqa: F401
from gaitval.track.gate import GATES  # noqa: F401
from gaitval.track.init import INITIALISERS  # noqa: F401
from gaitval.track import init_mtst  # noqa: F401  (registers "mtst_participant", seed 001)
from gaitval.track import init_annotated  # noqa: F401  (registers "annotated_pair")
from gaitval.track.kalman import FILTERS  # noqa: F401
from gaitval.track.kinds import TRACKER_KINDS  # noqa: F401
from gaitval.track.motion import MOTION_MODELS  # noqa: F401
from gaitval.track.occlusion import OCCLUSION_HANDLERS  # noqa: F401
from gaitval.track import occlusion_mtst  # noqa: F401  (registers "uo_pseudo_update")
from gaitval.track.phase import PHASE_MODELS  # noqa: F401
from gaitval.track.tracker import TRACK_COLUMNS, Tracker, TrackResult  # noqa: F401
from gaitval.track.ukf import UKF_TRACKERS  # noqa: F401

#: every role registry, by the role's key in a method entry
ROLE_REGISTRIES = {"filter": FILTERS, "motion": MOTION_MODELS, "phase": PHASE_MODELS,
                   "gate": GATES, "associator": ASSOCIATORS, "occlusion": OCCLUSION_HANDLERS,
                   "init": INITIALISERS}
# seed 002: registers the "facing_pair" initialiser and the "reinit_after_lost" handler
from gaitval.track import reinit  # noqa: F401,E402
from gaitval.track import pf  # noqa: F401,E402  (registers the "rollator_pf" kind)
# issue 36: the life-cycle roles and the "people" kind (several persons, two legs each)
from gaitval.track import people  # noqa: F401,E402  (registers the "people" kind)
