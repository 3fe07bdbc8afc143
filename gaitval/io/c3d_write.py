"""Writing C3D files (the simulator's mocap, the replay study's re-exported walks).

Part of :mod:`gaitval.io.c3d`, which re-exports :func:`write_c3d`; the conventions
(units, gaps, labels, first frame, events) are in that module's notes.  It uses
ezc3d [1]_.

References
----------
.. [1] Michaud, B., & Begon, M. (2021). ezc3d: An easy C3D file I/O cross-platform
   solution for C++, Python and MATLAB. Journal of Open Source Software, 6(58), 2911.
.. [2] Motion Lab Systems (2008). The C3D File Format User Guide. https://www.c3d.org
"""
from __future__ import annotations

import contextlib
import os
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.atomic import atomic_path, write_bytes
from gaitval.io.c3d_format import EVENT_COLUMNS

def _add_int_parameter(c, group: str, name: str, values: list[int]) -> None:
    """Add an INT parameter (ezc3d's ``add_parameter`` would store integers as FLOAT)."""
    from ezc3d import ezc3d as swig

    p = swig.Parameter(name, "")
    p.set(swig.VecInt([int(v) for v in values]), [len(values)])
    c.parameters.add_parameter(group, p)


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
    xyz = np.asarray(xyz_m, dtype=np.float64)
    if xyz.ndim != 3 or xyz.shape[2] != 3:
        raise ValueError(f"xyz_m must have shape (n_frames, n_markers, 3), not {xyz.shape}")
    n_frames, n_markers, _ = xyz.shape
    if n_frames == 0 or n_markers == 0:
        raise ValueError(f"{path}: a C3D file needs at least one frame and one marker "
                         f"(xyz_m holds {n_frames} frames of {n_markers} markers)")
    if not (np.isfinite(float(rate_hz)) and float(rate_hz) > 0):
        raise ValueError(f"{path}: rate_hz must be a finite number > 0, not {rate_hz!r}")
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
    fast = _FAST and n_frames >= 1
    if not _write(path, file_labels, mm, gap, rate_hz, events, first_frame, subject_prefix,
                  fast=fast):
        _write(path, file_labels, mm, gap, rate_hz, events, first_frame, subject_prefix,
               fast=False)
    return Path(path)


def _write(path, file_labels, mm, gap, rate_hz, events, first_frame, subject_prefix, *,
           fast: bool) -> bool:
    """Write the file (ezc3d alone, or ezc3d and numpy when ``fast``); False when the fast
    path cannot write this file as ezc3d would (nothing written then)."""
    import ezc3d

    n_frames, n_markers = gap.shape
    n_obj = 1 if fast else n_frames        # the fast path gives ezc3d one frame (below)
    points = np.ones((4, n_markers, n_obj), dtype=np.float64)
    points[:3] = mm[:n_obj].transpose(2, 1, 0)
    residuals = np.where(gap[:n_obj].T, -1.0, 0.0)[None, :, :]

    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = np.array([float(rate_hz)])
    c["parameters"]["POINT"]["LABELS"]["value"] = file_labels
    c["parameters"]["POINT"]["DESCRIPTIONS"]["value"] = [""] * n_markers
    c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c["header"]["points"]["first_frame"] = int(first_frame - 1)   # ezc3d is 0-based
    c["data"]["points"] = points
    # no camera masks given: ezc3d writes them as 0, the same bytes as an all-False
    # (7, n_markers, n_frames) array, ~15 % faster for a 60,000-frame trial
    c["data"]["meta_points"] = {"residuals": residuals}
    _add_trial_parameters(c, first_frame, n_frames, subject_prefix)
    if events is not None and len(events):
        _add_events(c, events, subject_prefix)
    if fast:
        return _write_frames_after(c, path, _float_frames(mm, gap), first_frame, n_frames,
                                   n_markers)
    _write_atomic(c, path)
    return True


# -- the fast path: ezc3d writes header and parameters, numpy the frames --------------------
# ezc3d turns every sample into a C++ object before writing it: 0.30 CPU-s for a
# 60,000-frame trial of 9 markers, ~40 % of the simulation of the default study.  The
# fast path lets ezc3d write the same file with one frame, sets the three numbers that
# depend on the frame count as ezc3d sets them (header word 5, POINT:FRAMES,
# ROTATION:DATA_START) and writes the frames with numpy: 0.03 s, byte-identical to
# ezc3d's whole file (tests/test_c3d_writer.py compares the two for 1 to 120,000 frames,
# gaps, events, a subject prefix and a late first frame).
_INT16_MAX = 0x7FFF
_FAST = True                            # False: ezc3d writes the frames too (tests compare)
_HEADER_LAST_FRAME = 8                  # byte offset of header word 5 (last frame, uint16)


def _rotation_start(n_frames: int, n_markers: int, data_start: int) -> int:
    """The block after the point data, as ezc3d writes ROTATION:DATA_START (int16): one
    past the last block the frames touch (16 bytes per marker and frame)."""
    return data_start + (n_frames * n_markers * 16) // 512 + 1


def _float_frames(mm: np.ndarray, gap: np.ndarray) -> bytes:
    """The data section of a float C3D without analogs: per frame and marker x, y, z (mm)
    and the residual word, little-endian float32: 0 for a sample, -1 for a gap (whose
    coordinates are 0), as ezc3d writes residual 0 / -1 with no camera mask."""
    n_frames, n_markers = gap.shape
    out = np.empty((n_frames, n_markers, 4), dtype="<f4")
    out[..., :3] = mm                                  # double -> float, round to nearest
    out[..., 3] = np.where(gap, -1.0, 0.0)
    return out.tobytes()


def _write_frames_after(c, path: str | Path, frames: bytes, first_frame: int,
                        n_frames: int, n_markers: int) -> bool:
    """Write ``c`` (one frame) with ezc3d, put the real frame count and ``frames`` in its
    place, and write the result to ``path`` atomically.  False, writing nothing, when the
    frames reach past block 32,767 (ROTATION:DATA_START would not fit its int16: left to
    ezc3d)."""
    import struct
    import tempfile

    from gaitval.io.c3d_params import parse_parameters

    with tempfile.TemporaryDirectory(prefix="gaitval-c3d-") as tmp:
        one_path = Path(tmp) / "one_frame.c3d"
        c.write(str(one_path))
        one = one_path.read_bytes()
    data_start = struct.unpack_from("<H", one, 16)[0]
    rotation = _rotation_start(n_frames, n_markers, data_start)
    if rotation > _INT16_MAX:
        return False
    params = parse_parameters(one, (one[0] - 1) * 512, (data_start - 1) * 512)
    buf = bytearray(one[:(data_start - 1) * 512])
    last = min(first_frame + n_frames - 1, 0xFFFF)               # ezc3d saturates it
    struct.pack_into("<H", buf, _HEADER_LAST_FRAME, last)
    struct.pack_into("<H", buf, params["POINT", "FRAMES"].offset, min(n_frames, 0xFFFF))
    struct.pack_into("<h", buf, params["ROTATION", "DATA_START"].offset, rotation)
    buf += frames
    # zeros up to the block ROTATION:DATA_START names (a whole block of them when the
    # frames end on a block boundary, as ezc3d writes it)
    buf += bytes((rotation - 1) * 512 - len(buf))
    write_bytes(path, bytes(buf))
    return True


def _add_trial_parameters(c, first_frame: int, n_frames: int,
                          subject_prefix: str | None) -> None:
    """TRIAL first/last frame (two 16-bit words), MANUFACTURER and a Vicon SUBJECTS group."""
    last = first_frame + n_frames - 1
    _add_int_parameter(c, "TRIAL", "ACTUAL_START_FIELD", [first_frame & 0xFFFF, first_frame >> 16])
    _add_int_parameter(c, "TRIAL", "ACTUAL_END_FIELD", [last & 0xFFFF, last >> 16])
    c.add_parameter("MANUFACTURER", "SOFTWARE", ["gaitval"])
    if subject_prefix:
        _add_int_parameter(c, "SUBJECTS", "USED", [1])
        _add_int_parameter(c, "SUBJECTS", "USES_PREFIXES", [1])
        c.add_parameter("SUBJECTS", "NAMES", [subject_prefix])
        c.add_parameter("SUBJECTS", "LABEL_PREFIXES", [f"{subject_prefix}:"])


def _add_events(c, events: pd.DataFrame, subject_prefix: str | None) -> None:
    """The EVENT group as Nexus writes it (times as minutes 0, seconds)."""
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


def _write_atomic(c, path: str | Path) -> None:
    """Write the ezc3d object to ``path`` through a temporary file (ezc3d appends .c3d)."""
    with atomic_path(path) as tmp:
        ez_tmp = str(tmp) + ".c3d"                               # ezc3d appends .c3d
        try:
            c.write(ez_tmp)
            os.replace(ez_tmp, tmp)
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(ez_tmp)
