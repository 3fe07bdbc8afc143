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


# -- reading -------------------------------------------------------------------------------

_PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS (SGI)"}


def _precheck(path: Path, trial: str | None) -> dict[str, Any]:
    """Check the file exists and looks like a C3D file before ezc3d sees it.

    Returns the processor type and the header's first/last frame words (Intel files).  Raises FileFormatError for a missing file, a file that is
    not C3D, or a processor type ezc3d cannot read (MIPS/SGI big-endian files).
    """
    if not path.is_file():
        raise FileFormatError("C3D file not found", path=path, trial=trial)
    with open(path, "rb") as fh:
        head = fh.read(512)
        if len(head) < 512 or head[1] != 0x50:
            raise FileFormatError("not a C3D file (the header's second byte is not 0x50)",
                                  path=path, trial=trial)
        param_block = head[0]
        fh.seek(max(param_block - 1, 0) * 512)
        phead = fh.read(4)
    if len(phead) < 4:
        raise FileFormatError(f"C3D file is truncated: the parameter section (block "
                              f"{param_block}) lies beyond the end of the file",
                              path=path, trial=trial)
    proc = _PROCESSORS.get(phead[3])
    if proc is None:
        raise FileFormatError(f"unknown C3D processor type {phead[3]} (expected 84 Intel, "
                              "85 DEC or 86 MIPS)", path=path, trial=trial)
    if proc.startswith("MIPS"):
        raise FileFormatError("C3D file uses the MIPS (SGI) big-endian processor format, "
                              "which ezc3d cannot read", path=path, trial=trial,
                              hint="convert it to Intel format, e.g. by opening and saving "
                                   "it in Mokka or Vicon Nexus")
    problem = _walk_parameters(path)
    if problem:
        raise FileFormatError(f"the C3D parameter section is corrupt: {problem}",
                              path=path, trial=trial,
                              hint="re-export the file from the capture software")
    # header words 4 and 5 (1-based, 16-bit): first and last frame of the 3-D data
    first_w, last_w = (int.from_bytes(head[i:i + 2], "little") for i in (6, 8))
    return {"processor": proc, "first_frame_word": first_w, "last_frame_word": last_w}


def _walk_parameters(path: Path) -> str | None:
    """Walk the parameter section's linked list; return the first structural problem.

    C3D User Guide: each group/parameter record is ``name length (int8, negative = locked),
    id (int8, negative = group), name, offset to the next record (int16)``; a parameter
    then has ``type (int8), n_dims (uint8), dims, data``.  ezc3d 1.7.2 spends tens of
    seconds (or crashes) on some corrupt sections, so gaitval checks the chain first:
    printable names, pointers that stay inside the file, data that fits before the next
    record.  Little-endian (Intel/DEC) files only; returns None when the chain is sound.
    """
    b = path.read_bytes()
    i = (b[0] - 1) * 512 + 4
    last = "the section start"
    groups: dict[int, str] = {}
    for _ in range(100_000):
        if i + 2 > len(b):
            return f"the record after {last} lies beyond the end of the file"
        nch = int.from_bytes(b[i:i + 1], "little", signed=True)
        gid = int.from_bytes(b[i + 1:i + 2], "little", signed=True)
        if nch == 0 or gid == 0:
            return None                                   # end of the parameter section
        name = b[i + 2:i + 2 + abs(nch)]
        if len(name) < abs(nch) or not all(0x20 <= c <= 0x7E for c in name):
            return f"the record after {last} has an unreadable name {name!r}"
        p = i + 2 + abs(nch)
        nxt = int.from_bytes(b[p:p + 2], "little", signed=True)
        label = name.decode("ascii")
        if gid < 0:
            groups[-gid] = label
        else:
            label = f"{groups.get(gid, f'group {gid}')}:{label}"
            t = int.from_bytes(b[p + 2:p + 3], "little", signed=True)
            nd = b[p + 3] if p + 3 < len(b) else 0
            size = abs(t)
            for d in b[p + 4:p + 4 + nd]:
                size *= d
            end = p + 4 + nd + size
            if nxt > 0 and end > p + nxt:
                return (f"parameter {label} holds {size} bytes of data, "
                        f"more than the {nxt - 4 - nd} bytes before the next record "
                        "(bad parameter offset)")
        if nxt == 0:
            return None                                   # last record
        if nxt < 0 or p + nxt >= len(b):
            return f"record {label} points to the next record at offset {nxt}, outside the file"
        last = f"{'group' if gid < 0 else 'parameter'} {label}"
        i = p + nxt
    return "the parameter section does not end"


def _ezc3d_reason(exc: Exception) -> str:
    """Turn an ezc3d exception into one sentence a user can act on."""
    msg = str(exc).replace(": iostream error", "").strip()
    low = msg.lower()
    if "format is not standard" in low:
        return ("the parameter section does not follow the C3D standard (ezc3d: non-standard "
                "format); re-export the file from the capture software")
    if "offset parameter is not an int" in low:
        return ("the ANALOG:OFFSET parameter is not of type INT, as the C3D standard requires "
                "(ezc3d: OFFSET parameter is not an INT)")
    if "processor type not supported" in low:
        return f"unsupported processor type (ezc3d: {msg})"
    if "valid c3d" in low:
        return "not a valid C3D file (ezc3d cannot parse the header)"
    return f"ezc3d cannot read it: {type(exc).__name__}: {msg}"


def _open_ezc3d(path: Path, trial: str | None):
    """ezc3d.c3d(path) with every failure turned into one FileFormatError.

    ``ignore_bad_formatting`` is deliberately never used: with ezc3d 1.7.2 it crashes the
    interpreter (segmentation fault) on ``c3dorg_sample18_bad_parameter_section.c3d``.
    """
    import ezc3d

    try:
        return ezc3d.c3d(str(path))
    except Exception as exc:  # ezc3d raises OSError, RuntimeError, ValueError, IndexError
        raise FileFormatError(_ezc3d_reason(exc), path=path, trial=trial) from None


def _param(c, group: str, name: str, default=None):
    try:
        return c["parameters"][group][name]["value"]
    except KeyError:
        return default


def _strings(value) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [value.strip("\x00 \t")]
    return [str(v).strip("\x00 \t") for v in np.asarray(value, dtype=object).ravel()]


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


def read_c3d(path: str | Path, *, trial: str | None = None, duplicates: str = "suffix"
             ) -> MocapTrial:
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
    module docstring and ``docs/formats.md``.
    """
    path = Path(path)
    if duplicates not in ("suffix", "error"):
        raise ValueError("duplicates must be 'suffix' or 'error'")
    pre = _precheck(path, trial)
    c = _open_ezc3d(path, trial)

    pts = np.asarray(c["data"]["points"], dtype=np.float64)   # (4, n_points, n_frames)
    n_points, n_frames = int(pts.shape[1]), int(pts.shape[2])
    hdr = c["header"]["points"]
    # ezc3d shrinks its header to what it could read, so compare with the raw header
    # words (meaningful below 65535 frames) and POINT:FRAMES
    expected = 0
    if pre["processor"] == "Intel" and 0 < pre["last_frame_word"] < 65535:
        expected = pre["last_frame_word"] - pre["first_frame_word"] + 1
    p_frames = _first_number(_param(c, "POINT", "FRAMES"), 0)
    if p_frames and 0 < int(p_frames) < 65535:
        expected = max(expected, int(p_frames))
    if n_frames == 0:
        raise FileFormatError("C3D file holds no point frames (empty or truncated)",
                              path=path, trial=trial)
    if n_frames < expected:
        raise FileFormatError(f"C3D file is truncated: the header announces {expected} "
                              f"frames, the data section holds {n_frames}",
                              path=path, trial=trial)

    units_raw = _strings(_param(c, "POINT", "UNITS"))
    units = units_raw[0].lower() if units_raw and units_raw[0] else ""
    units_assumed = not units
    if units_assumed:
        units = "mm"
    if units not in UNIT_SCALE:
        raise FileFormatError(f"POINT:UNITS is {units_raw[0]!r}; gaitval reads mm, cm or m",
                              path=path, trial=trial)

    raw_labels = _raw_labels(c, n_points)
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

    res = np.asarray(c["data"]["meta_points"]["residuals"], dtype=np.float64)
    xyz = pts[:3].transpose(2, 1, 0) * UNIT_SCALE[units]        # (n_frames, n_points, 3)
    neg = (res[0].T < 0) if res.size else np.zeros(xyz.shape[:2], dtype=bool)
    zero = np.all(xyz == 0.0, axis=2) & ~neg                     # all-zero coordinates
    gap = neg | zero | ~np.all(np.isfinite(xyz), axis=2)
    xyz[gap] = np.nan

    rate = _first_number(_param(c, "POINT", "RATE"), None)
    rate = float(rate) if rate else float(hdr["frame_rate"])
    if not rate > 0:
        raise FileFormatError("C3D point rate is zero", path=path, trial=trial)
    ff, header_ff = _first_frame(c)
    events, ev_source = _events(c)
    company = " ".join(_strings(_param(c, "MANUFACTURER", "COMPANY")))
    software = " ".join(_strings(_param(c, "MANUFACTURER", "SOFTWARE")))
    meta: dict[str, Any] = {
        "original_labels": raw_labels,
        "prefixes": prefixes,
        "duplicates": dups,
        "n_zero_gaps": int(zero.sum()),
        "units_assumed": units_assumed,
        "n_analogs": int(c["data"]["analogs"].shape[1]),
        "analog_rate_hz": float(c["header"]["analogs"]["frame_rate"]),
        "events_source": ev_source,
        "manufacturer": " / ".join(s for s in (company, software) if s),
        "processor": pre["processor"],
        "first_frame_header": header_ff,
        "subjects": _strings(_param(c, "SUBJECTS", "NAMES")),
    }
    return MocapTrial(path=str(path), rate_hz=rate, first_frame=int(ff), labels=labels,
                      xyz=xyz, events=events, units=units, meta=meta)


def describe_c3d(path: str | Path, *, trial: str | None = None) -> dict[str, Any]:
    """What :func:`read_c3d` sees in a file, as a JSON-serialisable dict (for ``inspect``).

    Keys: ``kind`` ("c3d"), ``path``, ``labels``, ``n_markers``, ``rate_hz``, ``n_frames``,
    ``first_frame``, ``last_frame``, ``t_start_s``, ``t_end_s``, ``duration_s``, ``units``,
    ``gaps`` (label -> number of frames missing, only markers with gaps),
    ``gap_fraction`` (missing samples / all samples), ``events`` (list of
    ``{context, label, t_s}``), ``prefixes``, ``prefix_stripped`` (bool),
    ``duplicates``, ``n_zero_gaps``, ``n_analogs``, ``analog_rate_hz``, ``manufacturer``.
    """
    tr = read_c3d(path, trial=trial)
    miss = np.isnan(tr.xyz[:, :, 0])
    counts = miss.sum(axis=0)
    n = tr.n_frames
    t = tr.t
    return {
        "kind": "c3d",
        "path": str(path),
        "labels": list(tr.labels),
        "n_markers": len(tr.labels),
        "rate_hz": float(tr.rate_hz),
        "n_frames": int(n),
        "first_frame": int(tr.first_frame),
        "last_frame": int(tr.first_frame + n - 1),
        "t_start_s": float(t[0]),
        "t_end_s": float(t[-1]),
        "duration_s": float(n / tr.rate_hz),
        "units": tr.units,
        "gaps": {lab: int(k) for lab, k in zip(tr.labels, counts) if k},
        "gap_fraction": float(miss.mean()) if miss.size else 0.0,
        "events": [{"context": str(r.context), "label": str(r.label),
                    "t_s": round(float(r.t_s), 6)} for r in tr.events.itertuples()],
        "events_source": tr.meta["events_source"],
        "prefixes": list(tr.meta["prefixes"]),
        "prefix_stripped": bool(tr.meta["prefixes"]),
        "duplicates": {k: list(v) for k, v in tr.meta["duplicates"].items()},
        "n_zero_gaps": int(tr.meta["n_zero_gaps"]),
        "n_analogs": int(tr.meta["n_analogs"]),
        "analog_rate_hz": float(tr.meta["analog_rate_hz"]),
        "manufacturer": tr.meta["manufacturer"],
    }
