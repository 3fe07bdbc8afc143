"""A trial's leg detections made once and read by every method that detects the same way
(issue 38).

Several tracking methods of a study run the same detector over the same scans: seed 000's
three methods, their eq. (3)-(4) reading variants and the people tracker (one spec, seven
track jobs per TUG trial), and three of seed 001's four methods with the people tracker
(the FS_U detector; Method 1 has its own).  The workflow makes each such detector's
observation table once per trial (rule ``detect``, verbs ``detect`` and ``mtst-detect``)
and hands the file to each method's track step (``--detections``), which tracks from it
instead of detecting again.  A track is the same either way: the tracker receives the
same table (:func:`gaitval.methods.track_trial`'s ``observations``).

The file is the detector's observation table (:mod:`gaitval.detect.base`) with three
schema metadata keys: the detector spec (canonical JSON), the leg width it was run with,
and a fingerprint of the scans (their count and timestamps).  A track step checks all
three against its own method, leg width and scans before it uses the table, so a file
made for another detector, subject or scan rate is refused with the file named, never
used.  Where the files live and which methods share them: docs/speed.md.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError, GaitvalError
from gaitval.io.atomic import write_parquet

META_SPEC = "gaitval.detector"
META_WIDTH = "gaitval.leg_width_m"
META_SCANS = "gaitval.scans"


def canonical(spec) -> str:
    """A detector spec as canonical JSON (sorted keys): equal specs, equal text."""
    return json.dumps(spec, sort_keys=True, separators=(",", ":"))


def detector_key(spec) -> str:
    """The folder name of a detector spec's detections: its name and a digest of the
    spec (``leg_patterns-1f3a...``)."""
    name = spec if isinstance(spec, str) else spec["name"]
    return f"{name}-{hashlib.sha256(canonical(spec).encode()).hexdigest()[:12]}"


def method_detector(cfg: dict, method: str, overrides: dict | None = None):
    """The detector spec ``method`` runs once over a trial's scans with the config (view)
    ``cfg`` and ``overrides`` (default: ``tracking.overrides.<method>`` of ``cfg``), or
    None (:func:`gaitval.methods.trial_detector`)."""
    from gaitval.methods import trial_detector

    tracking = cfg.get("tracking") or {}
    mdef = (tracking.get("methods") or {}).get(method, method)
    if overrides is None:
        overrides = (tracking.get("overrides") or {}).get(method)
    return trial_detector(mdef, overrides)


def scans_fingerprint(scans) -> str:
    """The scans' count, beams and a digest of their timestamps."""
    t = np.ascontiguousarray(np.asarray(scans.t, dtype=np.float64))
    ranges = np.asarray(scans.ranges)
    shape = "x".join(str(n) for n in ranges.shape)
    return f"{shape}:{hashlib.sha256(t.tobytes()).hexdigest()[:16]}"


def detect_and_write(scans, spec, leg_width_m: float, out_parquet, *, trial: str,
                     source=None) -> pd.DataFrame:
    """Run detector ``spec`` over a trial's scans and write its observation table with the
    metadata a track step checks (module notes)."""
    from gaitval.detect import DETECTORS

    try:
        obs = DETECTORS.build(spec).detect(scans, float(leg_width_m))
    except GaitvalError as exc:
        raise exc.with_context(path=source, trial=trial) from None
    write_parquet(obs.reset_index(drop=True), out_parquet, metadata={
        META_SPEC: canonical(spec), META_WIDTH: repr(float(leg_width_m)),
        META_SCANS: scans_fingerprint(scans)})
    return obs


def read_detections(path, spec, leg_width_m: float, scans, *, trial: str) -> pd.DataFrame:
    """The observation table of ``path``, after checking that it was made by detector
    ``spec`` with leg width ``leg_width_m`` from these ``scans`` (module notes)."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path, use_threads=False)
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"cannot read the detections: {exc}", path=path,
                              trial=trial) from None
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    wanted = {META_SPEC: canonical(spec), META_WIDTH: repr(float(leg_width_m)),
              META_SCANS: scans_fingerprint(scans)}
    for key, what in ((META_SPEC, "detector"), (META_WIDTH, "leg width"),
                      (META_SCANS, "scan series")):
        if meta.get(key) != wanted[key]:
            raise FileFormatError(
                f"the detections were made with another {what} ({meta.get(key)!r}) than "
                f"this method's ({wanted[key]!r})", path=path, trial=trial,
                hint="detect again with this method's detector (gaitval detect), or track "
                     "without --detections")
    return table.to_pandas()


def detections_or_none(path, spec, leg_width_m: float, scans, *, trial: str,
                       method: str) -> pd.DataFrame | None:
    """:func:`read_detections` when a file is given (``path``), else None; a file given
    for a method that detects nothing once per trial is refused."""
    if not path:
        return None
    if spec is None:
        raise GaitvalError(f"method {method!r} does not run a detector once over the trial's "
                           "scans, so it cannot track from detections", path=path, trial=trial,
                           hint="leave out --detections for this method")
    return read_detections(Path(path), spec, leg_width_m, scans, trial=trial)
