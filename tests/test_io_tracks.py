"""Issue 37: the leg-track exchange format (gaitval/io/tracks/, docs/formats_external.md "Leg
tracks"): exact round trips of gaitval's own tracks, the clock and frame conversion, and one
clear error per kind of bad file."""
from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.io.tracks.exchange import TRACK_COLUMNS
from gaitval.io.tracks.read import read_tracks
from gaitval.io.tracks.sensor import tracks_to_sensor
from gaitval.io.tracks.write import track_to_exchange, write_tracks


def own_track(n: int = 40, seed: int = 3) -> pd.DataFrame:
    """A track table with gaitval's columns and dtypes: NaN before initialisation, every
    pattern, phases, flags (as TrackResult.to_frame gives)."""
    rng = np.random.default_rng(seed)
    t = 12.3456789 + np.arange(n) * 0.025 + rng.normal(0, 1e-4, n)
    x = rng.normal(1.5, 0.3, (2, n))
    y = rng.normal(0.0, 0.2, (2, n))
    x[:, :3] = np.nan
    y[:, :3] = np.nan
    pat = rng.choice(np.array(["SL", "LT", "FS_O", "FS_U", "UO"], dtype=object), (2, n))
    pat[:, :3] = ""
    return pd.DataFrame({
        "k": np.repeat(np.arange(n, dtype=np.int64), 2),
        "t_sensor_s": np.repeat(t, 2),
        "side": pd.Series(np.tile(np.array(["L", "R"], dtype=object), n), dtype=object),
        "x_m": x.T.ravel(), "y_m": y.T.ravel(),
        "vx_mps": rng.normal(0, 1, 2 * n) / 3, "vy_mps": rng.normal(0, 1, 2 * n) / 7,
        "observed": rng.random(2 * n) > 0.2,
        "pattern": pd.Series(pat.T.ravel(), dtype=object),
        "phase": np.repeat(rng.integers(-1, 6, n).astype(np.int64), 2),
        "swing": rng.random(2 * n) > 0.5,
        "interpolated": rng.random(2 * n) > 0.9,
    })


@pytest.mark.parametrize("ext", ["csv", "parquet"])
def test_own_track_round_trips_exactly(tmp_path, ext):
    track = own_track()
    p = write_tracks(track_to_exchange(track), tmp_path / f"a.tracks.{ext}", source="test")
    rows, meta = read_tracks(p)
    assert meta["units"] == "m" and meta["frame"] == "sensor" and meta["clock"] == "sensor"
    assert meta["source"] == "test"
    back = tracks_to_sensor(rows, meta)
    pd.testing.assert_frame_equal(back, track[list(TRACK_COLUMNS)], check_exact=True)


def test_csv_header_and_columns_as_documented(tmp_path):
    p = write_tracks(track_to_exchange(own_track(5)), tmp_path / "a.tracks.csv")
    lines = p.read_text().splitlines()
    assert lines[:4] == ["# gaitval-tracks v1", "# units: m", "# frame: sensor",
                         "# clock: sensor"]
    assert lines[4] == "t_s,k,side,x,y,vx,vy,observed,pattern,phase,swing,interpolated"


def test_millimetres_and_mocap_frame_and_clock(tmp_path):
    """A file in mm, field frame and mocap clock comes back in the sensor frame and clock:
    p_s = R(-yaw) (p_f - [x, y]); t_sensor = offset + (1 + drift 1e-6) t_mocap."""
    track = own_track(20)
    reg = {"x_m": 2.0, "y_m": -1.0, "yaw_rad": 0.7, "clock_offset_s": 1.25,
           "clock_drift_ppm": 40.0}
    c, s = math.cos(0.7), math.sin(0.7)
    rows = track_to_exchange(track)
    xf = c * rows["x"] - s * rows["y"] + 2.0
    yf = s * rows["x"] + c * rows["y"] - 1.0
    vxf = c * rows["vx"] - s * rows["vy"]
    vyf = s * rows["vx"] + c * rows["vy"]
    rows = rows.assign(x=xf * 1000, y=yf * 1000, vx=vxf * 1000, vy=vyf * 1000,
                       t_s=(rows["t_s"] - 1.25) / (1 + 40e-6))
    p = write_tracks(rows, tmp_path / "m.tracks.csv", units="mm", frame="mocap",
                     clock="mocap")
    back = tracks_to_sensor(*read_tracks(p), reg)
    exp = track[list(TRACK_COLUMNS)]
    for col in ("x_m", "y_m", "vx_mps", "vy_mps", "t_sensor_s"):
        np.testing.assert_allclose(back[col], exp[col], atol=1e-9, equal_nan=True)
    for col in ("k", "side", "observed", "pattern", "phase", "swing", "interpolated"):
        assert back[col].tolist() == exp[col].tolist()


def test_minimal_file_gets_documented_defaults(tmp_path):
    """Only t_s, side, x, y: k from the time stamps, velocities by central differences,
    observed where a position is given, UO where not observed, swing from the speed."""
    p = tmp_path / "min.tracks.csv"
    t = np.arange(10) * 0.1
    lines = ["# gaitval-tracks v1", "# units: m", "# frame: sensor", "# clock: sensor",
             "t_s,side,x,y"]
    for i, ti in enumerate(t.tolist()):
        lines.append(f"{ti!r},L,{0.2 * i!r},0.0")          # 2 m/s: swing
        lines.append(f"{ti!r},R,1.0,{'' if i == 4 else '0.5'}")   # standing; one gap
    p.write_text("\n".join(lines) + "\n")
    tr = tracks_to_sensor(*read_tracks(p))
    assert list(tr.columns) == list(TRACK_COLUMNS)
    L, R = tr[tr["side"] == "L"], tr[tr["side"] == "R"]
    assert L["k"].tolist() == list(range(10))
    np.testing.assert_allclose(L["vx_mps"], 2.0)
    assert L["swing"].all() and not R["swing"].any()
    assert R["observed"].tolist() == [i != 4 for i in range(10)]
    assert not tr["interpolated"].any() and (tr["phase"] == -1).all()
    assert tr.loc[R.index[4], "pattern"] == ""      # no position: no track, not UO


HEAD = ["# gaitval-tracks v1", "# units: m", "# frame: sensor", "# clock: sensor"]


def _csv(tmp_path, lines, name="bad.tracks.csv"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


GOOD = ["t_s,side,x,y", "0.0,L,1.0,0.1", "0.0,R,1.0,-0.1", "0.025,L,1.0,0.1",
        "0.025,R,1.0,-0.1"]


@pytest.mark.parametrize("lines, words", [
    (["# something else"] + HEAD[1:] + GOOD, ["line 1", "gaitval-tracks v1"]),
    ([HEAD[0], "# units: cm"] + HEAD[2:] + GOOD, ["'units'", "'cm'", "(line 2)", "m, mm"]),
    ([HEAD[0], HEAD[2], HEAD[3]] + GOOD,
     ["'units'", "missing", "no '# units: ...' line among header lines 1-3"]),
    (HEAD[:2] + ["# frame: world", HEAD[3]] + GOOD,
     ["'frame'", "'world'", "(line 3)", "sensor, mocap"]),
    (HEAD[:3] + ["# clock: video"] + GOOD, ["'clock'", "'video'", "(line 4)"]),
    (HEAD + ["t_s,side,x"] + [r.rsplit(",", 1)[0] for r in GOOD[1:]], ["'y'", "missing"]),
    (HEAD + ["t_s,side,x,y,z"] + [r + ",0" for r in GOOD[1:]], ["unknown column", "'z'"]),
    (HEAD + GOOD[:3] + ["0.025,X,1.0,0.1"], ["'side'", "line 8", "'X'", "L or R"]),
    (HEAD + GOOD[:2] + ["abc,R,1.0,-0.1"], ["'t_s'", "line 7", "'abc'", "not a number"]),
    (HEAD + GOOD[:2] + [",R,1.0,-0.1"], ["'t_s'", "line 7", "finite"]),
    (HEAD + GOOD[:2] + ["0.0,R,1.0,oops"], ["'y'", "line 7", "'oops'"]),
    (HEAD + GOOD + ["0.05,L,1.0,0.1"], ["line 10", "leg R is missing", "0.05"]),
    (HEAD + [GOOD[0], GOOD[1], GOOD[3]], ["leg R is missing", "no row has side R"]),
    (HEAD + GOOD + ["0.025,R,1.0,-0.1"], ["line 10", "twice"]),
    (HEAD + GOOD + ["0.05,L,1.0"], ["line 10", "3 cells"]),
    (HEAD + ["t_s,side,x,y,observed"] + [r + ",maybe" for r in GOOD[1:]],
     ["'observed'", "line 6", "'maybe'", "true/false"]),
    (HEAD + ["t_s,side,x,y,pattern"] + [r + ",XX" for r in GOOD[1:]],
     ["'pattern'", "line 6", "'XX'"]),
    (HEAD + ["t_s,side,x,y,phase"] + [r + ",7" for r in GOOD[1:]],
     ["'phase'", "line 6", "from -1 to 5"]),
    (HEAD + ["t_s,side,person,x,y"] + [r.replace(",L,", ",L,p1,").replace(",R,", ",R,p2,")
                                       for r in GOOD[1:]], ["exactly one", "'person'"]),
])
def test_bad_csv_one_clear_error(tmp_path, lines, words):
    p = _csv(tmp_path, lines)
    with pytest.raises(FileFormatError) as exc:
        read_tracks(p, trial="T1")
    msg = str(exc.value)
    assert str(p) in msg and "trial T1" in msg
    for w in words:
        assert w in msg, (w, msg)


def test_bad_parquet_errors(tmp_path):
    rows = track_to_exchange(own_track(4))
    p = tmp_path / "x.tracks.parquet"
    rows.to_parquet(p)
    with pytest.raises(FileFormatError, match="no schema metadata key 'gaitval:tracks'"):
        read_tracks(p)
    from gaitval.io.atomic import write_parquet
    meta = {"format": "gaitval-tracks", "version": 1, "units": "inch", "frame": "sensor",
            "clock": "sensor"}
    write_parquet(rows, p, metadata={"gaitval:tracks": json.dumps(meta)})
    with pytest.raises(FileFormatError, match="'units' is 'inch' .schema metadata "
                                              "'gaitval:tracks'.,"):
        read_tracks(p)
    meta.update(units="m", version=2)
    write_parquet(rows, p, metadata={"gaitval:tracks": json.dumps(meta)})
    with pytest.raises(FileFormatError, match="'version' is 2"):
        read_tracks(p)
    meta.update(version=1)
    bad = rows.copy()
    bad.loc[5, "side"] = "M"
    write_parquet(bad, p, metadata={"gaitval:tracks": json.dumps(meta)})
    with pytest.raises(FileFormatError, match=r"'side', row 6: 'M'"):
        read_tracks(p)
    (tmp_path / "x.tracks.json").write_text("{}")
    with pytest.raises(FileFormatError, match="unknown extension '.json'"):
        read_tracks(tmp_path / "x.tracks.json")


def test_time_outside_recording_and_registration_needed(tmp_path):
    p = _csv(tmp_path, HEAD[:3] + ["# clock: mocap"] + GOOD)
    rows, meta = read_tracks(p, trial="T1")
    with pytest.raises(FileFormatError, match="needs the trial's registration"):
        tracks_to_sensor(rows, meta, {}, path=p, trial="T1")
    reg = {"clock_offset_s": 5.0, "clock_drift_ppm": 0.0}
    with pytest.raises(FileFormatError) as exc:
        tracks_to_sensor(rows, meta, reg, path=p, trial="T1", t_range=(0.0, 2.0))
    msg = str(exc.value)
    for w in ("line 6, column 't_s'", "time stamp 0.0 s", "5.0000 s on the sensor clock",
              "outside the recording", str(p), "trial T1"):
        assert w in msg, (w, msg)
    rows2, meta2 = read_tracks(_csv(tmp_path, HEAD + GOOD, "late.tracks.csv"))
    with pytest.raises(FileFormatError, match=r"line 8, column 't_s': time stamp 0\.025 s"):
        tracks_to_sensor(rows2, meta2, path=p, t_range=(0.0, 0.01))
    out = tracks_to_sensor(rows, meta, reg, path=p, trial="T1", t_range=(4.9, 6.0))
    np.testing.assert_allclose(out["t_sensor_s"].unique(), [5.0, 5.025])


def test_people_file_reads_but_is_refused_for_legs(tmp_path):
    p = _csv(tmp_path, HEAD + ["t_s,person,x,y", "0.0,p1,1.0,0.0", "0.0,p2,2.0,0.0"])
    rows, meta = read_tracks(p)
    assert rows["person"].tolist() == ["p1", "p2"]
    with pytest.raises(FileFormatError, match="gives people"):
        tracks_to_sensor(rows, meta, path=p)


def test_external_path_stays_inside_the_sheets_folder(tmp_path):
    from gaitval.errors import ConfigError
    from gaitval.pipeline.steps.declarations import external_track_path

    sheet = tmp_path / "study" / "trials.csv"
    sheet.parent.mkdir()
    ok = external_track_path(sheet, {"path": "tracks/{trial}.tracks.csv"}, "T1", "mine")
    assert ok == sheet.parent / "tracks" / "T1.tracks.csv"
    with pytest.raises(ConfigError, match=r"tracking.external.mine.path: .*leads outside"):
        external_track_path(sheet, {"path": "../x/{trial}.tracks.csv"}, "T1", "mine")
    (sheet.parent / "study.yaml").write_text("allow_outside_paths: true\n")
    assert external_track_path(sheet, {"path": "../x/{trial}.tracks.csv"}, "T1", "mine")


def test_import_step_empty_track_for_a_refused_registration_and_errors_by_file(tmp_path):
    """A mocap-frame file of a trial whose registration was refused gives an empty track
    (its evaluation is not_registered); a file past the recording is one error naming it."""
    from gaitval.io.scanlog import write_scanlog
    from gaitval.pipeline.steps.external import import_tracks_step
    from gaitval.types import ScanSeries

    scans = ScanSeries(t=np.arange(20) * 0.025, ranges=np.full((20, 5), 2.0),
                       angle_min=-0.5, angle_increment=0.25, range_min=0.1, range_max=30.0)
    sensor = tmp_path / "sensor.parquet"
    write_scanlog(sensor, scans)
    reg = tmp_path / "registration.json"
    reg.write_text(json.dumps({"status": "refused", "reason": "no poles"}))
    mocap = _csv(tmp_path, HEAD[:2] + ["# frame: mocap", HEAD[3]] + GOOD, "m.tracks.csv")
    out = import_tracks_step(mocap, sensor, reg, "T1", "ext", tmp_path / "o.parquet")
    assert len(out) == 0 and list(out.columns[:2]) == ["trial", "method"]
    late = _csv(tmp_path, HEAD + GOOD + ["9.0,L,1,0", "9.0,R,1,0"], "late.tracks.csv")
    with pytest.raises(FileFormatError) as exc:
        import_tracks_step(late, sensor, reg, "T1", "ext", tmp_path / "o.parquet")
    assert str(late) in str(exc.value) and "outside the recording" in str(exc.value)
    ok = import_tracks_step(_csv(tmp_path, HEAD + GOOD, "ok.tracks.csv"), sensor, None,
                            "T1", "ext", tmp_path / "o.parquet")
    assert ok["method"].eq("ext").all() and len(ok) == 4


def test_converted_times_snap_to_the_scan_they_name():
    from gaitval.io.tracks.sensor import snap_to_scans

    scans = np.array([0.0, 0.025, 0.05, 0.075])
    t = np.array([0.025 + 4e-16, 0.05 - 2e-7, 0.0374, 0.075 + 5e-6, -1e-9])
    np.testing.assert_array_equal(snap_to_scans(t, scans),
                                  [0.025, 0.05, 0.0374, 0.075 + 5e-6, 0.0])


def test_rollator_tracks_in_the_mocap_frame_are_refused(tmp_path):
    """The rollator's laser moves: a file in the mocap frame cannot be brought to it with
    one pose, and the import says so naming the file and the trial."""
    from gaitval.pipeline.steps.external import import_tracks_step

    p = _csv(tmp_path, HEAD[:2] + ["# frame: mocap", HEAD[3]] + GOOD)
    with pytest.raises(FileFormatError) as exc:
        import_tracks_step(p, tmp_path / "none.parquet", None, "R1", "ext", tmp_path / "o",
                           moving_sensor=True)
    msg = str(exc.value)
    assert str(p) in msg and "trial R1" in msg and "laser moves" in msg


@pytest.mark.parametrize("units, scale, words", [
    ("m", 1000.0, ["line 6, column 'x'", "(1000, 100) m", "beyond its range (30 m)",
                   "header units 'm'", "units: mm"]),
    ("mm", 1.0, ["line 6, column 'x'", "every position lies within 5 cm of the laser",
                 "header units 'mm'", "units: m"]),
])
def test_positions_in_the_wrong_units_are_refused(tmp_path, units, scale, words):
    """Positions in millimetres declared as metres lie beyond the laser's range; positions
    in metres declared as millimetres all lie at the laser: one error naming the file, the
    row and the header's units (the laser's range from its scan log)."""
    lines = [HEAD[0], f"# units: {units}"] + HEAD[2:] + ["t_s,side,x,y"] + [
        f"{t},{s},{1.0 * scale:g},{(0.1 if s == 'L' else -0.1) * scale:g}"
        for t in (0.0, 0.025) for s in "LR"]
    p = _csv(tmp_path, lines)
    rows, meta = read_tracks(p, trial="T1")
    with pytest.raises(FileFormatError) as exc:
        tracks_to_sensor(rows, meta, path=p, trial="T1", max_range_m=30.0)
    msg = str(exc.value)
    for w in (str(p), "trial T1", *words):
        assert w in msg, (w, msg)
    ok = _csv(tmp_path, HEAD + GOOD, "ok.tracks.csv")
    r, m = read_tracks(ok)
    assert len(tracks_to_sensor(r, m, path=ok, max_range_m=30.0)) == 4


@pytest.mark.parametrize("ext", ["csv", "parquet"])
def test_third_clock_offset_in_the_header(tmp_path, ext):
    """A tracker on its own computer's clock: the header's clock_offset_s, stated by the
    user, moves every t_s onto the header's clock; the import is then the same track."""
    track = own_track()
    rows = track_to_exchange(track)
    rows["t_s"] = rows["t_s"] + 1.7e9                     # e.g. Unix time on the tracker PC
    p = write_tracks(rows, tmp_path / f"a.tracks.{ext}", clock_offset_s=-1.7e9)
    back_rows, meta = read_tracks(p)
    assert meta["clock_offset_s"] == -1.7e9
    back = tracks_to_sensor(back_rows, meta)
    np.testing.assert_allclose(back["t_sensor_s"], track["t_sensor_s"], rtol=0, atol=1e-6)
    np.testing.assert_array_equal(back["x_m"], track["x_m"])
    # without the offset the same stamps are outside the recording, named with the row
    p2 = write_tracks(rows, tmp_path / f"b.tracks.{ext}")
    r2, m2 = read_tracks(p2)
    with pytest.raises(FileFormatError, match="outside the recording"):
        tracks_to_sensor(r2, m2, t_range=(12.0, 14.0))


def test_third_clock_offset_that_is_no_number(tmp_path):
    p = _csv(tmp_path, ["# gaitval-tracks v1", "# units: m", "# frame: sensor",
                        "# clock: sensor", "# clock_offset_s: soon", "t_s,side,x,y",
                        "0.0,L,1.0,0.1", "0.0,R,1.0,-0.1"])
    with pytest.raises(FileFormatError, match=r"clock_offset_s.*'soon' \(line 5\)"):
        read_tracks(p)
