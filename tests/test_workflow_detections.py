"""Issue 37: external leg *detectors* in the workflow and the report.  A study declares
them under ``external_detections:`` (study.yaml, or the external.yaml gaitval never
writes); rule ``leg_detections`` scores each trial against the registered mocap legs and
``detections_table`` pools them.  Here two detectors are made from the tiny study's own
ground truth with known misses, noise and false detections -- a leg_tracker LegArray bag
(laser frame, sensor clock) and a *.detections.csv in the mocap frame on the mocap clock
(so the registration's conversion is exercised) -- and the table must give back what was
put in.  An edited entry reruns its own job and the table only (dry runs), and a bad
declaration stops the run at start with one gaitval error naming the file and field."""
from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from conftest import ROOT, SNAKEMAKE
from test_io_tracks_bag import DEFS

#: what the synthetic detectors do, per scored scan and leg
P_DETECT, SIGMA_M, P_FALSE = 0.8, 0.02, 0.1
TABLE = "reports/tiny/tables/detections_table.csv"


def _draw(truth: pd.DataFrame, seed: int) -> tuple[pd.DataFrame, dict]:
    """Per scan of ``truth`` with both legs valid: each leg detected with P_DETECT at its
    position + N(0, SIGMA_M) per axis, and with P_FALSE one false detection 1.5 m beyond
    the left leg (never within the 0.30 m gate of a leg); scans with no detection are kept
    (empty x, y).  Returns the rows (sensor frame and clock) and what was drawn."""
    rng = np.random.default_rng(seed)
    tr = truth[truth["valid"].to_numpy(bool)]
    rows, hits, errs, n_false, n_scans = [], [], [], 0, 0
    for t, g in tr.groupby("t_sensor_s"):
        g = g.set_index("side")
        if not {"L", "R"} <= set(g.index):
            continue
        n_scans += 1
        dets = []
        for side in ("L", "R"):
            x, y = float(g.loc[side, "xs_m"]), float(g.loc[side, "ys_m"])
            hit = rng.random() < P_DETECT
            noise = rng.normal(0.0, SIGMA_M, 2)
            if hit:
                dets.append((x + noise[0], y + noise[1]))
                errs.append(noise)
            hits.append(hit)
        if rng.random() < P_FALSE:
            dets.append((float(g.loc["L", "xs_m"]) + 1.5, float(g.loc["L", "ys_m"])))
            n_false += 1
        rows += [(t, x, y) for x, y in dets] or [(t, np.nan, np.nan)]
    e = np.array(errs)
    return (pd.DataFrame(rows, columns=["t_s", "x", "y"]),
            {"hits": int(np.sum(hits)), "legs": len(hits), "n_scans": n_scans,
             "n_false": n_false, "rmse_x": float(np.sqrt(np.mean(e[:, 0] ** 2))),
             "rmse_y": float(np.sqrt(np.mean(e[:, 1] ** 2)))})


def legarray_bag(path: Path, rows: pd.DataFrame, scan_t) -> Path:
    """A ROS 1 bag as leg_tracker records it: one LaserScan (the laser's frame, for the
    reader's frame check) and /detected_leg_clusters (leg_tracker/LegArray) per scan time
    of ``rows``, header stamps integer s + ns."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types = {}
    for name in ("leg_tracker/msg/Leg", "leg_tracker/msg/LegArray"):
        types.update(get_types_from_msg(DEFS[name], name))
    store.register(types)
    T = store.types

    def header(k, t):
        sec = int(math.floor(t))
        return T["std_msgs/msg/Header"](seq=k, stamp=T["builtin_interfaces/msg/Time"](
            sec=sec, nanosec=int(round((t - sec) * 1e9))), frame_id="laser")

    path.parent.mkdir(parents=True, exist_ok=True)
    with Writer(path) as w:
        cs = w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=store)
        cl = w.add_connection("/detected_leg_clusters", "leg_tracker/msg/LegArray",
                              typestore=store)
        scan = T["sensor_msgs/msg/LaserScan"](
            header=header(0, float(scan_t[0])), angle_min=-1.0, angle_max=1.0,
            angle_increment=1.0, time_increment=0.0, scan_time=0.025, range_min=0.1,
            range_max=30.0, ranges=np.array([1.0, 2.0, 3.0], np.float32),
            intensities=np.array([], np.float32))
        w.write(cs, 10**9, store.serialize_ros1(scan, "sensor_msgs/msg/LaserScan"))
        for k, (t, g) in enumerate(rows.groupby("t_s")):
            legs = [T["leg_tracker/msg/Leg"](position=T["geometry_msgs/msg/Point"](
                x=float(x), y=float(y), z=0.0), confidence=0.9)
                for x, y in zip(g["x"], g["y"]) if np.isfinite(x)]
            w.write(cl, 10**9 + (k + 1) * 1000, store.serialize_ros1(
                T["leg_tracker/msg/LegArray"](header=header(k, float(t)), legs=legs),
                "leg_tracker/msg/LegArray"))
    return path


def to_mocap(rows: pd.DataFrame, reg: dict) -> pd.DataFrame:
    """Sensor-frame, sensor-clock rows in the mocap field and on the mocap clock (the
    inverse of docs/formats_external.md's conversion)."""
    c, s = math.cos(reg["yaw_rad"]), math.sin(reg["yaw_rad"])
    drift = 1.0 + float(reg.get("clock_drift_ppm") or 0.0) * 1e-6
    return pd.DataFrame({"t_s": (rows["t_s"] - reg["clock_offset_s"]) / drift,
                         "x": c * rows["x"] - s * rows["y"] + reg["x_m"],
                         "y": s * rows["x"] + c * rows["y"] + reg["y_m"]})


def dry_run(work: Path) -> dict[str, set[str]]:
    """rule -> the detector wildcard of each job a dry run of TABLE would run."""
    from conftest import planned_jobs

    return planned_jobs(work, [TABLE], ("detector",))


@pytest.fixture(scope="module")
def det_run(tiny_run, tmp_path_factory):
    """A copy of the tiny data with two detectors of its TUG trials: ``det_bag`` in
    study.yaml (LegArray bags) and ``det_csv`` in external.yaml (mocap frame and clock);
    the detection table run for real once.  Returns (folder, what was drawn per
    detector)."""
    from conftest import copy_run, tiny_workflow
    from gaitval.io.tracks.detections import write_detections

    work = tmp_path_factory.mktemp("det_run")
    copy_run(tiny_run, work)
    study, done = work / "data" / "tiny", tiny_run / "results" / "tiny"
    trials = sorted(p.name for p in (done / "register" / "tug").iterdir()
                    if (p / "groundtruth.parquet").is_file())
    assert trials
    drawn = {"det_bag": [], "det_csv": []}
    for i, t in enumerate(trials):
        truth = pd.read_parquet(done / "register" / "tug" / t / "groundtruth.parquet")
        reg = json.loads((done / "register" / "tug" / t / "registration.json").read_text())
        assert reg["status"] == "ok"
        rows, d = _draw(truth, seed=100 + i)
        legarray_bag(study / "det" / f"{t}.bag", rows, truth["t_sensor_s"].to_numpy())
        drawn["det_bag"].append(d)
        rows, d = _draw(truth, seed=200 + i)
        write_detections(to_mocap(rows, reg), study / "det" / f"{t}.detections.csv",
                         frame="mocap", clock="mocap", source="synthetic")
        drawn["det_csv"].append(d)
    rollator = sorted(p.name for p in (done / "register" / "rollator").iterdir()
                      if (p / "groundtruth.parquet").is_file())
    assert rollator
    drawn["det_rollator"] = []
    for i, t in enumerate(rollator):       # the moving laser's frame, the mocap clock
        truth = pd.read_parquet(done / "register" / "rollator" / t / "groundtruth.parquet")
        reg = json.loads((done / "register" / "rollator" / t / "registration.json")
                         .read_text())
        assert reg["status"] == "ok"
        rows, d = _draw(truth, seed=300 + i)
        drift = 1.0 + float(reg.get("clock_drift_ppm") or 0.0) * 1e-6
        rows["t_s"] = (rows["t_s"] - reg["clock_offset_s"]) / drift
        write_detections(rows, study / "detr" / f"{t}.detections.csv", clock="mocap")
        drawn["det_rollator"].append(d)
    cal = study / "study.yaml"
    doc = yaml.safe_load(cal.read_text()) or {}
    doc["external_detections"] = {"det_bag": {"path": "det/{trial}.bag",
                                              "topic": "/detected_leg_clusters",
                                              "protocols": ["tug"]}}
    cal.write_text(yaml.safe_dump(doc))
    (study / "external.yaml").write_text(yaml.safe_dump({"external_detections": {
        "det_csv": {"path": "det/{trial}.detections.csv", "protocols": ["tug"]},
        "det_rollator": {"path": "detr/{trial}.detections.csv",
                         "protocols": ["rollator"]}}}))
    res = tiny_workflow(work, targets=[TABLE])
    assert res.returncode == 0, res.stderr[-4000:]
    return work, drawn


@pytest.mark.slow
def test_the_table_gives_back_the_detectors_known_rates_and_noise(det_run):
    work, drawn = det_run
    table = pd.read_csv(work / TABLE).set_index("method")
    assert list(table.index) == ["det_bag", "det_csv", "det_rollator"]
    for m, ds in drawn.items():
        row = table.loc[m]
        legs, hits = sum(d["legs"] for d in ds), sum(d["hits"] for d in ds)
        n_scans = sum(d["n_scans"] for d in ds)
        assert row["protocol"] == ("rollator" if m == "det_rollator" else "tug")
        assert row["n_trials"] == len(ds)
        assert row["n_scans"] == n_scans and row["n_not_registered"] == 0
        # every drawn detection found, every false one counted: what was drawn (to the
        # CSV's 6 significant digits)
        assert row["detection_rate"] == pytest.approx(hits / legs, abs=1e-6)
        assert row["false_per_scan"] == pytest.approx(sum(d["n_false"] for d in ds) / n_scans,
                                                      abs=1e-6)
        # and close to the nominal values (binomial SE about 0.01 for ~2000 legs)
        assert abs(row["detection_rate"] - P_DETECT) < 0.04
        assert abs(row["left_detection_rate"] - P_DETECT) < 0.05
        assert abs(row["false_per_scan"] - P_FALSE) < 0.04
        # RMSE: the drawn noise (legs closer than a few noise SDs may swap their
        # detections in the assignment, which can only lower the sum of distances)
        want_x = math.sqrt(sum(d["rmse_x"] ** 2 * d["hits"] for d in ds) / hits)
        assert row["rmse_x_m"] == pytest.approx(want_x, rel=0.03)
        assert row["rmse_x_m"] == pytest.approx(SIGMA_M, rel=0.1)
        assert row["rmse_y_m"] == pytest.approx(SIGMA_M, rel=0.1)
    md = (work / TABLE).with_suffix(".md").read_text()
    assert "no row in the tracking tables" in md
    tex = (work / TABLE).with_suffix(".tex").read_text()
    assert "\\toprule" in tex and "det\\_csv" in tex


@pytest.mark.slow
def test_an_edited_detector_entry_reruns_its_job_and_the_table_only(det_run):
    work, _ = det_run
    assert dry_run(work) == {}, "not up to date after its own run"
    cal = work / "data" / "tiny" / "study.yaml"
    text = cal.read_text()
    doc = yaml.safe_load(text)
    doc["external_detections"]["det_bag"]["topic"] = "detected_leg_clusters"
    try:
        cal.write_text(yaml.safe_dump(doc))
        jobs = dry_run(work)
    finally:
        cal.write_text(text)
    assert jobs == {"leg_detections": {"det_bag"}, "detections_table": {""}}, jobs
    assert dry_run(work) == {}


def _start(work: Path, cf: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(SNAKEMAKE), "-n", "--snakefile", str(ROOT / "Snakefile"),
                           "--directory", str(work), "--cores", "1", "--force-use-threads",
                           "--configfile", str(cf)], capture_output=True, text=True,
                          timeout=300)


def _study(tmp_path: Path, side: dict | None = None, own: dict | None = None) -> Path:
    folder = tmp_path / "mine"
    folder.mkdir()
    sheet = folder / "trials.csv"
    sheet.write_text("study,protocol,subject,trial\nmine,tug,S1,tug_a\n")
    if own is not None:
        (folder / "study.yaml").write_text(yaml.safe_dump(own))
    if side is not None:
        (folder / "external.yaml").write_text(yaml.safe_dump(side))
    cf = tmp_path / "c.yaml"
    cf.write_text(yaml.safe_dump({"run": ["mine"], "peer_results": "", "studies": {"mine": {
        "trial_sheet": str(sheet), "subjects": str(folder / "subjects.csv")}}}))
    return cf


@pytest.mark.slow
@pytest.mark.parametrize("side, own, words", [
    ({"external_detections": {"d": {"path": "det/{trial}.bag", "topics": "/x"}}}, None,
     ["external.yaml", "external_detections.d", "topics", "did you mean"]),
    ({"external_detections": {"d": {"path": "det/tug_a.bag"}}}, None,
     ["external.yaml", "external_detections.d.path", "{trial}"]),
    (None, {"external_detections": {"d": {"path": "det/{trial}.bag", "protocols": ["treadmill"]}}},
     ["study.yaml", "external_detections.d.protocols"]),
    (None, {"external_detections": {"tug_m1": {"path": "det/{trial}.bag"}}},
     ["study.yaml", "external_detections.tug_m1", "already a method name"]),
    ({"external_detections": {"d": {"path": "det/{trial}.detections.csv"}}}, None,
     ["external.yaml] external_detections d", "1 of 1 trials' detection files are missing",
      "tug_a.detections.csv"]),
    ({"external_detections": {"d": {"path": "../{trial}.detections.csv"}}}, None,
     ["external_detections.d.path", "leads outside the trial sheet's folder"]),
])
def test_a_bad_declaration_stops_the_run_at_start_naming_file_and_field(tmp_path, side,
                                                                          own, words):
    res = _start(tmp_path, _study(tmp_path, side, own))
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert out.count("ConfigError") == 1, out[-3000:]
    for w in words:
        assert w in out, (w, out[-3000:])


@pytest.mark.slow
def test_a_bag_without_the_topic_is_named_at_start(tmp_path):
    from test_leg_detections import detection_bag

    cf = _study(tmp_path, {"external_detections": {"d": {"path": "det/{trial}.bag",
                                                          "topic": "/legs"}}})
    (tmp_path / "mine" / "det").mkdir()
    detection_bag(tmp_path / "mine" / "det" / "tug_a.bag")
    out = (r := _start(tmp_path, cf)).stdout + r.stderr
    assert r.returncode != 0
    for w in ("ConfigError", "external.yaml] external_detections d.topic", "'/legs' is not in",
              "tug_a.bag", "/detected_leg_clusters"):
        assert w in out, (w, out[-3000:])


@pytest.mark.slow
def test_the_report_shows_the_detection_table_and_lists_the_files(det_run):
    from conftest import tiny_workflow

    work, _ = det_run
    res = tiny_workflow(work)
    assert res.returncode == 0, res.stderr[-4000:]
    html = (work / "reports" / "tiny" / "index.html").read_text()
    assert "External leg detectors (no identity)" in html and "detections_table" in html
    inputs = (work / "reports" / "tiny" / "provenance" / "inputs.txt").read_text()
    assert "data/tiny/external.yaml" in inputs
    listed = inputs.splitlines()
    for t in (p.stem for p in (work / "data" / "tiny" / "det").glob("*.bag")):
        assert f"data/tiny/det/{t}.bag" in listed and \
            f"data/tiny/det/{t}.detections.csv" in listed, t
