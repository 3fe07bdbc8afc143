"""C3D motion-capture files (VICON and others): reader, writer and description.

This is the only module in gaitval that knows the C3D format; it uses ezc3d [1]_.
Everything it returns is in metres and seconds (:class:`~gaitval.types.MocapTrial`).

Conventions (also in ``docs/formats.md``)
-----------------------------------------
Units
    ``POINT:UNITS`` ``mm``, ``cm`` or ``m`` is converted to metres.  A file without
    ``POINT:UNITS`` is taken as millimetres (the C3D default; recorded in
    ``meta["units_assumed"]``); any other unit is a :class:`~gaitval.errors.FileFormatError`.
Gaps
    A marker sample is missing (NaN in all three coordinates) when its residual is
    negative (the C3D rule; Vicon writes residual -1 and zero coordinates) **or** when all
    three coordinates are exactly zero (some writers store gaps that way and leave the
    residual at 0).  The second rule is counted separately in ``meta["n_zero_gaps"]``.
Labels
    ``POINT:LABELS`` (and ``LABELS2``, ``LABELS3`` ... for more than 255 points), cut to
    ``POINT:USED``, with trailing blanks removed.  A subject prefix is stripped:
    everything up to and including the last ``:`` (``Matt:LKNE`` -> ``LKNE``), which covers
    Vicon's ``SUBJECTS:LABEL_PREFIXES``.  The original labels are kept in
    ``meta["original_labels"]`` and the prefixes found in ``meta["prefixes"]``.
    Empty labels become ``POINT<k>`` (1-based point index).
Duplicate labels (policy)
    Labels that are equal after prefix stripping are **kept, never merged**: the first
    occurrence keeps the label, later ones get ``#2``, ``#3`` ... (``RKNE``, ``RKNE#2``) in
    file order.  ``meta["duplicates"]`` maps each duplicated label to the list of labels it
    was given, and a warning is logged.  Code that asks for ``RKNE`` therefore gets the
    first one; check ``meta["duplicates"]`` (``gaitval inspect`` prints it) before using
    such a file.  Pass ``duplicates="error"`` to :func:`read_c3d` to refuse such files.
First frame and time
    ``MocapTrial.first_frame`` is the 1-based number of the first stored frame, as Vicon
    numbers frames: the header's first-frame word (ezc3d reports it 0-based, so +1), or
    ``TRIAL:ACTUAL_START_FIELD`` (two 16-bit words, low then high) when present, which
    also holds frame numbers above 65535.  Frame ``i`` (0-based in the arrays) is at
    ``t = (first_frame - 1 + i) / rate_hz`` seconds: frame 1 of the capture is t = 0.
Events
    ``EVENT:CONTEXTS``, ``EVENT:LABELS`` and ``EVENT:TIMES`` (a 2 x n matrix: minutes,
    seconds) give ``t_s = 60 * minutes + seconds``.  C3D event times count from frame 1 of
    the capture, the same time base as ``MocapTrial.t``, so an event at ``t_s`` falls on
    array index ``round(t_s * rate_hz) - (first_frame - 1)``; no shift is applied.  Files
    without an ``EVENT`` group fall back to the header's event block (context empty).
    Events are sorted by time (stable).
Analogs
    Not read; their count and rate are recorded in ``meta``.

References
----------
.. [1] Michaud, B., & Begon, M. (2021). ezc3d: An easy C3D file I/O cross-platform
   solution for C++, Python and MATLAB. Journal of Open Source Software, 6(58), 2911.
.. [2] Motion Lab Systems (2008). The C3D File Format User Guide. https://www.c3d.org
"""
from __future__ import annotations

import contextlib
import logging
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.atomic import atomic_path
from gaitval.types import MocapTrial

log = logging.getLogger(__name__)

#: metres per file unit
UNIT_SCALE = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
EVENT_COLUMNS = ["context", "label", "t_s"]


def _add_int_parameter(c, group: str, name: str, values: list[int]) -> None:
    """Add an INT parameter (ezc3d's ``add_parameter`` would store integers as FLOAT)."""
    from ezc3d import ezc3d as swig

    p = swig.Parameter(name, "")
    p.set(swig.VecInt([int(v) for v in values]), [len(values)])
    c.parameters.add_parameter(group, p)


# -- writing -------------------------------------------------------------------------------

def write_c3d(path: str | Path, labels: list[str], xyz_m: np.ndarray, rate_hz: float, *,
              events: pd.DataFrame | None = None, first_frame: int = 1,
              subject_prefix: str | None = None) -> Path:
    """Write marker trajectories as a C3D file in millimetres (atomically).

    Parameters
    ----------
    path : str or Path
        Target file (``.c3d``).
    labels : list of str
        Marker labels, one per marker (without prefix).
    xyz_m : ndarray, shape (n_frames, n_markers, 3)
        Positions in metres; NaN (in any coordinate) marks a missing sample.
    rate_hz : float
        Point rate.
    events : DataFrame, optional
        Columns ``context``, ``label``, ``t_s`` (seconds on the ``MocapTrial.t`` time base,
        i.e. from frame 1 of the capture).  Written to the ``EVENT`` group.
    first_frame : int
        1-based number of the first stored frame (also in ``TRIAL:ACTUAL_START_FIELD``).
    subject_prefix : str, optional
        Written as ``<prefix>:<label>`` with a Vicon ``SUBJECTS`` group, as Nexus does.

    Returns
    -------
    Path
        ``path``.

    Notes
    -----
    Points are stored as floats (``POINT:SCALE = -1``) in ``mm``.  A missing sample is
    written as Vicon writes it: coordinates 0 and residual -1, so every C3D reader sees
    the gap.  Present samples get residual 0.
    """
    import ezc3d

    xyz = np.asarray(xyz_m, dtype=np.float64)
    if xyz.ndim != 3 or xyz.shape[2] != 3:
        raise ValueError(f"xyz_m must have shape (n_frames, n_markers, 3), not {xyz.shape}")
    n_frames, n_markers, _ = xyz.shape
    labels = [str(s) for s in labels]
    if len(labels) != n_markers:
        raise ValueError(f"{len(labels)} labels for {n_markers} markers")
    if first_frame < 1:
        raise ValueError("first_frame is 1-based and must be >= 1")
    if subject_prefix:
        file_labels = [f"{subject_prefix}:{s}" for s in labels]
    else:
        file_labels = list(labels)

    gap = ~np.all(np.isfinite(xyz), axis=2)                      # (n_frames, n_markers)
    mm = np.where(gap[..., None], 0.0, xyz * 1000.0)
    points = np.ones((4, n_markers, n_frames), dtype=np.float64)
    points[:3] = mm.transpose(2, 1, 0)
    residuals = np.where(gap.T, -1.0, 0.0)[None, :, :]

    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = np.array([float(rate_hz)])
    c["parameters"]["POINT"]["LABELS"]["value"] = file_labels
    c["parameters"]["POINT"]["DESCRIPTIONS"]["value"] = [""] * n_markers
    c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c["header"]["points"]["first_frame"] = int(first_frame - 1)   # ezc3d is 0-based
    c["data"]["points"] = points
    c["data"]["meta_points"] = {
        "residuals": residuals,
        "camera_masks": np.zeros((7, n_markers, n_frames), dtype=bool),
    }
    last = first_frame + n_frames - 1
    _add_int_parameter(c, "TRIAL", "ACTUAL_START_FIELD", [first_frame & 0xFFFF, first_frame >> 16])
    _add_int_parameter(c, "TRIAL", "ACTUAL_END_FIELD", [last & 0xFFFF, last >> 16])
    c.add_parameter("MANUFACTURER", "SOFTWARE", ["gaitval"])
    if subject_prefix:
        _add_int_parameter(c, "SUBJECTS", "USED", [1])
        _add_int_parameter(c, "SUBJECTS", "USES_PREFIXES", [1])
        c.add_parameter("SUBJECTS", "NAMES", [subject_prefix])
        c.add_parameter("SUBJECTS", "LABEL_PREFIXES", [f"{subject_prefix}:"])
    if events is not None and len(events):
        ev = events.reset_index(drop=True)
        for col in EVENT_COLUMNS:
            if col not in ev:
                raise ValueError(f"events need columns {EVENT_COLUMNS}; missing {col!r}")
        t = ev["t_s"].to_numpy(dtype=np.float64)
        times = np.vstack([np.zeros_like(t), t])                 # minutes 0, as Nexus writes
        _add_int_parameter(c, "EVENT", "USED", [len(ev)])
        c.add_parameter("EVENT", "CONTEXTS", [str(s) for s in ev["context"]])
        c.add_parameter("EVENT", "LABELS", [str(s) for s in ev["label"]])
        c.add_parameter("EVENT", "DESCRIPTIONS", [""] * len(ev))
        c.add_parameter("EVENT", "SUBJECTS", [subject_prefix or ""] * len(ev))
        _add_int_parameter(c, "EVENT", "ICON_IDS", [0] * len(ev))
        _add_int_parameter(c, "EVENT", "GENERIC_FLAGS", [0] * len(ev))
        c.add_parameter("EVENT", "TIMES", times)

    with atomic_path(path) as tmp:
        ez_tmp = str(tmp) + ".c3d"                               # ezc3d appends .c3d
        try:
            c.write(ez_tmp)
            os.replace(ez_tmp, tmp)
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(ez_tmp)
    return Path(path)
