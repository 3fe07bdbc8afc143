"""``gaitval inspect FILE``: what gaitval's loaders see in any supported file.

:func:`describe` returns a JSON-serialisable dict (plain ``str``/``int``/``float``/``bool``/
``list``/``dict``/``None``; NaN becomes ``None``) and :func:`format_description` turns it
into a short human-readable text in the spirit of ``rosbag info``.  The CLI prints one or
the other (``--json``).

Supported files (dispatch on the name):

=============================  =========================================  ===============
file                           reader                                     ``kind``
=============================  =========================================  ===============
``*.c3d``                      :func:`gaitval.io.c3d.read_c3d`            ``c3d``
``*.bag``, ROS 2 bag folder    :func:`gaitval.io.rosbag.read_rosbag_scans` ``rosbag``
``*.scan.parquet``             :func:`gaitval.io.scanlog.read_scanlog`    ``scanlog``
``*.us.parquet``               :func:`gaitval.io.ultrasonic.read_ultrasonic` ``ultrasonic``
``*.annotations.csv``          :func:`gaitval.io.annotations.read_annotations` ``annotations``
=============================  =========================================  ===============
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from gaitval.errors import FileFormatError
from gaitval.io.guard import loader

KINDS = ("c3d", "rosbag", "scanlog", "ultrasonic", "annotations")


def kind_of(path: str | Path) -> str:
    """The file kind by name (see the module table); FileFormatError when unknown."""
    from gaitval.io.rosbag import is_rosbag

    p = Path(path)
    name = p.name.lower()
    try:
        found = p.exists()
    except (OSError, ValueError) as exc:                   # e.g. a name too long
        raise FileFormatError(f"cannot use this path: {getattr(exc, 'strerror', None) or exc}",
                              path=str(path)[:200]) from None
    if not found:
        raise FileFormatError("file not found", path=p)
    if name.endswith(".c3d"):
        return "c3d"
    if is_rosbag(p):
        return "rosbag"
    if name.endswith(".scan.parquet"):
        return "scanlog"
    if name.endswith(".us.parquet"):
        return "ultrasonic"
    if name.endswith(".annotations.csv"):
        return "annotations"
    raise FileFormatError(
        "unknown file kind", path=p,
        hint="gaitval reads *.c3d, *.bag or ROS 2 bag folders, *.scan.parquet, "
             "*.us.parquet and *.annotations.csv; see docs/formats.md")


def _jsonable(x: Any) -> Any:
    """Plain Python types only; NaN/inf become None."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return [_jsonable(v) for v in x.tolist()]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        x = float(x)
        return x if math.isfinite(x) else None
    if x is None or isinstance(x, str):
        return x
    return str(x)


def _describe_scanlog(path: Path) -> dict[str, Any]:
    from gaitval.io.rosbag import scan_summary
    from gaitval.io.scanlog import read_scanlog

    s = read_scanlog(path)
    return {"kind": "scanlog", "path": str(path), "sensor_model": s.sensor_model,
            "mounting_height_m": s.mounting_height_m,
            "range_unit": s.meta.get("range_unit"), **scan_summary(s)}


def _describe_ultrasonic(path: Path) -> dict[str, Any]:
    from gaitval.io.ultrasonic import read_ultrasonic

    u = read_ultrasonic(path)
    data = u.tof_s if u.tof_s is not None else u.distance_m
    issues = u.meta.get("timestamp_issues")
    n = len(u.t)
    return {
        "kind": "ultrasonic", "path": str(path),
        "quantity": "tof" if u.tof_s is not None else "distance",
        "n_samples": n, "rate_hz": u.rate_hz,
        "t_start_s": float(u.t[0]) if n else None,
        "duration_s": float(u.t[-1] - u.t[0]) if n else 0.0,
        "anchors": [{"anchor": str(r.anchor), "x_m": float(r.x_m), "y_m": float(r.y_m),
                     "z_m": float(r.z_m)} for r in u.anchors.itertuples()],
        "no_echo": {a: int(np.isnan(data[:, j]).sum()) for j, a in enumerate(u.anchor_ids)},
        "temperature_c": {"min": float(np.nanmin(u.temperature_c)) if n else None,
                          "mean": float(np.nanmean(u.temperature_c)) if n else None,
                          "max": float(np.nanmax(u.temperature_c)) if n else None},
        "transmitter": u.meta.get("transmitter"), "sensor_model": u.meta.get("sensor_model"),
        "n_timestamp_issues": 0 if issues is None else int(len(issues)),
    }


def _describe_annotations(path: Path) -> dict[str, Any]:
    from gaitval.io.annotations import read_annotations

    ev, meta = read_annotations(path)
    counts = {str(k): int(v) for k, v in ev.groupby("event", sort=True).size().items()}
    by_side = {f"{e}/{s or '-'}": int(v) for (e, s), v in
               ev.groupby(["event", "side"], sort=True).size().items()}
    ts = ev[ev["event"] == "target_step"]
    return {
        "kind": "annotations", "path": str(path), "n_events": int(len(ev)),
        "events": counts, "events_by_side": by_side,
        "target_steps": {str(k): int(v) for k, v in ts.groupby("value").size().items()},
        "raters": sorted({str(r) for r in ev["rater"]}),
        "time_base": meta.get("time_base"), "time_offset_s": meta.get("time_offset_s"),
        "t_first_s": float(ev["t_s"].min()) if len(ev) else None,
        "t_last_s": float(ev["t_s"].max()) if len(ev) else None,
        "header": dict(meta),
    }


@loader("file")
def describe(path: str | Path, *, topic: str | None = None) -> dict[str, Any]:
    """Describe any supported file (see the module table) as a JSON-serialisable dict.

    Parameters
    ----------
    path : str or Path
    topic : str, optional
        For bags: summarise only this LaserScan topic.

    Returns
    -------
    dict
        Always ``kind`` and ``path``; the other keys depend on the kind (see
        :func:`gaitval.io.c3d.describe_c3d`, :func:`gaitval.io.rosbag.describe_rosbag`;
        scan logs: the scan summary keys ``n_scans, n_beams, angle_min_deg, angle_max_deg,
        angle_increment_deg, rate_hz, n_no_return, ...``; ultrasonic: ``n_samples,
        rate_hz, duration_s, anchors, no_echo, temperature_c``; annotations: ``n_events,
        events, events_by_side, target_steps, raters, time_base, time_offset_s``).

    Raises
    ------
    FileFormatError
        Unknown kind, missing file, or whatever the kind's reader raises.
    """
    p = Path(path)
    kind = kind_of(p)
    if kind == "c3d":
        from gaitval.io.c3d import describe_c3d
        d = describe_c3d(p)
    elif kind == "rosbag":
        from gaitval.io.rosbag import describe_rosbag
        d = describe_rosbag(p, topic)
    elif kind == "scanlog":
        d = _describe_scanlog(p)
    elif kind == "ultrasonic":
        d = _describe_ultrasonic(p)
    else:
        d = _describe_annotations(p)
    return _jsonable(d)


# -- text ----------------------------------------------------------------------------------

def _f(x, fmt=".3f", unit="") -> str:
    return "n/a" if x is None else f"{x:{fmt}}{unit}"


def _wrap(words: list[str], width: int = 88, indent: int = 14) -> str:
    lines, cur = [], ""
    for w in words:
        if cur and len(cur) + 1 + len(w) > width - indent:
            lines.append(cur)
            cur = w
        else:
            cur = f"{cur} {w}" if cur else w
    lines.append(cur)
    return ("\n" + " " * indent).join(lines)


def _row(key: str, value: str) -> str:
    return f"{key + ':':<13} {value}"


def _text_scans(s: dict[str, Any]) -> list[str]:
    return [
        _row("scans", f"{s['n_scans']}  ({_f(s['rate_hz'], '.2f', ' Hz')} median, "
             f"{_f(s['duration_s'], '.2f', ' s')})"),
        _row("beams", f"{s['n_beams']}  ({_f(s['angle_min_deg'], '.2f')} .. "
             f"{_f(s['angle_max_deg'], '.2f')} deg, step {_f(s['angle_increment_deg'], '.4f')}"
             " deg)"),
        _row("range", f"valid {_f(s['range_min_m'], '.3f')} .. {_f(s['range_max_m'], '.3f')} m"
             f", observed {_f(s['observed_range_min_m'], '.3f')} .. "
             f"{_f(s['observed_range_max_m'], '.3f')} m"),
        _row("no return", f"{s['n_no_return']} beams "
             f"({100 * (s['no_return_fraction'] or 0):.1f} %) -> NaN"),
        _row("timestamps", "clean" if not s["n_timestamp_issues"] else
             f"{s['n_timestamp_issues']} problems (reported, not reordered): " + ", ".join(
                 f"#{i['index']} {i['problem']}" for i in s["timestamp_issues"][:5])),
    ]


def format_description(d: dict[str, Any]) -> str:
    """Human-readable text of a :func:`describe` dict."""
    kind = d.get("kind")
    out = [_row("path", str(d.get("path"))), _row("kind", str(kind))]
    if kind == "c3d":
        out += [
            _row("rate", f"{_f(d['rate_hz'], 'g')} Hz"),
            _row("frames", f"{d['n_frames']}  (frames {d['first_frame']}..{d['last_frame']}, "
                 f"t = {_f(d['t_start_s'])} .. {_f(d['t_end_s'])} s, "
                 f"{_f(d['duration_s'])} s)"),
            _row("units", ("POINT:UNITS blank: mm assumed (the C3D default) -> m"
                           if d.get("units_assumed") else f"{d['units']} in the file -> m")),
            _row("up", str(d.get("vertical_axis")) + ("" if str(d.get("vertical_axis",
                 "+z")).startswith("+z") else " in the file -> turned to +z")),
            _row("markers", f"{d['n_markers']}: " + _wrap(d["labels"])),
        ]
        if d.get("prefixes"):
            out.append(_row("prefixes", ", ".join(d["prefixes"]) + " (stripped)"))
        if d.get("duplicates"):
            out.append(_row("DUPLICATES", "; ".join(
                f"{k} -> {', '.join(v)}" for k, v in d["duplicates"].items())))
        gaps = d.get("gaps") or {}
        out.append(_row("gaps", f"{len(gaps)} of {d['n_markers']} markers, "
                        f"{100 * (d['gap_fraction'] or 0):.1f} % of samples missing"
                        + (f" ({d['n_zero_gaps']} stored as all-zero)" if d.get("n_zero_gaps")
                           else "")))
        if gaps:
            out.append(" " * 14 + _wrap([f"{k}:{v}" for k, v in gaps.items()]))
        ev = d.get("events") or []
        out.append(_row("events", f"{len(ev)}" + (f" (from the {d['events_source']} section)"
                                                   if ev else "")))
        for e in ev:
            out.append(" " * 14 + f"{e['t_s']:9.3f} s  {e['context']:<8} {e['label']}")
        out.append(_row("analogs", f"{d['n_analogs']} channels at "
                        f"{_f(d['analog_rate_hz'], 'g')} Hz (not read)"))
        if d.get("manufacturer"):
            out.append(_row("written by", d["manufacturer"]))
        enc = d.get("text_encodings") or {}
        out.append(_row("text", "UTF-8" if not enc else "UTF-8, except " + ", ".join(
            f"{k} {v}" for k, v in enc.items())))
    elif kind == "rosbag":
        out += [_row("ROS version", str(d["ros_version"])),
                _row("duration", _f(d["duration_s"], ".2f", " s")),
                _row("topics", "")]
        for t in d["topics"]:
            out.append(f"  {t['topic']:<30} {t['count']:>7} msgs : {t['msgtype']}")
        for name, s in d["scans"].items():
            out.append(f"LaserScan topic {name} (frame {s['frame_id']}, time from "
                       f"{s['time_source']})")
            out += ["  " + line for line in _text_scans(s)]
    elif kind == "scanlog":
        out += [_row("sensor", f"{d['sensor_model']}, scan plane at "
                     f"{_f(d['mounting_height_m'], '.3f', ' m')}"),
                _row("stored in", str(d["range_unit"]))]
        out += _text_scans(d)
    elif kind == "ultrasonic":
        out += [
            _row("quantity", d["quantity"]),
            _row("samples", f"{d['n_samples']}  ({_f(d['rate_hz'], '.2f', ' Hz')}, "
                 f"{_f(d['duration_s'], '.2f', ' s')})"),
            _row("temperature", f"{_f(d['temperature_c']['min'], '.1f')} .. "
                 f"{_f(d['temperature_c']['max'], '.1f')} degC"),
            _row("anchors", str(len(d["anchors"]))),
        ]
        for a in d["anchors"]:
            out.append(f"  {a['anchor']:<8} ({a['x_m']:.3f}, {a['y_m']:.3f}, {a['z_m']:.3f}) m"
                       f"  no echo: {d['no_echo'].get(a['anchor'], 0)}")
        out.append(_row("timestamps", "clean" if not d["n_timestamp_issues"] else
                        f"{d['n_timestamp_issues']} problems (reported, not reordered)"))
    elif kind == "annotations":
        out += [
            _row("events", f"{d['n_events']}: " + ", ".join(
                f"{k} {v}" for k, v in d["events"].items())),
            _row("by side", ", ".join(f"{k} {v}" for k, v in d["events_by_side"].items())),
            _row("time base", f"{d['time_base']} (offset to mocap {d['time_offset_s']} s)"),
            _row("raters", ", ".join(d["raters"])),
        ]
        if d["target_steps"]:
            out.append(_row("target steps", ", ".join(
                f"{k} {v}" for k, v in d["target_steps"].items())))
    else:
        out += [_row(str(k), str(v)) for k, v in d.items()
                if k not in ("kind", "path", "warnings")]
    warns = list(d.get("warnings") or [])
    for s in (d.get("scans") or {}).values():
        warns += [w for w in s.get("warnings") or [] if w not in warns]
    out.append(_row("warnings", "none" if not warns else str(len(warns))))
    out += [f"  WARNING: {w}" for w in warns]
    return "\n".join(out) + "\n"
