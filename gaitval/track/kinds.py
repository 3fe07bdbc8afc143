"""Tracker kinds: how a method turns a trial's scans into a two-leg track.

Role ``kind``: ``track(scans, leg_width_m) -> TrackResult``.  A method entry chooses its
kind (``kind: {name: ...}``; default ``detect_then_track``):

``detect_then_track`` (:class:`DetectThenTrack`)
    A detector role makes per-scan observations and the per-scan :class:`Tracker` loop
    (predict, gate, associate, correct, occlusion) follows the legs (seeds 000, 001 and the
    KF of 002).  A detector with ``windowed = True`` is called scan by scan with the
    prediction (seed 002 §II's observation window) instead of once for the whole trial.
:class:`RawScanTracker` (interface)
    A tracker that reads the raw laser points itself, e.g. seed 002's particle filter (one
    filter of 500 particles per leg weighted by the points around each particle).  It
    receives the whole :class:`~gaitval.types.ScanSeries` and returns the same
    :class:`TrackResult`, so evaluation, tables and the workflow do not change; its parts
    (initialising detector, proposal, likelihood, resampling) are its own parameters.
"""
from __future__ import annotations

from gaitval.detect.base import split_observations
from gaitval.registry import Registry
from gaitval.track.leg import TrackResult
from gaitval.track.tracker import Tracker
from gaitval.types import ScanSeries

TRACKER_KINDS = Registry("tracker kind", table="gaitval.track.roles")


class TrackerKind:
    """Role base.

    ``accepts_observations``: the kind runs its detector once over all of a trial's scans
    before it tracks, and ``track`` takes that detector's observation table made earlier
    (``observations``, :mod:`gaitval.detect.base`) instead of detecting again: methods
    that share a detector configuration share its observations
    (:func:`gaitval.methods.trial_detector`).
    """

    accepts_observations = False

    def track(self, scans: ScanSeries, leg_width_m: float, observations=None) -> TrackResult:
        raise NotImplementedError


class DetectThenTrack(TrackerKind):
    """A detector role followed by the per-scan :class:`Tracker` loop.

    ``detector_spec``: the detector's spec (``{"name": ..., **params}``), given by
    :func:`gaitval.methods.build_method` (kept for the record: which detector ran).
    """

    def __init__(self, detector, tracker: Tracker, detector_spec: dict | None = None):
        self.detector = detector
        self.tracker = tracker
        self.detector_spec = detector_spec

    accepts_observations = True

    def track(self, scans, leg_width_m, observations=None):
        """``observations``: this method's detector's table of these scans, made earlier
        (None: detect now; ignored by a windowed detector, which looks scan by scan)."""
        if getattr(self.detector, "windowed", False):
            return self.tracker.run_windowed(scans, self.detector, leg_width_m)
        obs = (self.detector.detect(scans, leg_width_m) if observations is None
               else observations)
        xy, pats = split_observations(obs, scans.n_scans)
        return self.tracker.run(scans.t, xy, pats, leg_width_m)


class RawScanTracker(TrackerKind):
    """Interface of a tracker that reads raw scans (see the module notes).

    Subclasses register under a name and take their parameters as keyword arguments
    (a ``seed`` for any random draw, so that the same seed gives the same track).
    """
