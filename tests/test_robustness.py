"""Issue 15: bad input ends as a gaitval error naming the file — no segfault, no hang, no
traceback, nothing silently wrong — and an empty scene gives no leg track."""
from __future__ import annotations

import json
import math
import os
import time

import numpy as np
import pandas as pd
import pytest

from gaitval.cli import main
from gaitval.errors import FileFormatError, TrialSheetError
from gaitval.io.c3d import read_c3d, write_c3d
from gaitval.io.isolate import run_isolated
from gaitval.io.trialsheet import load_trial_sheet, sheet_problems

TUG_METHODS = ("tug_m1", "tug_m2", "tug_m3")


# -- C3D: the three reproducers of the issue, and the child process ------------------------
@pytest.mark.realdata
@pytest.mark.parametrize("cut, message", [
    ("flip666", "POINT:USED must be a number but is stored as text"),       # was SIGSEGV
    (3570, r"the data section \(block 11\) lies beyond the end of the file"),  # was a hang
    (10120, "the header announces 487 frames of 824 bytes, the data section holds 6"),
])                                                       # was 6 frames of NaN (DEC file)
def test_issue_reproducers_give_gaitval_errors(realdata, tmp_path, capsys, cut, message):
    data = bytearray((realdata / "c3d" / "Gait_MotionAnalysis.c3d").read_bytes())
    if cut == "flip666":
        data[666] = 0xFF
    else:
        data = data[:cut]
    path = tmp_path / f"repro_{cut}.c3d"
    path.write_bytes(bytes(data))
    t0 = time.monotonic()
    with pytest.raises(FileFormatError, match=message) as exc:
        read_c3d(path)
    assert str(path) in str(exc.value) and time.monotonic() - t0 < 10
    assert main(["inspect", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("gaitval: error: [file ") and "Traceback" not in err


def _segfault(_):
    import ctypes
    ctypes.string_at(0)


def _stall(_):
    time.sleep(60)


@pytest.mark.parametrize("func, message", [(_segfault, r"crashed reading it \(SIGSEGV\)"),
                                           (_stall, "did not finish reading it within 1 s")])
def test_a_native_crash_or_stall_in_the_child_is_an_error_naming_the_file(func, message):
    with pytest.raises(FileFormatError, match=message) as exc:
        run_isolated(func, None, path="walk.c3d", trial="T1", what="ezc3d", timeout_s=1)
    assert "[file walk.c3d, trial T1]" in str(exc.value)


def test_a_capture_of_40000_frames_is_not_refused(tmp_path):
    """C3D counts are unsigned: POINT:FRAMES of 40,000 is int16 -25,536 in the file."""
    xyz = np.zeros((40000, 1, 3)) + 0.5
    assert read_c3d(write_c3d(tmp_path / "long.c3d", ["A"], xyz, 200.0)).n_frames == 40000


@pytest.mark.realdata
def test_a_y_up_walk_is_turned_to_z_up_or_refused(realdata, tmp_path):
    m = read_c3d(realdata / "c3d" / "PiG_Motion-FlatFoot-Full.c3d")
    assert m.meta["vertical_axis"] == "+z"
    y_up = np.stack([m.xyz[..., 0], m.xyz[..., 2], -m.xyz[..., 1]], axis=-1)   # y up
    p = write_c3d(tmp_path / "yup.c3d", m.labels, y_up, m.rate_hz)
    back = read_c3d(p)
    assert back.meta["vertical_axis"] == "+y"
    np.testing.assert_allclose(back.xyz, m.xyz, atol=1e-6)
    with pytest.raises(FileFormatError, match=r"\+y points up"):
        read_c3d(p, vertical="z")


# -- loaders: non-finite and contradictory metadata -----------------------------------------
def _scanlog(tmp_path, **meta):
    import pyarrow as pa
    import pyarrow.parquet as pq
    base = {"format": "gaitval-scanlog", "version": 1, "angle_min_rad": -1.0,
            "angle_increment_rad": 0.1, "n_beams": 3, "range_unit": "m",
            "range_min_m": 0.1, "range_max_m": 30.0}
    base.update(meta)
    tab = pa.table({"t_s": [0.0, 0.1], "ranges": pa.FixedSizeListArray.from_arrays(
        pa.array(np.ones(6, dtype=np.float32)), 3)})
    p = tmp_path / "x.scan.parquet"
    pq.write_table(tab.replace_schema_metadata(
        {b"gaitval:scanlog": json.dumps(base).encode()}), p)
    return p


@pytest.mark.parametrize("meta, field", [
    ({"n_beams": math.inf}, "n_beams"), ({"range_max_m": math.nan}, "range_max_m"),
    ({"range_min_m": 40.0}, "range_min_m"), ({"angle_increment_rad": 0}, "angle_increment"),
    ({"version": "two"}, "version"), ({"mounting_height_m": "low"}, "mounting_height_m")])
def test_scan_log_metadata_is_checked(tmp_path, meta, field):
    from gaitval.io.scanlog import read_scanlog
    with pytest.raises(FileFormatError, match=field) as exc:
        read_scanlog(_scanlog(tmp_path, **meta))
    assert "x.scan.parquet" in str(exc.value) and not getattr(exc.value, "unexpected", 0)


def test_annotations_in_utf16_are_refused_by_name(tmp_path):
    from gaitval.io.annotations import read_annotations
    p = tmp_path / "a.annotations.csv"
    p.write_text("# gaitval-annotations v1\nt_s,event\n1.0,foot_contact\n", encoding="utf-16")
    with pytest.raises(FileFormatError, match="not UTF-8"):
        read_annotations(p)


# -- trial sheet -----------------------------------------------------------------------------
HEADER = ("study,protocol,subject,trial,sensor_kind,mocap_file,sensor_file,sensor_topic,"
          "annotation_file,sensor_height_m,clock_offset_s")


def _study(tmp_path, rows, subjects="subject,leg_width_m\nS01,0.10\n"):
    (tmp_path / "m").mkdir(exist_ok=True)
    (tmp_path / "m" / "a.c3d").write_bytes(b"")
    (tmp_path / "a.scan.parquet").write_bytes(b"")
    (tmp_path / "trials.csv").write_text(HEADER + "\n" + "\n".join(rows) + "\n")
    (tmp_path / "subjects.csv").write_text(subjects)
    return tmp_path / "trials.csv"


def test_validate_lists_every_problem_at_once(tmp_path, capsys):
    sheet = _study(tmp_path, [
        "s,tug,S01,t1,lrs,m/a.c3d,a.scan.parquet,,,nan,",
        "s,tug,S01,t2,lrs,m/a.c3d,a.scan.parquet,,,0.27,inf",
        "s,tug,S01,t3,lrs,m/a.c3d,../../../../etc/passwd,,,0.27,",
        "s,tug,S01,t4,lrs,m/a.c3d," + "x" * 5000 + ".scan.parquet,,,0.27,"],
        subjects="subject,leg_width_m\nS01,nan\n")
    _, problems = sheet_problems(sheet)
    text = "\n".join(str(p) for p in problems)
    for expect in ("row 2 (trial 't1'), column 'sensor_height_m'",
                   "row 3 (trial 't2'), column 'clock_offset_s'",
                   "row 4 (trial 't3'), column 'sensor_file': path '../../../../etc/passwd' "
                   "leads outside", "row 5 (trial 't4'), column 'sensor_file'",
                   "row 2 (subject 'S01'), column 'leg_width_m'"):
        assert expect in text
    assert main(["validate", str(sheet)]) == 1
    err = capsys.readouterr().err
    assert f"{len(problems)} problems" in err and "Traceback" not in err


def test_outside_paths_only_when_the_study_allows_them(tmp_path):
    outside = tmp_path.parent / f"{tmp_path.name}_elsewhere.c3d"
    outside.write_bytes(b"")
    sheet = _study(tmp_path, [f"s,tug,S01,t1,lrs,{outside},a.scan.parquet,,,0.27,"])
    with pytest.raises(TrialSheetError, match="leads outside the trial sheet's folder"):
        load_trial_sheet(sheet)
    (tmp_path / "study.yaml").write_text("allow_outside_paths: true\n")
    assert load_trial_sheet(sheet).loc["t1", "mocap_path"] == str(outside)


# -- outputs, command line -------------------------------------------------------------------
def test_outputs_follow_the_umask(tmp_path):
    from gaitval.io.atomic import write_csv, write_text
    old = os.umask(0o022)
    try:
        a = write_text(tmp_path / "index.html", "<html/>")
        b = write_csv(pd.DataFrame({"x": [1]}), tmp_path / "t.csv")
    finally:
        os.umask(old)
    assert os.stat(a).st_mode & 0o777 == 0o644 and os.stat(b).st_mode & 0o777 == 0o644


def test_a_missing_config_file_is_one_line_exit_1(tmp_path, capsys):
    rc = main(["track", "--sensor", str(tmp_path / "s.parquet"), "--sheet", "x.csv",
               "--subjects", "y.csv", "--trial", "t", "--method", "tug_m1", "--config",
               str(tmp_path / "missing.json"), "--out", str(tmp_path / "o.parquet")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and len(err) == 1 and err[0].startswith("gaitval: error: [file ")


# -- "no subject": empty scenes --------------------------------------------------------------
def _furniture(n=300, seed=3):
    """A room seen by a still sensor at 7.5 scans/s: chair and table legs in pairs (leg-like
    separations) flickering in and out, nobody walking."""
    rng = np.random.default_rng(seed)
    legs = np.array([[1.5, 0.3], [1.5, -0.1], [2.2, 0.8], [2.6, 0.8], [3.0, -1.0],
                     [3.4, -1.0], [3.0, -1.4], [3.4, -1.4]])
    xy = []
    for _ in range(n):
        keep = rng.random(len(legs)) > 0.3
        xy.append(legs[keep] + rng.normal(0, 0.01, (int(keep.sum()), 2)))
    return xy


def test_closest_pair_says_no_subject_for_furniture_and_finds_a_walker():
    from gaitval.track.init import INITIALISERS, ClosestPair
    from gaitval.track.observations import DetectionSeries
    xy = _furniture()
    src = DetectionSeries(xy, [["SL"] * len(o) for o in xy])
    assert ClosestPair().find(src, 0.1) is not None          # the plain rule: a "subject"
    assert INITIALISERS.build("closest_pair").find(src, 0.1) is None
    walk = [np.vstack([o, [[0.5 + 0.02 * k, 0.1 + 0.05 * (k // 4 % 2)],
                           [0.6 + 0.02 * k, -0.1]]]) for k, o in enumerate(xy)]
    src = DetectionSeries(walk, [["SL"] * len(o) for o in walk])
    assert INITIALISERS.build("closest_pair").find(src, 0.1) is not None


def _negative_bags(realdata):
    bags = sorted((realdata / "lrs").glob("negative_*.bag"))
    if not bags:
        pytest.skip(f"no empty-scene recordings (negative_*.bag) in {realdata / 'lrs'}")
    return bags


MTST_METHODS = ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed")


@pytest.mark.realdata
@pytest.mark.slow
def test_empty_scene_bags_give_no_leg_track(realdata):
    """leg_tracker's recordings of empty rooms (a robot's three lasers, the robot moving at
    times): every TUG and MTST method reports no track on every topic.  (The rollator's KF
    and PF still follow furniture here: issue 36.)"""
    from gaitval.detect.base import split_observations
    from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans
    from gaitval.methods import build_tracker
    for bag in _negative_bags(realdata):
        for topic in describe_rosbag(bag)["scans"]:
            scans = read_rosbag_scans(bag, topic)
            det, _ = build_tracker("tug_m1")                  # the three share the detector
            xy, pats = split_observations(det.detect(scans, 0.10), scans.n_scans)
            for method in TUG_METHODS:
                res = build_tracker(method)[1].run(scans.t, xy, pats, 0.10)
                assert np.isnan(res.x).all(), f"{bag.name} {topic} {method}"
            for method in MTST_METHODS:
                det, trk = build_tracker(method)
                xy, pats = split_observations(det.detect(scans, 0.10), scans.n_scans)
                res = trk.run(scans.t, xy, pats, 0.10)
                assert np.isnan(res.x).all(), f"{bag.name} {topic} {method}"


@pytest.mark.realdata
def test_a_walking_subject_is_still_found(realdata):
    from gaitval.io.rosbag import read_rosbag_scans
    from gaitval.methods import track_trial
    scans = read_rosbag_scans(realdata / "lrs" / "positive_1.bag")
    track = track_trial(scans, "tug_m1", 0.10)
    assert track["x_m"].notna().mean() > 0.9
