"""C3D motion-capture files (VICON and others): reader, writer and description.

This module and its three parts are the only code in gaitval that knows the C3D format;
they use ezc3d [1]_.  Everything read is in metres and seconds
(:class:`~gaitval.types.MocapTrial`).  The reader is :mod:`gaitval.io.c3d_read`, the
writer :mod:`gaitval.io.c3d_write`, the format's constants and the checks made before
ezc3d opens a file :mod:`gaitval.io.c3d_format` (header, data size) and
:mod:`gaitval.io.c3d_params` (parameter section); ezc3d itself runs in a child process
(:mod:`gaitval.io.isolate`), so a file that crashes it is an error, not a crash of
gaitval.  Their public names are re-exported here,
so ``from gaitval.io.c3d import read_c3d, write_c3d`` is the way to use them.

Conventions (also in ``docs/formats_recordings.md``)
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

from pathlib import Path
from typing import Any

import numpy as np

from gaitval.io.c3d_format import EVENT_COLUMNS, UNIT_SCALE
from gaitval.io.c3d_read import clean_labels, read_c3d
from gaitval.io.c3d_write import write_c3d

__all__ = ["EVENT_COLUMNS", "UNIT_SCALE", "clean_labels", "describe_c3d", "read_c3d",
           "write_c3d"]


def describe_c3d(path: str | Path, *, trial: str | None = None) -> dict[str, Any]:
    """What :func:`read_c3d` sees in a file, as a JSON-serialisable dict (for ``inspect``).

    Keys: ``kind`` ("c3d"), ``path``, ``labels``, ``n_markers``, ``rate_hz``, ``n_frames``,
    ``first_frame``, ``last_frame``, ``t_start_s``, ``t_end_s``, ``duration_s``, ``units``,
    ``gaps`` (label -> number of frames missing, only markers with gaps),
    ``gap_fraction`` (missing samples / all samples), ``events`` (list of
    ``{context, label, t_s}``), ``prefixes``, ``prefix_stripped`` (bool),
    ``duplicates``, ``n_zero_gaps``, ``n_analogs``, ``analog_rate_hz``, ``manufacturer``,
    ``vertical_axis`` (the stored axis that points up; see :mod:`gaitval.io.c3d_axes`),
    ``text_encodings`` (parameter -> encoding, for text that is not UTF-8), ``warnings``
    (what the reader logged as a warning).
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
        "units_assumed": bool(tr.meta.get("units_assumed")),
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
        "vertical_axis": tr.meta["vertical_axis"],
        "text_encodings": dict(tr.meta.get("text_encodings", {})),
        "warnings": list(tr.meta.get("warnings", [])),
    }
