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

import dataclasses
import hashlib
import json
from collections import OrderedDict

import numpy as np

from gaitval.detect.base import split_observations
from gaitval.registry import Registry
from gaitval.track.leg import TrackResult
from gaitval.track.tracker import Tracker
from gaitval.types import ScanSeries

TRACKER_KINDS = Registry("tracker kind")


class TrackerKind:
    """Role base."""

    def track(self, scans: ScanSeries, leg_width_m: float) -> TrackResult:
        raise NotImplementedError


#: Detections of recent trials, by (detector spec, leg width, the scans' contents): the
#: methods of one paper share their detector (seed 000's three methods and their reading
#: variants, six tracks a trial; seed 001's four methods, two detectors), and a process that
#: runs many jobs (a warm worker of gaitval.forkserver) detects each trial's legs once per
#: detector instead of once per method.  Same numbers: a hit is a copy of what the same
#: detector returned for the same scans.
_DETECTIONS: OrderedDict = OrderedDict()
_DETECTIONS_MAX = 256          # a few MB: a trial's detections are ~10^3 rows


def _scans_key(scans: ScanSeries) -> bytes:
    """SHA-1 of every field of a scan series (arrays by dtype, shape and bytes)."""
    h = hashlib.sha1()
    for f in dataclasses.fields(scans):
        v = getattr(scans, f.name)
        h.update(f.name.encode())
        if isinstance(v, np.ndarray):
            a = np.ascontiguousarray(v)
            h.update(f"{a.dtype.str}{a.shape}".encode())
            h.update(a.tobytes())
        elif hasattr(v, "to_csv"):                     # a DataFrame (timestamp issues)
            h.update(v.to_csv(index=False).encode())
        else:
            h.update(repr(v).encode())
    return h.digest()


@TRACKER_KINDS.register("detect_then_track")
class DetectThenTrack(TrackerKind):
    """A detector role followed by the per-scan :class:`Tracker` loop.

    ``detector_spec``: the detector's spec (``{"name": ..., **params}``), given by
    :func:`gaitval.methods.build_method`; with it, the detections are remembered for the
    next method with the same detector on the same scans (:data:`_DETECTIONS`).
    """

    def __init__(self, detector, tracker: Tracker, detector_spec: dict | None = None):
        self.detector = detector
        self.tracker = tracker
        self.detector_spec = detector_spec

    def _detect(self, scans, leg_width_m):
        if self.detector_spec is None:
            return self.detector.detect(scans, leg_width_m)
        key = (json.dumps(self.detector_spec, sort_keys=True, default=repr),
               float(leg_width_m), _scans_key(scans))
        hit = _DETECTIONS.get(key)
        if hit is None:
            hit = self.detector.detect(scans, leg_width_m)
            _DETECTIONS[key] = hit
            if len(_DETECTIONS) > _DETECTIONS_MAX:
                _DETECTIONS.popitem(last=False)
        else:
            _DETECTIONS.move_to_end(key)
        return hit.copy(deep=True)

    def track(self, scans, leg_width_m):
        if getattr(self.detector, "windowed", False):
            return self.tracker.run_windowed(scans, self.detector, leg_width_m)
        obs = self._detect(scans, leg_width_m)
        xy, pats = split_observations(obs, scans.n_scans)
        return self.tracker.run(scans.t, xy, pats, leg_width_m)


class RawScanTracker(TrackerKind):
    """Interface of a tracker that reads raw scans (see the module notes).

    Subclasses register under a name and take their parameters as keyword arguments
    (a ``seed`` for any random draw, so that the same seed gives the same track).
    """
