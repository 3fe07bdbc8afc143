"""Reading C3D files: marker trajectories in metres and seconds, NaN gaps, events.

Part of :mod:`gaitval.io.c3d`, which re-exports :func:`read_c3d` and
:func:`clean_labels`; the conventions (units, gaps, labels, duplicates, first frame,
events) are in that module's notes.  It uses ezc3d [1]_ after the structural checks of
:mod:`gaitval.io.c3d_format`.

References
----------
.. [1] Michaud, B., & Begon, M. (2021). ezc3d: An easy C3D file I/O cross-platform
   solution for C++, Python and MATLAB. Journal of Open Source Software, 6(58), 2911.
.. [2] Motion Lab Systems (2008). The C3D File Format User Guide. https://www.c3d.org
"""
from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.c3d_axes import detect_vertical, to_z_up
from gaitval.io.c3d_format import EVENT_COLUMNS, UNIT_SCALE, _open_ezc3d, _precheck
from gaitval.io.c3d_params import decode_text
from gaitval.types import MocapTrial

# the reader's messages keep the name of the module users import it from
log = logging.getLogger("gaitval.io.c3d")

def _param(c, group: str, name: str, default=None):
    try:
        return c["parameters"][group][name]["value"]
    except KeyError:
        return default


def _text(s) -> str:
    """A text value as ezc3d passes it (bytes that are not UTF-8 as lone surrogates),
    decoded as the parameter check decoded it: UTF-8, else CP-1252, else Latin-1."""
    s = str(s)
    try:
        s.encode("utf-8")
    except UnicodeEncodeError:
        s = decode_text(s.encode("utf-8", "surrogateescape"))
    return s.strip("\x00 \t")


def _strings(value) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [_text(value)]
    return [_text(v) for v in np.asarray(value, dtype=object).ravel()]


def _first_number(value, default=None):
    if value is None:
        return default
    arr = np.asarray(value).ravel()
    return default if arr.size == 0 else arr[0].item()


def _raw_labels(c, n_points: int) -> list[str]:
    labels = _strings(_param(c, "POINT", "LABELS"))
    k = 2
    while _param(c, "POINT", f"LABELS{k}") is not None:
        labels += _strings(_param(c, "POINT", f"LABELS{k}"))
        k += 1
    labels = labels[:n_points]
    labels += [""] * (n_points - len(labels))
    return labels


def clean_labels(raw: list[str], *, duplicates: str = "suffix"
                 ) -> tuple[list[str], dict[str, list[str]], list[str]]:
    """Strip subject prefixes and disambiguate duplicates (see the module docstring).

    Returns
    -------
    labels : list of str
    dups : dict
        Duplicated label -> the labels given to its occurrences (``["RKNE", "RKNE#2"]``).
    prefixes : list of str
        Distinct prefixes stripped (``"Matt:"``), in order of appearance.
    """
    stripped, prefixes = [], []
    for k, lab in enumerate(raw):
        lab = lab.strip()
        if ":" in lab:
            pre, lab = lab.rsplit(":", 1)
            if pre + ":" not in prefixes:
                prefixes.append(pre + ":")
            lab = lab.strip()
        stripped.append(lab or f"POINT{k + 1}")
    counts: dict[str, int] = {}
    for lab in stripped:
        counts[lab] = counts.get(lab, 0) + 1
    dups = {lab: [] for lab, n in counts.items() if n > 1}
    if dups and duplicates == "error":
        raise ValueError(", ".join(f"{lab} x{counts[lab]}" for lab in dups))
    seen: dict[str, int] = {}
    taken = set(stripped)
    out = []
    for lab in stripped:
        seen[lab] = seen.get(lab, 0) + 1
        new = lab
        if seen[lab] > 1:
            k = seen[lab]
            while f"{lab}#{k}" in taken:                 # never collide with a real label
                k += 1
            new = f"{lab}#{k}"
            taken.add(new)
        out.append(new)
        if lab in dups:
            dups[lab].append(new)
    return out, dups, prefixes


def _events(c) -> tuple[pd.DataFrame, str]:
    """Events from the EVENT group, else from the header event block."""
    times = _param(c, "EVENT", "TIMES")
    if times is not None and np.asarray(times).size:
        arr = np.asarray(times, dtype=np.float64)
        if arr.ndim == 1:
            arr = arr.reshape(-1, 2).T      # stored column-major: (minutes, seconds) pairs
        t = 60.0 * arr[0] + arr[1]          # C3D guide: TIMES(1,i) minutes, TIMES(2,i) seconds
        n = len(t)
        used = _first_number(_param(c, "EVENT", "USED"), n)
        n = min(n, int(used))
        ctx = (_strings(_param(c, "EVENT", "CONTEXTS")) + [""] * n)[:n]
        lab = (_strings(_param(c, "EVENT", "LABELS")) + [""] * n)[:n]
        df = pd.DataFrame({"context": ctx, "label": lab, "t_s": t[:n]})
        source = "EVENT"
    else:
        ht = c["header"]["events"]["events_time"]
        hl = c["header"]["events"]["events_label"]
        rows = [("", str(lab).strip(), float(tt)) for tt, lab in zip(ht, hl)
                if str(lab).strip()]
        for k, (_, lab, _) in enumerate(rows):
            try:
                lab.encode("utf-8")
            except UnicodeEncodeError:    # ezc3d passes undecodable bytes as surrogates
                raise ValueError(f"the header's event label {k + 1} is not text") from None
        df = pd.DataFrame(rows, columns=EVENT_COLUMNS)
        source = "header" if rows else "none"
    df = df.astype({"context": object, "label": object, "t_s": np.float64})
    df = df.sort_values("t_s", kind="stable").reset_index(drop=True)
    return df, source


def _first_frame(c) -> tuple[int, int]:
    """(first_frame 1-based, header value 1-based) — see the module docstring."""
    header_ff = int(c["header"]["points"]["first_frame"]) + 1
    start = _param(c, "TRIAL", "ACTUAL_START_FIELD")
    if start is not None and np.asarray(start).size >= 1:
        w = [int(v) & 0xFFFF for v in np.asarray(start).ravel()[:2]] + [0]
        ff = w[0] + 65536 * w[1]
        if ff >= 1:
            return ff, header_ff
    return header_ff, header_ff


def read_c3d(path: str | Path, *, trial: str | None = None, duplicates: str = "suffix",
             vertical: str = "auto") -> MocapTrial:
    """Read the marker trajectories of a C3D file (metres, seconds, NaN gaps).

    Parameters
    ----------
    path : str or Path
    trial : str, optional
        Trial id, named in error messages.
    duplicates : {"suffix", "error"}
        Policy for labels that are equal after prefix stripping: ``suffix`` keeps every
        marker and names later ones ``LABEL#2``, ``LABEL#3`` (listed in
        ``meta["duplicates"]``); ``error`` raises :class:`FileFormatError`.
    vertical : {"auto", "z", "+y", "-y", "+x", "-x", "-z"}
        Which stored axis points up.  ``auto`` reads it from the markers
        (:func:`gaitval.io.c3d_axes.detect_vertical`) and turns a y-up (or x-up) file into
        gaitval's z-up field frame, logging a warning; ``z`` refuses a file whose markers
        say otherwise; an explicit axis is rotated to +z without looking.

    Returns
    -------
    MocapTrial
        ``labels`` (prefix stripped), ``xyz`` (n_frames, n_markers, 3) in metres with NaN
        gaps, ``rate_hz``, ``first_frame`` (1-based), ``events`` (``context, label, t_s``
        on the ``MocapTrial.t`` time base), ``units`` (the file's unit), ``meta`` with
        ``original_labels``, ``prefixes``, ``duplicates``, ``n_zero_gaps``, ``n_analogs``,
        ``analog_rate_hz``, ``events_source``, ``manufacturer``, ``processor``.

    Raises
    ------
    FileFormatError
        Missing, unreadable, truncated or non-standard file; unknown units; duplicate
        labels under ``duplicates="error"``.  The message names the file and the reason.

    Notes
    -----
    The conventions (units, gaps, prefixes, duplicates, first frame, events) are in the
    module docstring and ``docs/formats_recordings.md``.
    """
    path = Path(path)
    if duplicates not in ("suffix", "error"):
        raise ValueError("duplicates must be 'suffix' or 'error'")
    pre = _precheck(path, trial)
    c = _open_ezc3d(path, trial, pre)
    pts = _point_data(c, pre, path, trial)                    # (4, n_points, n_frames)
    units, units_assumed = _units(c, path, trial)
    raw_labels = _raw_labels(c, int(pts.shape[1]))
    labels, dups, prefixes = _labels(raw_labels, duplicates, path, trial)

    res = np.asarray(c["data"]["meta_points"]["residuals"], dtype=np.float64)
    xyz = pts[:3].transpose(2, 1, 0) * UNIT_SCALE[units]        # (n_frames, n_points, 3)
    neg = (res[0].T < 0) if res.size else np.zeros(xyz.shape[:2], dtype=bool)
    zero = np.all(xyz == 0.0, axis=2) & ~neg                     # all-zero coordinates
    gap = neg | zero | ~np.all(np.isfinite(xyz), axis=2)
    xyz[gap] = np.nan
    xyz, up = _vertical(xyz, vertical, path, trial)
    scale_warnings = _scale_problems(xyz, units, units_assumed, up, path, trial)

    rate = _first_number(_param(c, "POINT", "RATE"), None)
    rate = float(rate) if rate else float(c["header"]["points"]["frame_rate"])
    if not (math.isfinite(rate) and rate > 0):
        raise FileFormatError(f"C3D point rate is {rate!r} (POINT:RATE, or the header's "
                              "rate); it must be a finite number > 0", path=path, trial=trial)
    ff, header_ff = _first_frame(c)
    try:
        events, ev_source = _events(c)
    except ValueError as exc:                 # odd EVENT:TIMES, a label that is not text
        raise FileFormatError(f"the events cannot be read: {exc}", path=path,
                              trial=trial) from None
    bad = np.flatnonzero(~np.isfinite(events["t_s"].to_numpy(dtype=np.float64)))
    if bad.size:
        raise FileFormatError(f"event {events['label'].iloc[bad[0]]!r} has time "
                              f"{events['t_s'].iloc[bad[0]]!r} ({ev_source} section); event "
                              "times must be finite", path=path, trial=trial)
    company = " ".join(_strings(_param(c, "MANUFACTURER", "COMPANY")))
    software = " ".join(_strings(_param(c, "MANUFACTURER", "SOFTWARE")))
    meta: dict[str, Any] = {
        "original_labels": raw_labels,
        "prefixes": prefixes,
        "duplicates": dups,
        "n_zero_gaps": int(zero.sum()),
        "units_assumed": units_assumed,
        "n_analogs": int(c["n_analogs"]),
        "analog_rate_hz": float(c["header"]["analogs"]["frame_rate"]),
        "events_source": ev_source,
        "manufacturer": " / ".join(s for s in (company, software) if s),
        "processor": pre["processor"],
        "first_frame_header": header_ff,
        "subjects": _strings(_param(c, "SUBJECTS", "NAMES")),
        "vertical_axis": up,
        # parameters whose text is not UTF-8 -> the encoding it was read with
        "text_encodings": dict(pre.get("encodings", {})),
        # what was logged as a warning while reading (gaitval inspect lists it)
        "warnings": ([f"duplicate marker labels kept with suffixes: "
                      + "; ".join(f"{k} -> {', '.join(v)}" for k, v in dups.items())]
                     if dups else [])
        + ([f"the markers say {up} points up; rotated to gaitval's z-up field frame"]
           if vertical == "auto" and up not in (None, "+z") and not up.startswith("+z")
           else [])
        + (["POINT:UNITS is blank: the coordinates are taken as mm (the C3D default)"]
           if units_assumed else [])
        + scale_warnings,
    }
    return MocapTrial(path=str(path), rate_hz=rate, first_frame=int(ff), labels=labels,
                      xyz=xyz, events=events, units=units, meta=meta)


def _point_data(c, pre: dict, path: Path, trial: str | None) -> np.ndarray:
    """The point array (4, n_points, n_frames); a file with fewer frames than its header
    (or ``POINT:FRAMES``) announces is truncated."""
    pts = np.asarray(c["data"]["points"], dtype=np.float64)   # (4, n_points, n_frames)
    n_frames = int(pts.shape[2])
    # ezc3d shrinks its header to what it could read, so compare with what the raw header
    # words and POINT:FRAMES announce (c3d_format._precheck)
    expected = pre["frames_expected"]          # header words and POINT:FRAMES, any processor
    if n_frames == 0:
        raise FileFormatError("C3D file holds no point frames (empty or truncated)",
                              path=path, trial=trial)
    if pts.shape[1] == 0:
        raise FileFormatError(f"C3D file holds no markers over its {n_frames} frames",
                              path=path, trial=trial)
    if n_frames < expected:
        raise FileFormatError(f"C3D file is truncated: the header announces {expected} "
                              f"frames, the data section holds {n_frames}",
                              path=path, trial=trial)
    return pts


def _vertical(xyz: np.ndarray, vertical: str, path: Path, trial: str | None
              ) -> tuple[np.ndarray, str]:
    """Markers in the z-up field frame, and which stored axis was up (see read_c3d)."""
    if vertical not in ("auto", "z") + tuple(f"{s}{a}" for s in "+-" for a in "xyz"):
        raise ValueError(f"vertical must be 'auto', 'z' or an axis such as '+y', not "
                         f"{vertical!r}")
    if vertical not in ("auto", "z"):
        return (xyz if vertical == "+z" else to_z_up(xyz, vertical)), vertical
    up, _ = detect_vertical(xyz)
    if up is None or up == "+z":
        return xyz, up or "+z (as stored; the markers do not tell)"
    if vertical == "z":
        raise FileFormatError(f"the markers say {up} points up (their heights barely change "
                              "and the body spans it), but gaitval's field frame has +z up",
                              path=path, trial=trial,
                              hint="read it with vertical='auto' (the default), which turns "
                                   "it to z up, or re-export it z-up")
    log.warning("%s: the markers say %s points up; rotated to gaitval's z-up field frame",
                path, up)
    return to_z_up(xyz, up), up


#: A walking subject in a motion-capture volume: the markers' median distance from the
#: origin is metres (a large hall: tens of metres), one frame's markers span under
#: ~2.5 m vertically (a person; a pole).  Past these, the declared unit is wrong.
MAX_MEDIAN_DISTANCE_M = 100.0
MAX_VERTICAL_SPAN_M = 5.0
#: below these, the coordinates are most likely metres declared as mm (a warning: a small
#: calibration object can be this small)
MIN_VERTICAL_SPAN_M = 0.02
MIN_MEDIAN_DISTANCE_M = 0.05


def _scale_problems(xyz: np.ndarray, units: str, units_assumed: bool, up: str,
                    path: Path, trial: str | None) -> list[str]:
    """The marker positions against the declared ``POINT:UNITS``: a file whose markers
    sit kilometres from the origin, or whose body spans tens of metres vertically, has the
    wrong unit (``'m'`` or ``'cm'`` on millimetre data): a FileFormatError naming the unit
    that would fit.  Markers that all sit within millimetres (metres declared as mm): a
    warning (returned, and logged)."""
    ok = np.isfinite(xyz).all(axis=2)
    if ok.sum() < 3:
        return []
    dist = float(np.median(np.linalg.norm(xyz[ok], axis=1)))
    z = np.where(ok, xyz[:, :, 2], np.nan)
    rows = ok.sum(axis=1) >= 2
    span = 0.0
    if rows.any() and not str(up).startswith("+z (as stored"):
        with np.errstate(all="ignore"):
            zz = z[rows]
            span = float(np.median(np.nanmax(zz, axis=1) - np.nanmin(zz, axis=1)))
    declared = f"POINT:UNITS {units!r}" + (" (blank: mm assumed)" if units_assumed else "")
    scale = UNIT_SCALE[units]

    def fitting() -> str:
        ref = span if span > 0 else dist
        good = [u for u, f in UNIT_SCALE.items()
                if u != units and 0.3 <= ref / scale * f <= (2.5 if span > 0 else 20.0)]
        return (f"; the data look like {good[0]} (set POINT:UNITS to {good[0]!r})"
                if good else "")

    if dist > MAX_MEDIAN_DISTANCE_M or span > MAX_VERTICAL_SPAN_M:
        raise FileFormatError(
            f"{declared} puts the markers a median {dist:.4g} m from the origin, one "
            f"frame's markers spanning {span:.4g} m vertically; a walking subject is metres "
            f"from the origin and under 2.5 m tall: the declared unit is wrong{fitting()}",
            path=path, trial=trial)
    if span and span < MIN_VERTICAL_SPAN_M and dist < MIN_MEDIAN_DISTANCE_M:
        msg = (f"{declared}: the markers sit a median {dist * 1000:.3g} mm from the origin "
               f"and one frame's span {span * 1000:.3g} mm vertically, too small for a "
               f"person{fitting()}")
        log.warning("%s: %s", path, msg)
        return [msg]
    return []


def _units(c, path: Path, trial: str | None) -> tuple[str, bool]:
    """``POINT:UNITS`` (mm when absent: (unit, assumed))."""
    units_raw = _strings(_param(c, "POINT", "UNITS"))
    units = units_raw[0].lower() if units_raw and units_raw[0] else ""
    units_assumed = not units
    if units_assumed:
        units = "mm"
    if units not in UNIT_SCALE:
        raise FileFormatError(f"POINT:UNITS is {units_raw[0]!r}; gaitval reads mm, cm or m",
                              path=path, trial=trial)
    return units, units_assumed


def _labels(raw_labels: list[str], duplicates: str, path: Path, trial: str | None
            ) -> tuple[list[str], dict[str, list[str]], list[str]]:
    """:func:`clean_labels` with its errors as FileFormatError and duplicates logged."""
    try:
        labels, dups, prefixes = clean_labels(raw_labels, duplicates=duplicates)
    except ValueError as exc:
        raise FileFormatError(f"duplicate marker labels after prefix stripping: {exc}",
                              path=path, trial=trial,
                              hint="rename them in the capture software, or read with "
                                   "duplicates='suffix'") from None
    if dups:
        log.warning("%s: duplicate marker labels kept with suffixes: %s", path,
                    "; ".join(f"{k} -> {', '.join(v)}" for k, v in dups.items()))
    return labels, dups, prefixes
