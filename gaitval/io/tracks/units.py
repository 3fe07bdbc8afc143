"""Plausibility of positions once in the laser's frame: none beyond the laser's range, not all
at its origin (positions in millimetres declared as metres, the reverse, or another frame),
each error naming the row as the file names it.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.io.tracks.exchange import _err


def _where(rows: pd.DataFrame, meta: dict, i: int, field: str) -> str:
    """Row ``i`` of :func:`~gaitval.io.tracks.read.read_tracks` /
    :func:`~gaitval.io.tracks.bag.people_to_legs` rows, as the file names it: a CSV line, a
    Parquet data row, or a bag topic's message (``msg``), with the field."""
    if "msg" in rows and np.isfinite(rows["msg"].iloc[i]):
        f = {"t_s": "header.stamp", "x": "position.x", "y": "position.y"}.get(field, field)
        return f"{meta.get('source', 'topic')}, message {int(rows['msg'].iloc[i])}, field {f}"
    kind, first = meta.get("_row", ("data row", 1))
    return f"{kind} {first + i}, column {field!r}"


#: a leg farther from the laser than its range by this much is no leg it saw (m)
RANGE_MARGIN_M = 1.0
#: every position closer to the laser than this: not in metres (m)
MIN_DISTANCE_M = 0.05


def _check_distances(rows, meta, x, y, max_range_m, path, trial) -> None:
    """Positions (sensor frame, metres) the laser can have seen: none beyond its range,
    not all at its origin (wrong ``units``, or ``frame``)."""
    d = np.hypot(x, y)
    ok = np.isfinite(d)
    if not ok.any():
        return
    head = f"header units {meta['units']!r}, frame {meta['frame']!r}"
    far = ok & (d > max_range_m + RANGE_MARGIN_M)
    if np.median(d[ok]) > max_range_m + RANGE_MARGIN_M:   # most, not one diverged track
        i = int(np.flatnonzero(far)[0])
        raise _err(path, f"{_where(rows, meta, i, 'x')}: position "
                   f"({rows['x_m'].iloc[i]:.6g}, {rows['y_m'].iloc[i]:.6g}) m is "
                   f"{d[i]:.1f} m from the laser, beyond its range ({max_range_m:g} m), "
                   f"as are {far.sum()} of {ok.sum()} positions ({head})", trial,
                   hint="positions in millimetres need 'units: mm'; positions in the "
                        "mocap field need 'frame: mocap'")
    if d[ok].max() < MIN_DISTANCE_M:
        i = int(np.flatnonzero(ok)[0])
        raise _err(path, f"{_where(rows, meta, i, 'x')}: every position lies within "
                   f"{MIN_DISTANCE_M * 100:g} cm of the laser (largest {d[ok].max():.3g} m; "
                   f"{head})", trial, hint="positions in metres need 'units: m'")


def _check_detection_distances(det, meta, x, y, max_range_m, path, trial) -> None:
    """As :func:`_check_distances` for tracks: most detections beyond the laser's range
    (+ :data:`RANGE_MARGIN_M`), or all within :data:`MIN_DISTANCE_M` of it, are wrong
    units or frame; the error names the first such detection's line (file) or message
    (bag)."""
    d = np.hypot(x, y)
    head = f"header units {meta.get('units', 'm')!r}, frame {meta.get('frame', 'sensor')!r}"

    def at(i):
        if "_row" in det:
            return f"{meta.get('_row', ('line', 0))[0]} {int(det['_row'].iloc[i])}"
        return f"{meta.get('source', 'topic')}, message {int(det['msg'].iloc[i])}"

    far = d > max_range_m + RANGE_MARGIN_M
    if np.median(d) > max_range_m + RANGE_MARGIN_M:
        i = int(np.flatnonzero(far)[0])
        raise _err(path, f"{at(i)}: detection ({x[i]:.6g}, {y[i]:.6g}) m (laser frame) is "
                   f"{d[i]:.1f} m from the laser, beyond its range ({max_range_m:g} m), as "
                   f"are {int(far.sum())} of {len(d)} detections ({head})", trial,
                   hint="positions in millimetres need 'units: mm'; positions in the "
                        "mocap field need 'frame: mocap'")
    if d.max() < MIN_DISTANCE_M:
        raise _err(path, f"{at(0)}: every detection lies within {MIN_DISTANCE_M * 100:g} cm "
                   f"of the laser (largest {d.max():.3g} m; {head})", trial,
                   hint="positions in metres need 'units: m'")
