"""Foot trajectories as an exchange format: ``*.foot.csv`` and ``*.foot.parquet`` (version 1).

The treadmill protocol (seed 003) validates a foot-mounted system's 3-D trajectory of one
heel against the heel marker, stride by stride.  Another system's heel trajectory (a
vendor's ultrasonic or inertial system, a depth camera's) enters the same gait-parameter
extraction and agreement statistics through this format (issue 37; docs/formats_external.md,
section *Foot trajectories*): one row per time stamp, columns ``t_s``, ``x``, ``y``,
``z``.  The header is that of the leg-track format (:mod:`gaitval.io.tracks`): ``units``
(``m``/``mm``), ``frame`` (``sensor``: the ultrasonic receivers' frame, that of the
trial's anchor table; ``mocap``: the C3D's field frame), ``clock`` (``sensor``: the
ultrasonic log's clock; ``mocap``: the C3D's time) and the optional ``clock_offset_s``
(a third clock).  CSV: first line ``# gaitval-foot v1``; Parquet: schema metadata key
``gaitval:foot``.

:func:`read_foot` returns the rows in metres; :func:`ukf_track_to_foot` and
:func:`write_foot` write gaitval's own UKF track in the format, so that an export and
re-import give the same strides and tables.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.tracks.exchange import (UNITS, VERSION, _check_meta, _err, _floats,
                                        _on_header_clock, open_exchange)
from gaitval.io.tracks.write import _write_rows

FOOT_FORMAT = "gaitval-foot"
FOOT_META_KEY = b"gaitval:foot"
FOOT_COLUMNS = ("t_s", "x", "y", "z")
#: at least this many finite positions (the alignment needs a trajectory)
MIN_SAMPLES = 10
#: most positions farther than this from the receivers' centre: not the treadmill's heel
#: in metres in that frame (millimetres declared as metres, or another frame); the
#: receivers of seed 003 stand within about 1 m of the walking heel
MAX_FROM_RECEIVERS_M = 5.0
#: every position within this of the receivers' centre: metres declared as millimetres
MIN_FROM_RECEIVERS_M = 0.02


def read_foot(path: str | Path, *, trial: str | None = None) -> tuple[pd.DataFrame, dict]:
    """Read a ``*.foot.csv`` or ``*.foot.parquet`` file.

    Returns
    -------
    (DataFrame, dict)
        ``t_s`` (on the header's clock, its ``clock_offset_s`` added), ``x_m``, ``y_m``,
        ``z_m`` (metres; NaN where the system has no position), in file order; and the
        header.

    Raises
    ------
    FileFormatError
        Naming the file, the field or column and the line (CSV) or data row (Parquet): a
        wrong first line, version, units, frame or clock, a missing or unknown column, a
        non-number, a time stamp given twice or going back, one or two of x, y, z empty
        and not all three, fewer than :data:`MIN_SAMPLES` positions.
    """
    p = Path(path)
    meta, names, cols, where, meta_lines, first_line = open_exchange(
        p, trial, "foot", FOOT_FORMAT, FOOT_META_KEY, FOOT_COLUMNS, FOOT_COLUMNS,
        "one foot: the one the reference marker is on")
    scale = UNITS[meta["units"]]
    t = _on_header_clock(_floats(p, "t_s", cols["t_s"], where, trial, finite=True), meta)
    back = np.flatnonzero(np.diff(t) <= 0)
    if len(back):
        i = int(back[0]) + 1
        raise _err(p, f"{where(i)}: time stamp {float(t[i])!r} s is not after the previous "
                   f"row's {float(t[i - 1])!r} s (one row per time stamp, in time order)",
                   trial)
    xyz = np.column_stack([_floats(p, c, cols[c], where, trial, finite=False) * scale
                           for c in ("x", "y", "z")])
    nan = np.isnan(xyz)
    part = nan.any(axis=1) & ~nan.all(axis=1)
    if part.any():
        i = int(np.flatnonzero(part)[0])
        raise _err(p, f"{where(i)}: some of 'x', 'y', 'z' are empty and some not (all "
                   "three empty: no position at this time)", trial)
    if np.isinf(xyz).any():
        i = int(np.flatnonzero(np.isinf(xyz).any(axis=1))[0])
        raise _err(p, f"{where(i)}: a non-finite position", trial)
    n_ok = int((~nan.any(axis=1)).sum())
    if n_ok < MIN_SAMPLES:
        raise _err(p, f"{n_ok} rows with a position; the stride segmentation needs at "
                   f"least {MIN_SAMPLES}", trial)
    df = pd.DataFrame({"t_s": t, "x_m": xyz[:, 0], "y_m": xyz[:, 1], "z_m": xyz[:, 2]})
    meta = {**meta, "source": str(meta.get("source") or p.name),
            "_row": ("line" if meta_lines is not None else "row", first_line)}
    return df, meta


def ukf_track_to_foot(track: pd.DataFrame) -> pd.DataFrame:
    """gaitval's ultrasonic UKF track (``t_s, x_m, y_m, z_m``: the ultrasonic clock and
    frame, metres) as exchange-format rows."""
    return pd.DataFrame({"t_s": track["t_s"].to_numpy(float),
                         "x": track["x_m"].to_numpy(float),
                         "y": track["y_m"].to_numpy(float),
                         "z": track["z_m"].to_numpy(float)})


def write_foot(rows: pd.DataFrame, path: str | Path, *, units: str = "m",
               frame: str = "sensor", clock: str = "sensor", **extra) -> Path:
    """Write foot rows (``t_s, x, y, z``; positions in ``units``, NaN for none) as
    ``*.foot.csv`` or ``*.foot.parquet``, atomically; CSV floats as their shortest exact
    text, so a round trip gives the same numbers.  ``extra`` header keys (``source``,
    ``clock_offset_s``) follow the required ones."""
    p = Path(path)
    meta = _check_meta({"format": FOOT_FORMAT, "version": VERSION, "units": units,
                        "frame": frame, "clock": clock}, p, None, fmt=FOOT_FORMAT,
                       meta_key=FOOT_META_KEY)
    meta.update({k: str(v) for k, v in extra.items()})
    rows = rows[list(FOOT_COLUMNS)].reset_index(drop=True)
    return _write_rows(p, rows, meta, FOOT_FORMAT, FOOT_META_KEY, "foot", all_float=True)


def check_foot(foot: pd.DataFrame, meta: dict, *, t_range: tuple[float, float],
               tolerance_s: float, centre: np.ndarray, path=None,
               trial: str | None = None) -> None:
    """A heel trajectory that can be this trial's: at least :data:`MIN_SAMPLES` time
    stamps inside the recording on the header's clock (``t_range`` ± ``tolerance_s``: the
    ultrasonic log's span for ``clock: sensor``, the C3D's for ``clock: mocap``; another
    system may record longer than either, so stamps outside are allowed while enough are
    inside) and positions (in the receivers' frame, metres) whose median distance from the
    receivers' ``centre`` is at most :data:`MAX_FROM_RECEIVERS_M` and not all within
    :data:`MIN_FROM_RECEIVERS_M`.

    Raises
    ------
    FileFormatError
        Naming the file, the trial, the row (CSV line or Parquet row) and the header's
        clock, or units and frame."""
    kind, first = meta.get("_row", ("row", 1))
    t = foot["t_s"].to_numpy(float)
    lo, hi = t_range[0] - tolerance_s, t_range[1] + tolerance_s
    out = (t < lo) | (t > hi)
    if (~out).sum() < MIN_SAMPLES:
        i = int(np.flatnonzero(out)[0])
        c0 = float(meta.get("clock_offset_s") or 0.0)
        off = f" after the header's clock_offset_s {c0!r} s" if c0 else ""
        raise _err(path, f"{kind} {first + i}, column 't_s': time stamp {t[i] - c0!r} s "
                   f"({meta['clock']} clock{off}) is outside the recording ({t_range[0]:.4f} "
                   f"to {t_range[1]:.4f} s on that clock), as are {int(out.sum())} of "
                   f"{len(t)} time stamps (at least {MIN_SAMPLES} must be inside)", trial,
                   hint="check the header's clock (sensor: the ultrasonic log's; mocap: the "
                        "C3D's) and clock_offset_s")
    xyz = foot[["x_m", "y_m", "z_m"]].to_numpy(float)
    d = np.linalg.norm(xyz - np.asarray(centre, float), axis=1)
    ok = np.isfinite(d)
    head = f"header units {meta['units']!r}, frame {meta['frame']!r}"
    if np.median(d[ok]) > MAX_FROM_RECEIVERS_M:
        i = int(np.flatnonzero(ok & (d > MAX_FROM_RECEIVERS_M))[0])
        raise _err(path, f"{kind} {first + i}, column 'x': the position is {d[i]:.1f} m from "
                   f"the receivers' centre, as is the median position ({np.median(d[ok]):.1f} "
                   f"m; more than {MAX_FROM_RECEIVERS_M:g} m: not the heel on the treadmill; "
                   f"{head})", trial, hint="positions in millimetres need 'units: mm'; "
                   "positions in the mocap field need 'frame: mocap'")
    if d[ok].max() < MIN_FROM_RECEIVERS_M:
        i = int(np.flatnonzero(ok)[0])
        raise _err(path, f"{kind} {first + i}, column 'x': every position lies within "
                   f"{MIN_FROM_RECEIVERS_M * 100:g} cm of the receivers' centre (largest "
                   f"{d[ok].max():.3g} m; {head})", trial,
                   hint="positions in metres need 'units: m'")
