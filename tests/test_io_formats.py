"""gaitval's own formats (scan log, ultrasonic log, annotations): round trips, the
no-return mapping, timestamp reporting, bad files, and ``describe`` on each kind."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.io.annotations import read_annotations, write_annotations
from gaitval.io.inspect import describe, format_description, kind_of
from gaitval.io.scanlog import read_scanlog, write_scanlog
from gaitval.io.ultrasonic import read_ultrasonic, write_ultrasonic
from gaitval.types import ScanSeries, UltrasonicLog


def make_series() -> ScanSeries:
    rng = np.random.default_rng(3)
    r = rng.uniform(0.2, 8.0, size=(6, 11))
    r[0, 3] = np.nan                      # no return already NaN
    r[1, 4] = np.inf                      # driver's inf
    r[2, 5] = 0.0                         # zero
    r[3, 6] = 45.0                        # beyond range_max
    r[4, 7] = 0.05                        # below range_min
    t = np.array([0.0, 0.025, 0.05, 0.05, 0.075, 0.07])   # duplicate at 3, going back at 5
    return ScanSeries(t=t, ranges=r, angle_min=-np.pi / 2, angle_increment=np.pi / 10,
                      range_min=0.1, range_max=30.0, sensor_model="Hokuyo UTM-30LX",
                      mounting_height_m=0.27)


@pytest.mark.parametrize("unit,tol", [("mm", 0.0005), ("m", 1e-6)])
def test_scanlog_roundtrip(tmp_path, unit, tol):
    s = make_series()
    p = write_scanlog(tmp_path / f"a_{unit}.scan.parquet", s, range_unit=unit)
    r = read_scanlog(p)
    bad = np.zeros(s.ranges.shape, dtype=bool)
    bad[0, 3] = bad[1, 4] = bad[2, 5] = bad[3, 6] = bad[4, 7] = True
    assert np.array_equal(np.isnan(r.ranges), bad)
    assert r.n_no_return_raw == 5
    assert np.max(np.abs(r.ranges[~bad] - s.ranges[~bad])) <= tol
    assert np.array_equal(r.t, s.t)                                 # never reordered
    assert list(r.timestamp_issues["problem"]) == ["duplicate", "non-monotonic"]
    assert list(r.timestamp_issues["index"]) == [3, 5]
    assert (r.angle_min, r.angle_increment) == (s.angle_min, s.angle_increment)
    assert r.sensor_model == "Hokuyo UTM-30LX" and r.mounting_height_m == 0.27
    assert r.meta["range_unit"] == unit


def test_scanlog_mm_is_readable_without_gaitval(tmp_path):
    import pyarrow.parquet as pq

    p = write_scanlog(tmp_path / "b.scan.parquet", make_series())
    tab = pq.read_table(p)
    meta = json.loads(tab.schema.metadata[b"gaitval:scanlog"])
    mm = np.stack(tab["ranges"].to_numpy(zero_copy_only=False))
    assert meta["range_unit"] == "mm" and meta["n_beams"] == 11
    assert mm[1, 4] == 0 and mm[0, 3] == 0                          # 0 = no return on disk
    assert mm.dtype.kind == "u"


def test_scanlog_bad_files(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    plain = tmp_path / "plain.scan.parquet"
    pq.write_table(pa.table({"t_s": [0.0], "ranges": [[1, 2]]}), plain)
    with pytest.raises(FileFormatError, match="no 'gaitval:scanlog' metadata"):
        read_scanlog(plain, trial="T1")
    junk = tmp_path / "junk.scan.parquet"
    junk.write_text("not parquet")
    with pytest.raises(FileFormatError, match="junk.scan.parquet"):
        read_scanlog(junk)
    partial = tmp_path / "partial.scan.parquet"
    tab = pa.table({"t_s": [0.0], "ranges": [[1, 2]]}).replace_schema_metadata(
        {b"gaitval:scanlog": json.dumps({"format": "gaitval-scanlog"}).encode()})
    pq.write_table(tab, partial)
    with pytest.raises(FileFormatError, match="metadata incomplete"):
        read_scanlog(partial)


def make_us() -> UltrasonicLog:
    tof = np.array([[1.0e-3, 2.0e-3, 3.0e-3], [1.1e-3, np.nan, 3.1e-3],
                    [1.2e-3, 2.2e-3, 0.0], [1.3e-3, 2.3e-3, 3.3e-3]])
    anchors = pd.DataFrame({"anchor": ["ANC1", "ANC2", "ANC3"], "x_m": [0.0, 2.0, 0.0],
                            "y_m": [0.0, 0.0, 1.5], "z_m": [0.0, 0.0, 0.0]})
    return UltrasonicLog(t=np.array([0.0, 0.02, 0.02, 0.06]),
                         temperature_c=np.array([21.0, 21.0, 21.5, 21.5]),
                         anchors=anchors, tof_s=tof)


def test_ultrasonic_roundtrip(tmp_path):
    u = make_us()
    p = write_ultrasonic(tmp_path / "a.us.parquet", u, sensor_model="MB1360")
    r = read_ultrasonic(p)
    assert r.anchor_ids == ["ANC1", "ANC2", "ANC3"]
    assert np.allclose(r.anchors[["x_m", "y_m", "z_m"]], u.anchors[["x_m", "y_m", "z_m"]])
    nan = np.isnan(r.tof_s)
    assert nan[1, 1] and nan[2, 2] and nan.sum() == 2                # NaN and 0 -> no echo
    assert np.allclose(r.tof_s[~nan], u.tof_s[~nan])
    assert np.array_equal(r.t, u.t) and np.array_equal(r.temperature_c, u.temperature_c)
    assert list(r.meta["timestamp_issues"]["problem"]) == ["duplicate"]


def test_ultrasonic_bad_file(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    p = tmp_path / "x.us.parquet"
    pq.write_table(pa.table({"t_s": [0.0]}), p)
    with pytest.raises(FileFormatError, match="gaitval:ultrasonic"):
        read_ultrasonic(p)


EVENTS = pd.DataFrame({
    "t_s": [1.25, 1.8, 2.4, 3.0],
    "event": ["foot_contact", "target_step", "target_step", "cross_step"],
    "side": ["L", "R", "L", "R"],
    "target": ["", "T3", "T5", ""],
    "value": ["", "hit", "miss", "yes"],
})


def test_annotations_roundtrip(tmp_path):
    p = write_annotations(tmp_path / "s1.annotations.csv", EVENTS, time_base="video",
                          time_offset_s=-0.5, rater="R2", fps=30.0)
    ev, meta = read_annotations(p)
    assert meta["time_base"] == "video" and float(meta["time_offset_s"]) == -0.5
    assert list(ev["event"]) == list(EVENTS["event"])
    assert list(ev["value"]) == list(EVENTS["value"])
    assert list(ev["target"]) == list(EVENTS["target"])
    assert list(ev["rater"]) == ["R2"] * 4
    assert np.allclose(ev["t_mocap_s"], EVENTS["t_s"] - 0.5)


def test_annotations_bad_files(tmp_path):
    p = tmp_path / "a.annotations.csv"
    p.write_text("t_s,event,side\n1.0,foot_contact,L\n")
    with pytest.raises(FileFormatError, match="gaitval-annotations v1"):
        read_annotations(p)
    p.write_text("# gaitval-annotations v1\nt_s,event,side\n1.0,foot_contact,X\n")
    with pytest.raises(FileFormatError, match="line 3"):
        read_annotations(p)
    p.write_text("# gaitval-annotations v1\nt_s,event,side\nabc,foot_contact,L\n")
    with pytest.raises(FileFormatError, match="not a number"):
        read_annotations(p)


# -- describe() on each kind ---------------------------------------------------------------

def test_describe_scanlog(tmp_path):
    p = write_scanlog(tmp_path / "d.scan.parquet", make_series())
    d = describe(p)
    json.dumps(d, allow_nan=False)
    assert d["kind"] == "scanlog" and d["n_scans"] == 6 and d["n_beams"] == 11
    assert d["angle_min_deg"] == pytest.approx(-90.0)
    assert d["angle_max_deg"] == pytest.approx(90.0)
    assert d["angle_increment_deg"] == pytest.approx(18.0)
    assert d["n_no_return"] == 5 and d["n_timestamp_issues"] == 2
    assert d["rate_hz"] == pytest.approx(40.0)                  # median of positive steps
    assert d["sensor_model"] == "Hokuyo UTM-30LX" and d["mounting_height_m"] == 0.27
    text = format_description(d)
    assert "6" in text and "11" in text and "Hokuyo" in text and "non-monotonic" in text


def test_describe_ultrasonic(tmp_path):
    p = write_ultrasonic(tmp_path / "d.us.parquet", make_us())
    d = describe(p)
    json.dumps(d, allow_nan=False)
    assert d["kind"] == "ultrasonic" and d["n_samples"] == 4 and d["quantity"] == "tof"
    assert [a["anchor"] for a in d["anchors"]] == ["ANC1", "ANC2", "ANC3"]
    assert d["no_echo"] == {"ANC1": 0, "ANC2": 1, "ANC3": 1}
    assert d["duration_s"] == pytest.approx(0.06)
    assert "ANC2" in format_description(d)


def test_describe_annotations(tmp_path):
    p = write_annotations(tmp_path / "d.annotations.csv", EVENTS)
    d = describe(p)
    json.dumps(d, allow_nan=False)
    assert d["kind"] == "annotations" and d["n_events"] == 4
    assert d["events"] == {"cross_step": 1, "foot_contact": 1, "target_step": 2}
    assert d["target_steps"] == {"hit": 1, "miss": 1}
    assert d["time_base"] == "video"
    assert "target_step 2" in format_description(d)


def test_unknown_and_missing_files(tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("hello")
    with pytest.raises(FileFormatError, match="unknown file kind") as exc:
        describe(f)
    assert "notes.txt" in str(exc.value)
    with pytest.raises(FileFormatError, match="not found"):
        kind_of(tmp_path / "gone.c3d")
    folder = tmp_path / "folder"
    folder.mkdir()
    with pytest.raises(FileFormatError, match="unknown file kind"):
        describe(folder)


# -- the ingested marker table (mocap.parquet) ---------------------------------------------
@pytest.mark.realdata
def test_ingested_marker_table_round_trips_a_real_walk_with_its_gaps(realdata, tmp_path):
    """A real Vicon walk with missing markers comes back from ``mocap.parquet`` with the
    same coordinates and gaps; only the label column is dictionary-encoded, and the file
    still reads as the documented tidy table without gaitval."""
    import pyarrow.parquet as pq

    from gaitval.io.c3d import read_c3d
    from gaitval.io.ingest import read_mocap_parquet, write_mocap_parquet

    m = read_c3d(realdata / "c3d" / "PiG_Motion-FlatFoot-Hole.c3d")
    assert np.isnan(m.xyz).any()                          # the file has real gaps
    p = write_mocap_parquet(m, tmp_path / "mocap.parquet", source="walk.c3d")
    back = read_mocap_parquet(p)
    np.testing.assert_array_equal(back.xyz, m.xyz)        # NaN where NaN, bit for bit
    n_f, n_m, _ = m.xyz.shape                            # the layout readers always had:
    assert back.xyz.strides == (8 * n_m, 8, 8 * n_f * n_m)   # sums downstream follow it
    assert (back.labels, back.rate_hz, back.first_frame, back.path) == (
        m.labels, m.rate_hz, m.first_frame, "walk.c3d")
    tidy = pd.read_parquet(p)
    assert list(tidy.columns) == ["frame", "t_s", "marker", "x_m", "y_m", "z_m"]
    assert len(tidy) == m.n_frames * len(m.labels)
    assert list(tidy["marker"][: len(m.labels)]) == list(m.labels)
    np.testing.assert_array_equal(tidy["t_s"].to_numpy()[:: len(m.labels)], m.t)
    rg = pq.ParquetFile(p).metadata.row_group(0)
    enc = {rg.column(i).path_in_schema: rg.column(i).encodings for i in range(rg.num_columns)}
    assert "RLE_DICTIONARY" in enc["marker"] and "RLE_DICTIONARY" not in enc["x_m"]


def test_a_bad_ingested_marker_table_is_an_error_naming_file_and_trial(tmp_path):
    from gaitval.io.ingest import read_mocap_parquet

    junk = tmp_path / "junk.parquet"
    junk.write_bytes(b"not parquet at all")
    with pytest.raises(FileFormatError, match="not an ingested mocap.parquet") as exc:
        read_mocap_parquet(junk, trial="T7")
    assert "junk.parquet" in str(exc.value) and "trial T7" in str(exc.value)
    plain = tmp_path / "plain.parquet"                   # a Parquet file, no gaitval metadata
    pd.DataFrame({"x_m": [1.0], "y_m": [2.0], "z_m": [3.0]}).to_parquet(plain)
    with pytest.raises(FileFormatError, match="not an ingested mocap.parquet"):
        read_mocap_parquet(plain, trial="T7")
    import pyarrow as pa
    import pyarrow.parquet as pq

    torn = pa.table({"x_m": [1.0, 2.0, 3.0], "y_m": [0.0] * 3, "z_m": [0.0] * 3})
    torn = torn.replace_schema_metadata({b"gaitval:mocap": json.dumps(
        {"labels": ["A", "B"], "rate_hz": 100, "first_frame": 1, "units": "mm",
         "source": "x.c3d"}).encode()})
    pq.write_table(torn, tmp_path / "torn.parquet")
    with pytest.raises(FileFormatError, match="3 rows are not whole frames of 2 markers"):
        read_mocap_parquet(tmp_path / "torn.parquet", trial="T7")


# -- issue 33: metadata and column types checked against each format's schema ---------------

def _log_parts(kind: str):
    """Columns, metadata key and metadata of a small valid log (the fuzz harness' seeds)."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parent / "fuzz"))
    import fuzz_seeds
    return fuzz_seeds.parquet_parts(kind)


def _write_log(path, cols, key, meta):
    import pyarrow as pa
    import pyarrow.parquet as pq
    raw = json.dumps(meta).encode()               # NaN/inf as JSON's NaN/Infinity tokens
    pq.write_table(pa.table(cols).replace_schema_metadata({key: raw}), path)
    return path


@pytest.mark.parametrize("kind, field, value, message", [
    ("ultrasonic", "version", float("inf"), "'version' is inf"),
    ("ultrasonic", "version", float("nan"), "'version' is nan"),
    ("ultrasonic", "version", 2, "version 2 is newer"),
    ("ultrasonic", "format", float("nan"), "'format' is nan, not text"),
    ("ultrasonic", "format", "gaitval-scanlog", "'format' is 'gaitval-scanlog'"),
    ("ultrasonic", "sensor_model", float("nan"), "'sensor_model' is nan, not text"),
    ("scanlog", "scan_time_s", float("nan"), "'scan_time_s' is nan"),
    ("scanlog", "scan_time_s", float("-inf"), "'scan_time_s' is -inf"),
    ("scanlog", "scan_time_s", 3600.0, "a scan takes at most 10 s"),
    ("scanlog", "sensor_model", float("nan"), "'sensor_model' is nan, not text"),
    ("scanlog", "version", float("nan"), "'version' is nan"),
    ("scanlog", "version", 0.5, "'version' is 0.5"),
    ("scanlog", "format", None, "field 'format' is missing"),
    ("scanlog", "time_increment_s", float("nan"), "'time_increment_s' is nan"),
    ("scanlog", "time_increment_s", 0.5, "time_increment is 0.5 s; over 31 beams"),
    ("scanlog", "angle_increment_rad", 1.0, "1 rad x 31 beams spans more than one turn"),
    ("scanlog", "angle_min_rad", 10.0, "angle_min is 10 rad, more than one turn"),
])
def test_non_finite_or_wrong_metadata_is_refused_naming_the_field(tmp_path, kind, field,
                                                                   value, message):
    cols, key, meta = _log_parts(kind)
    if value is None:
        del meta[field]
    else:
        meta[field] = value
    p = _write_log(tmp_path / f"x.{'scan' if kind == 'scanlog' else 'us'}.parquet", cols,
                   key, meta)
    read = read_scanlog if kind == "scanlog" else read_ultrasonic
    with pytest.raises(FileFormatError, match=message) as exc:
        read(p, trial="T9")
    assert str(p) in str(exc.value) and "T9" in str(exc.value)
    assert not getattr(exc.value, "unexpected", False)


def _dtype_swap(cols, name, how):
    import pyarrow as pa
    n = len(cols["t_s"])
    if how == "timestamp":
        cols[name] = pa.array((np.asarray(cols[name]) * 1e9).astype("datetime64[ns]"))
    elif how == "bool":
        cols[name] = pa.array(np.ones(n, dtype=bool))
    elif how == "int":
        cols[name] = pa.array(np.arange(n, dtype=np.int64))
    return cols


@pytest.mark.parametrize("kind, column, how, message", [
    ("ultrasonic", "temperature_c", "timestamp", "'temperature_c' holds timestamp"),
    ("ultrasonic", "tof_R1_s", "bool", "'tof_R1_s' holds bool, not float numbers"),
    ("ultrasonic", "tof_R2_s", "int", "'tof_R2_s' holds int64, not float numbers"),
    ("ultrasonic", "t_s", "bool", "'t_s' holds bool"),
    ("scanlog", "t_s", "bool", "'t_s' holds bool"),
    ("scanlog", "t_s", "timestamp", "'t_s' holds timestamp"),
])
def test_wrong_column_types_are_refused(tmp_path, kind, column, how, message):
    cols, key, meta = _log_parts(kind)
    p = _write_log(tmp_path / f"x.{'scan' if kind == 'scanlog' else 'us'}.parquet",
                   _dtype_swap(cols, column, how), key, meta)
    read = read_scanlog if kind == "scanlog" else read_ultrasonic
    with pytest.raises(FileFormatError, match=message) as exc:
        read(p)
    assert str(p) in str(exc.value)


@pytest.mark.parametrize("kind, rows, message", [
    ("scanlog", 0, "holds 0 scans; at least 2"),
    ("scanlog", 1, "holds 1 scan; at least 2"),
    ("ultrasonic", 0, "holds 0 samples; at least 2"),
    ("ultrasonic", 1, "holds 1 sample; at least 2"),
])
def test_empty_and_one_row_logs_are_refused(tmp_path, kind, rows, message):
    import pyarrow as pa
    cols, key, meta = _log_parts(kind)
    tab = pa.table(cols).slice(0, rows)
    p = _write_log(tmp_path / f"x.{'scan' if kind == 'scanlog' else 'us'}.parquet",
                   {c: tab[c] for c in tab.column_names}, key, meta)
    read = read_scanlog if kind == "scanlog" else read_ultrasonic
    with pytest.raises(FileFormatError, match=message):
        read(p)


def test_times_that_never_advance_and_hot_air_are_refused(tmp_path):
    cols, key, meta = _log_parts("ultrasonic")
    cols["t_s"] = np.full(len(cols["t_s"]), 5.0)
    with pytest.raises(FileFormatError, match="never advances"):
        read_ultrasonic(_write_log(tmp_path / "a.us.parquet", cols, key, meta))
    cols, key, meta = _log_parts("ultrasonic")
    cols["temperature_c"] = cols["temperature_c"].copy()
    cols["temperature_c"][3] = 2.19e10
    with pytest.raises(FileFormatError, match="'temperature_c' holds 21900000000.0 degC at "
                                              "row 3"):
        read_ultrasonic(_write_log(tmp_path / "b.us.parquet", cols, key, meta))


def test_the_seed_logs_load(tmp_path):
    for kind, read in (("scanlog", read_scanlog), ("ultrasonic", read_ultrasonic)):
        cols, key, meta = _log_parts(kind)
        p = _write_log(tmp_path / f"x.{'scan' if kind == 'scanlog' else 'us'}.parquet",
                       cols, key, meta)
        assert len(read(p).t) == 20
