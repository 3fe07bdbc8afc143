"""Leg tracking: one subpackage module per role, and the :class:`Tracker` that wires them.

Roles and their registries: ``FILTERS`` (kalman), ``MOTION_MODELS`` (motion),
``GATES`` (gate), ``ASSOCIATORS`` (associate), ``OCCLUSION_HANDLERS`` (occlusion).
"""
from gaitval.track.associate import ASSOCIATORS  # noqa: F401
from gaitval.track.gate import GATES  # noqa: F401
from gaitval.track.kalman import FILTERS  # noqa: F401
from gaitval.track.motion import MOTION_MODELS  # noqa: F401
from gaitval.track.occlusion import OCCLUSION_HANDLERS  # noqa: F401
from gaitval.track.tracker import TRACK_COLUMNS, Tracker, TrackResult  # noqa: F401
