"""External tracks and detections through gaitval's exchange formats
(:mod:`gaitval.io.tracks`, docs/formats_external.md "Leg tracks"): export gaitval's own tracks,
import another tracker's as one more method, score a detector's leg detections.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.atomic import write_parquet, write_text
from gaitval.io.parquet import read_parquet
from gaitval.pipeline.steps.config import load_json


def export_tracks_step(track_parquet, out, units: str = "m", topic: str | None = None,
                       legs: dict | None = None) -> Path:
    """One of gaitval's own track files (``results/<study>/track/<method>/<trial>.parquet``)
    in the exchange format (sensor frame and clock), CSV or Parquet by ``out``'s suffix; or
    a tracker's people topic of a ROS bag (``*.bag`` or a ROS 2 bag folder; ``topic``:
    leg_tracker/PersonArray or people_msgs/People, :func:`gaitval.io.tracks.bag.read_bag_tracks`);
    with ``out`` a ``*.foot.csv``/``.parquet``, gaitval's ultrasonic UKF track as a heel
    trajectory (:mod:`gaitval.io.foot`)."""
    from gaitval.io.tracks.bag import read_bag_tracks
    from gaitval.io.tracks.write import track_to_exchange, write_tracks

    src_path = Path(track_parquet)
    if not src_path.exists():
        raise FileFormatError("file not found", path=src_path,
                              hint="a track of gaitval's is results/<study>/track/<method>/"
                                   "<trial>.parquet, made by the report run")
    if src_path.suffix == ".bag" or src_path.is_dir():
        rows, meta = read_bag_tracks(src_path, topic)
        if legs:                  # each leg a person: leg rows (docs/formats_external.md, Leg tracks)
            from gaitval.io.tracks.bag import people_to_legs
            rows = people_to_legs(rows, legs, path=src_path, topic=meta["source"]).rename(
                columns={"x_m": "x", "y_m": "y"})
        if units == "mm":
            rows[["x", "y"]] = rows[["x", "y"]] * 1000.0
        return write_tracks(rows, out, units=units, source=meta["source"])
    track = read_parquet(track_parquet)
    if Path(out).name.endswith((".foot.csv", ".foot.parquet")):
        # gaitval's ultrasonic UKF track (results/<study>/ultrasonic/track/<trial>.parquet)
        # as a heel trajectory (gaitval.io.foot; ultrasonic frame and clock)
        from gaitval.io.foot import ukf_track_to_foot, write_foot
        if not {"t_s", "x_m", "y_m", "z_m"} <= set(track.columns):
            raise FileFormatError("a *.foot.csv/parquet is a heel trajectory: the input "
                                  "is no ultrasonic track (columns t_s, x_m, y_m, z_m)",
                                  path=track_parquet, hint="export a leg track as "
                                  "*.tracks.csv, an ultrasonic track as *.foot.csv")
        rows = ukf_track_to_foot(track)
        if units == "mm":
            rows[["x", "y", "z"]] = rows[["x", "y", "z"]] * 1000.0
        return write_foot(rows, out, units=units, source="gaitval ultrasonic UKF")
    rows = track_to_exchange(track)
    if units == "mm":
        for c in ("x", "y", "vx", "vy"):
            if c in rows:
                rows[c] = rows[c] * 1000.0
    src = {}
    if len(track) and "method" in track and "trial" in track:
        src = {"source": f"gaitval {track['method'].iloc[0]}",
               "trial": str(track["trial"].iloc[0])}
    return write_tracks(rows, out, units=units, **src)


def external_entry(config_json, method: str) -> dict:
    """``tracking.external.<method>`` of a config view (empty without one)."""
    if not config_json:
        return {}
    ext = ((load_json(config_json).get("tracking") or {}).get("external") or {})
    return dict(ext.get(method) or {})


def read_external(tracks_file, entry: dict, trial: str) -> tuple[pd.DataFrame, dict]:
    """An external method's file of one trial as :func:`gaitval.io.tracks.read.read_tracks`
    rows: a ``*.tracks.csv``/``.parquet``, or a ROS bag's tracker topic (``entry``'s
    ``topic``) whose people are the legs named by ``entry``'s ``legs``."""
    from gaitval.io.rosbag import is_rosbag
    from gaitval.io.tracks.bag import people_to_legs, read_bag_tracks
    from gaitval.io.tracks.read import read_tracks

    if not is_rosbag(tracks_file):
        return read_tracks(tracks_file, trial=trial)
    rows, meta = read_bag_tracks(tracks_file, entry.get("topic"), trial=trial)
    legs = entry.get("legs")
    if not legs:
        return rows.rename(columns={"x": "x_m", "y": "y_m"}), meta
    return people_to_legs(rows, legs, path=tracks_file, trial=trial,
                          topic=meta["source"]), meta


def read_external_detections(path, topic: str | None = None, trial: str | None = None
                             ) -> tuple[pd.DataFrame, dict]:
    """A detector's leg detections of one trial: a ROS bag's ``leg_tracker/LegArray``
    topic (:func:`gaitval.io.tracks.bag.read_bag_leg_detections`) or a
    ``*.detections.csv``/``.parquet`` (:func:`gaitval.io.tracks.detections.read_detections`)."""
    from gaitval.io.rosbag import is_rosbag
    from gaitval.io.tracks.bag import read_bag_leg_detections
    from gaitval.io.tracks.detections import read_detections

    if is_rosbag(path):
        return read_bag_leg_detections(path, topic, trial=trial)
    return read_detections(path, trial=trial)


def _refuse_mocap_frame(meta: dict, path, trial, what: str) -> None:
    """A file in the mocap frame on a trial whose laser moves (the rollator): refused with
    one error naming the file and the header field (only a fixed laser's pose converts
    the field frame into the laser's)."""
    if meta.get("frame", "sensor") == "mocap":
        raise FileFormatError(
            "header field 'frame' is 'mocap', but this trial's laser moves (rollator): "
            f"gaitval converts only a fixed laser's {what} from the mocap frame",
            path=path, trial=trial, hint=f"write the {what} in the laser's frame "
            "(frame: sensor)")


def leg_detections_step(detections, groundtruth_parquet, out_dir, *, topic: str | None = None,
                        trial: str | None = None, gate_m: float = 0.30,
                        registration_json=None, sensor_parquet=None,
                        method: str | None = None, protocol: str | None = None,
                        moving_sensor: bool = False) -> dict:
    """A detector's leg detections of one trial (leg_tracker's ``leg_tracker/LegArray``
    in a bag, or a ``*.detections.csv``/``.parquet``; no identity, no side) scored against
    the trial's mocap legs (:func:`gaitval.evaluate.leg_detections.detection_statistics`);
    writes ``per_scan.parquet`` and ``summary.json`` into ``out_dir`` (atomically) and
    returns the summary.  A file on the mocap clock or in the mocap frame is converted with
    the trial's registration (``registration_json``); with the trial's scan log
    (``sensor_parquet``) time stamps outside the recording and positions in the wrong
    units are refused naming the row (:func:`gaitval.io.tracks.sensor.detections_to_sensor`).
    Stamps on the sensor clock must be the scans' (the ground truth's ``t_sensor_s``).
    ``moving_sensor`` (the rollator): a file in the mocap frame is refused, as
    :func:`import_tracks_step` refuses one (the ground truth is in the moving laser's
    frame, scan by scan)."""
    from gaitval.evaluate.leg_detections import detection_statistics
    from gaitval.io.tracks.sensor import detections_to_sensor

    det, meta = read_external_detections(detections, topic, trial)
    if moving_sensor:
        _refuse_mocap_frame(meta, detections, trial, "detections")
    rec = load_json(registration_json) if registration_json else None
    out = Path(out_dir)
    if rec is not None and rec.get("status") != "ok":
        return _not_registered(out, trial, meta, gate_m, method, protocol)
    scan_t, period, rng = _scans_of(sensor_parquet, trial)
    det, t_messages = detections_to_sensor(det, meta, rec, path=detections, trial=trial,
                                           scan_t=scan_t, tolerance_s=period,
                                           max_range_m=rng)
    truth = read_parquet(groundtruth_parquet)
    per_scan, summary = detection_statistics(det, t_messages, truth, gate_m)
    if not summary["n_scans"]:
        raise FileFormatError(f"no time stamp of {meta['source']} is a scan time of the "
                              "ground truth with both legs known (no scan to score)",
                              path=detections, trial=trial, hint="the detections' time "
                              "stamps must be the scans' stamps, on the registered sensor "
                              "clock (or 'clock: mocap' in a detections file's header)")
    summary = {"trial": trial, "source": meta["source"], "status": "ok", **summary}
    summary.update({k: v for k, v in (("method", method), ("protocol", protocol))
                    if v is not None})
    write_parquet(per_scan, out / "per_scan.parquet")
    write_text(out / "summary.json", json.dumps(summary, indent=1, sort_keys=True) + "\n")
    return summary


def _not_registered(out: Path, trial, meta: dict, gate_m: float, method, protocol) -> dict:
    """:func:`leg_detections_step` on a trial whose registration was refused: no mocap legs
    in the laser's frame, nothing to score (the tracking tables count such a trial as not
    registered too); an empty ``per_scan.parquet`` and the summary saying so."""
    summary = {"trial": trial, "source": meta["source"], "status": "not_registered",
               "n_messages": int(meta["n_messages"]), "n_scans": 0, "gate_m": gate_m}
    summary.update({k: v for k, v in (("method", method), ("protocol", protocol))
                    if v is not None})
    write_parquet(pd.DataFrame({"t_sensor_s": pd.Series(dtype=float),
                                "side": pd.Series(dtype=object),
                                "detected": pd.Series(dtype=bool),
                                "dx_m": pd.Series(dtype=float),
                                "dy_m": pd.Series(dtype=float),
                                "n_false": pd.Series(dtype=np.int64)}),
                  out / "per_scan.parquet")
    write_text(out / "summary.json", json.dumps(summary, indent=1, sort_keys=True) + "\n")
    return summary


def _scans_of(sensor_parquet, trial) -> tuple:
    """The scan times, median scan period and laser range of a trial's scan log (None,
    0.0, None without one)."""
    scan_t, period, rng = None, 0.0, None
    if sensor_parquet:
        from gaitval.io.scanlog import read_scanlog
        scans = read_scanlog(sensor_parquet, trial=trial)
        scan_t = np.asarray(scans.t, float)
        period = float(np.median(np.diff(scan_t))) if len(scan_t) > 1 else 0.0
        rng = float(scans.range_max)
    return scan_t, period, rng


def import_tracks_step(tracks_file, sensor_parquet, registration_json, trial: str,
                       method: str, out_parquet, config_json=None,
                       moving_sensor: bool = False) -> pd.DataFrame:
    """An external tracker's file of one trial as gaitval's per-scan track (the columns of
    :func:`gaitval.methods.track_trial`, plus ``trial`` and ``method``), so that the TUG
    evaluation and tables treat it as one more method.  The clock and frame conversion use
    the trial's registration (docs/formats.md); a file on the sensor clock in the sensor
    frame needs none.  A trial whose registration was refused gets an empty track when the
    file needs it (its evaluation is ``not_registered`` anyway).  ``config_json``: the
    method's config view, whose ``tracking.external.<method>`` gives a bag's ``topic``
    and ``legs`` (:func:`read_external`).  ``moving_sensor`` (the rollator): a file in
    the mocap frame is refused (the laser's pose changes every frame; give the tracks in
    the laser's frame)."""
    from gaitval.io.scanlog import read_scanlog
    from gaitval.io.tracks.exchange import TRACK_COLUMNS
    from gaitval.io.tracks.sensor import tracks_to_sensor

    rows, meta = read_external(tracks_file, external_entry(config_json, method), trial)
    if moving_sensor:
        _refuse_mocap_frame(meta, tracks_file, trial, "tracks")
    rec = load_json(registration_json) if registration_json else None
    needs_reg = "mocap" in (meta["frame"], meta["clock"])
    if needs_reg and rec is not None and rec.get("status") != "ok":
        track = pd.DataFrame(columns=list(TRACK_COLUMNS))
    else:
        scans = read_scanlog(sensor_parquet, trial=trial)
        t = np.asarray(scans.t, float)
        period = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
        track = tracks_to_sensor(rows, meta, rec, path=tracks_file, trial=trial,
                                 t_range=(float(t[0]), float(t[-1])), tolerance_s=period,
                                 scan_t=t, max_range_m=float(scans.range_max))
    track.insert(0, "method", method)
    track.insert(0, "trial", trial)
    write_parquet(track, out_parquet)
    return track
