"""Leg tracking: one module per role, and the :class:`Tracker` that wires them.

Roles and their registries: ``FILTERS`` (kalman), ``MOTION_MODELS`` (motion),
``PHASE_MODELS`` (phase), ``GATES`` (gate), ``ASSOCIATORS`` (associate),
``OCCLUSION_HANDLERS`` (occlusion), ``INITIALISERS`` (init), and ``TRACKER_KINDS`` (kinds:
detect-then-track, or a tracker that reads raw scans such as a particle filter); and
``UKF_TRACKERS`` (ukf: trackers of an ultrasonic log's ranges, seed 003).  Which part is
registered under which name is one table, :mod:`gaitval.track.roles`.
"""
from gaitval.track.roles import (ASSOCIATORS, FILTERS, GATES, INITIALISERS,  # noqa: F401
                                 MOTION_MODELS, OCCLUSION_HANDLERS, PHASE_MODELS,
                                 ROLE_REGISTRIES, TRACKER_KINDS, UKF_TRACKERS)
from gaitval.track.tracker import TRACK_COLUMNS, Tracker, TrackResult  # noqa: F401
