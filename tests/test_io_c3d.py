"""C3D loader and writer on real files (../shared/realdata/c3d) and round trips.

The independent reference is the pure-Python ``c3d`` package (0.6, test-only dependency),
read with its own frame loop: ``c3d.Reader(fh).read_frames()`` yields per frame an
``(n_points, 5)`` array ``x, y, z, residual, cameras`` in file units (integer files already
multiplied by |POINT:SCALE|, float files as stored), with residual -1 for invalid samples.
The reference route applies the same rules as gaitval: metres = file value * unit scale
(mm -> 1e-3), gap = residual < 0 or all three coordinates exactly zero.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.io.c3d import describe_c3d, read_c3d, write_c3d

pytestmark = pytest.mark.realdata

PIG16 = ["LASI", "RASI", "LPSI", "RPSI", "LTHI", "RTHI", "LKNE", "RKNE",
         "LTIB", "RTIB", "LANK", "RANK", "LHEE", "RHEE", "LTOE", "RTOE"]

# realdata/README.md table: file -> (rate Hz, frame count or None when not given, labels
# the README says are in the file)
README = {
    "FunctionalWalk.c3d": (120.0, 438, ["SACR", "LKNEin", "LANKin", "LFEO", "LTIO"] + [
        m for m in PIG16 if m not in ("LPSI", "RPSI")] + ["LPSI", "RPSI"]),
    "FunctionalStatic.c3d": (120.0, None, ["LKNE", "RKNE"]),
    "PiG_Motion-FlatFoot-Full.c3d": (100.0, 315, PIG16),
    "PiG_Motion-FlatFoot-Hole.c3d": (100.0, 320, PIG16),
    "PiG_Calibration-FlatFoot-Full.c3d": (100.0, None, PIG16),
    "c3dorg_sample09_PlugInC3D.c3d": (60.0, None, ["LTIB", "LFEO", "LTIO"]),
    "c3dorg_sample04_sub_labels.c3d": (60.0, None, ["LKNE", "C7"]),
    "c3dorg_sample01_Eb015pi.c3d": (50.0, None, ["RFT1", "RSK1"]),
    "Gait_MotionAnalysis.c3d": (100.0, None, ["RKNE", "RANK"]),
    "opensim_walking2.c3d": (250.0, 1249, ["LTB1", "LTB2", "LTB3", "LLFC", "LMFC",
                                           "LKJC", "LAJC"]),
}
FILES = sorted(README)
BAD = {
    # file -> words the reason must contain.  realdata/README.md lists what ezc3d says; for
    # the two corrupt parameter sections gaitval's own pre-check names the broken record
    # before ezc3d spends ~30 s on them.
    "c3dorg_sample02_sgi_int.c3d": "MIPS",
    "c3dorg_sample18_bad_parameter_section.c3d": "parameter section is corrupt",
    "badParameterOffset.c3d": "bad parameter offset",
    "c3dorg_sample13_Dance.c3d": "OFFSET",
}


@pytest.fixture(scope="module")
def loaded(realdata):
    """Every readable real C3D read once by gaitval (module cache)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {f: read_c3d(realdata / "c3d" / f) for f in FILES}


def reference(path: Path):
    """(labels, xyz metres with NaN gaps, first_frame, rate) by the ``c3d`` package."""
    import c3d

    scale = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
    with open(path, "rb") as fh, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = c3d.Reader(fh)
        units = r.get("POINT:UNITS").string_value.strip("\x00 ").lower() or "mm"
        frames = [p.copy() for _, p, _ in r.read_frames()]
        labels = [s.strip("\x00 ") for s in r.point_labels][: r.point_used]
        first, rate = r.first_frame, r.point_rate
    pts = np.stack(frames)                                   # (n_frames, n_points, 5)
    xyz = pts[:, :, :3].astype(np.float64) * scale[units]
    gap = (pts[:, :, 3] < 0) | np.all(pts[:, :, :3] == 0, axis=2)
    xyz[gap] = np.nan
    return labels, xyz, first, rate, pts[:, :, 3] < 0


@pytest.mark.parametrize("name", FILES)
def test_real_file_header_values(loaded, name):
    rate, n_frames, must_have = README[name]
    tr = loaded[name]
    assert tr.rate_hz == rate
    if n_frames is not None:
        assert tr.n_frames == n_frames
    assert tr.units == "mm"
    assert set(must_have) <= set(tr.labels)
    assert tr.xyz.shape == (tr.n_frames, len(tr.labels), 3)
    assert all(":" not in lab for lab in tr.labels)
    # time convention: t[i] = (first_frame - 1 + i) / rate
    assert tr.t[0] == pytest.approx((tr.first_frame - 1) / rate)
    assert np.allclose(np.diff(tr.t), 1 / rate)


def _floats(buf: np.ndarray, dec: bool) -> np.ndarray:
    """float32 words; DEC floats: swap the two 16-bit halves and divide by 4 (valid for
    normal numbers; the C3D guide's DEC -> IEEE rule)."""
    b = np.ascontiguousarray(buf, dtype=np.uint8).reshape(-1, 4)
    if dec:
        b = b[:, [2, 3, 0, 1]]
    f = np.frombuffer(b.tobytes(), "<f4").astype(np.float64)
    return f / 4.0 if dec else f


def header_route(path: Path):
    """Second reference without any C3D library: the 512-byte header + the data blocks.

    C3D User Guide (Motion Lab Systems), header words (1-based, 16-bit, little endian for
    Intel and DEC): 2 = number of 3-D points, 3 = analog measurements per 3-D frame, 4/5 =
    first/last frame, 7-8 = scale factor (float; negative = float data), 9 = first data
    block.  Processor type: byte 4 of the parameter section (84 Intel, 85 DEC).  Each frame:
    points (x, y, z, residual/camera word) then analogs; residual word < 0 = invalid.
    Returns (xyz metres with NaN gaps, first_frame); all real files here are in mm.
    """
    b = np.frombuffer(path.read_bytes(), np.uint8)
    dec = b[(int(b[0]) - 1) * 512 + 3] == 85
    w = b[:20].view("<i2")
    n_pts, n_an = int(w[1]), int(w[2])
    first, last = int(w[3]) & 0xFFFF, int(w[4]) & 0xFFFF
    scale = float(_floats(b[12:16], dec)[0])
    start = (int(b[16:18].view("<u2")[0]) - 1) * 512
    n = last - first + 1
    per = 4 * n_pts + n_an                                      # words per frame
    if scale < 0:
        words = _floats(b[start: start + 4 * n * per], dec).reshape(n, per)
        pts = words[:, : 4 * n_pts].reshape(n, n_pts, 4)
        xyz = pts[:, :, :3].copy()
        resid = pts[:, :, 3]
    else:
        words = b[start: start + 2 * n * per].view("<i2").reshape(n, per)
        pts = words[:, : 4 * n_pts].reshape(n, n_pts, 4).astype(np.float64)
        xyz = pts[:, :, :3] * abs(scale)
        resid = pts[:, :, 3]
    xyz *= 1e-3
    gap = (resid < 0) | np.all(xyz == 0, axis=2)
    xyz[gap] = np.nan
    return xyz, first


@pytest.mark.parametrize("name", FILES)
def test_values_agree_with_header_route(loaded, realdata, name):
    tr = loaded[name]
    xyz, first = header_route(realdata / "c3d" / name)
    assert tr.first_frame == first
    assert np.array_equal(np.isnan(tr.xyz), np.isnan(xyz))
    ok = ~np.isnan(xyz)
    assert np.max(np.abs(tr.xyz[ok] - xyz[ok])) < 1e-5          # 0.01 mm


# the c3d package (0.6) refuses this file: "Parameter already exists with key BODYMASS"
C3D_PKG_FAILS = {"PiG_Calibration-FlatFoot-Full.c3d"}


@pytest.mark.parametrize("name", [f for f in FILES if f not in C3D_PKG_FAILS])
def test_values_agree_with_c3d_package(loaded, realdata, name):
    tr = loaded[name]
    labels, xyz, first, rate, _ = reference(realdata / "c3d" / name)
    ref = [lab.rsplit(":", 1)[-1].strip() or f"POINT{k + 1}" for k, lab in enumerate(labels)]
    undo = {new: old for old, news in tr.meta["duplicates"].items() for new in news}
    assert [undo.get(lab, lab) for lab in tr.labels] == ref
    assert tr.first_frame == first
    assert tr.rate_hz == pytest.approx(rate)
    assert np.array_equal(np.isnan(tr.xyz), np.isnan(xyz))
    ok = ~np.isnan(xyz)
    assert np.max(np.abs(tr.xyz[ok] - xyz[ok])) < 1e-5          # 0.01 mm


def test_gap_file_nan_exactly_where_residual_negative(loaded, realdata):
    name = "PiG_Motion-FlatFoot-Hole.c3d"
    tr = loaded[name]
    _, _, _, _, invalid = reference(realdata / "c3d" / name)
    nan = np.isnan(tr.xyz[:, :, 0])
    assert np.array_equal(nan, invalid)                         # this file has no all-zero gaps
    assert np.all(np.isnan(tr.xyz[nan]))                       # all three coordinates
    assert 0.05 < nan.mean() < 0.15                             # README: about 10 % missing
    assert tr.meta["n_zero_gaps"] == 0


def test_subject_prefix_stripped(loaded):
    tr = loaded["c3dorg_sample04_sub_labels.c3d"]
    assert tr.meta["prefixes"] == ["Matt:"]
    assert tr.meta["original_labels"][tr.labels.index("LKNE")] in ("Matt:LKNE", "LKNE")
    assert "Matt:C7" in tr.meta["original_labels"]
    assert {"C7", "RTIB", "LTOE"} <= set(tr.labels)
    assert {"N", "RS", "LS"} <= set(tr.labels)                 # unprefixed extras kept
    assert len(set(tr.labels)) == len(tr.labels)


def test_duplicates_kept_with_suffix_and_recorded(loaded, realdata):
    tr = loaded["Gait_MotionAnalysis.c3d"]
    dup = tr.meta["duplicates"]
    assert set(dup) == {"RKNE", "RANK", "LKNE", "LANK", "RFOO", "LFOO"}
    assert dup["RKNE"] == ["RKNE", "RKNE#2"]
    assert len(set(tr.labels)) == len(tr.labels)
    # not merged: the two RKNE are different markers, each equal to its own file column
    labels, xyz, *_ = reference(realdata / "c3d" / "Gait_MotionAnalysis.c3d")
    cols = [i for i, lab in enumerate(labels) if lab == "RKNE"]
    assert np.allclose(tr.marker("RKNE"), xyz[:, cols[0]], equal_nan=True)
    assert np.allclose(tr.marker("RKNE#2"), xyz[:, cols[1]], equal_nan=True)
    assert np.nanmax(np.abs(tr.marker("RKNE") - tr.marker("RKNE#2"))) > 0.01
    with pytest.raises(FileFormatError, match="RKNE") as exc:
        read_c3d(realdata / "c3d" / "Gait_MotionAnalysis.c3d", duplicates="error",
                 trial="T7")
    assert "Gait_MotionAnalysis.c3d" in str(exc.value) and "T7" in str(exc.value)


@pytest.mark.parametrize("name,n_events", [("FunctionalWalk.c3d", 11),
                                           ("PiG_Motion-FlatFoot-Full.c3d", 12),
                                           ("PiG_Motion-FlatFoot-Hole.c3d", 10)])
def test_events_on_the_trial_time_base(loaded, realdata, name, n_events):
    import c3d

    tr = loaded[name]
    ev = tr.events
    assert list(ev.columns) == ["context", "label", "t_s"]
    assert len(ev) == n_events
    assert set(ev["context"]) <= {"Left", "Right", "General"}
    assert set(ev["label"]) <= {"Foot Strike", "Foot Off", "Event"}
    assert ev["t_s"].is_monotonic_increasing
    # events lie within the stored frames: C3D event times and MocapTrial.t share frame 1 = 0 s
    assert ev["t_s"].min() >= tr.t[0] - 1e-6 and ev["t_s"].max() <= tr.t[-1] + 1e-6
    with open(realdata / "c3d" / name, "rb") as fh, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        times = c3d.Reader(fh).get("EVENT:TIMES")
        raw = np.asarray(times.float_array, dtype=np.float64).reshape(-1, 2)
    ref = np.sort(60.0 * raw[:, 0] + raw[:, 1])                # minutes*60 + seconds
    assert np.allclose(ev["t_s"].to_numpy(), ref[:n_events], atol=1e-6)


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_files_give_one_clear_error(realdata, name):
    with pytest.raises(FileFormatError) as exc:
        read_c3d(realdata / "c3d-bad" / name, trial="S01_T1")
    msg = str(exc.value)
    assert name in msg and "S01_T1" in msg and BAD[name] in msg
    with pytest.raises(FileFormatError):
        describe_c3d(realdata / "c3d-bad" / name)


def test_truncated_missing_and_non_c3d(realdata, tmp_path):
    data = (realdata / "c3d" / "FunctionalWalk.c3d").read_bytes()
    (tmp_path / "cut.c3d").write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(FileFormatError, match="truncated"):
        read_c3d(tmp_path / "cut.c3d")
    (tmp_path / "cut2.c3d").write_bytes(data[:20000])          # inside the parameters
    with pytest.raises(FileFormatError, match="cut2.c3d"):
        read_c3d(tmp_path / "cut2.c3d")
    (tmp_path / "notes.c3d").write_text("not a c3d file\n" * 50)
    with pytest.raises(FileFormatError, match="not a C3D file"):
        read_c3d(tmp_path / "notes.c3d")
    with pytest.raises(FileFormatError, match="not found"):
        read_c3d(tmp_path / "absent.c3d")


# -- writer round trips ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def written(tmp_path_factory):
    rng = np.random.default_rng(7)
    xyz = rng.uniform(-3, 3, size=(120, 4, 3))
    xyz[10:14, 1, :] = np.nan                                  # a gap
    xyz[50, 3, 2] = np.nan                                     # one coordinate -> whole gap
    ev = pd.DataFrame({"context": ["Left", "Right", "Left"],
                       "label": ["Foot Strike", "Foot Off", "Foot Strike"],
                       "t_s": [0.33, 0.5, 1.01]})
    d = tmp_path_factory.mktemp("c3d")
    p = write_c3d(d / "sim.c3d", ["LKNE", "RKNE", "POLE1", "TX"], xyz, 100.0, events=ev,
                  first_frame=31, subject_prefix="S01")
    return p, xyz, ev


def test_roundtrip_values_gaps_events(written):
    p, xyz, ev = written
    tr = read_c3d(p)
    assert tr.labels == ["LKNE", "RKNE", "POLE1", "TX"]
    assert tr.meta["prefixes"] == ["S01:"]
    assert tr.rate_hz == 100.0 and tr.first_frame == 31 and tr.units == "mm"
    gap = ~np.all(np.isfinite(xyz), axis=2)
    assert np.array_equal(np.isnan(tr.xyz[:, :, 0]), gap)
    assert np.max(np.abs(tr.xyz[~gap] - xyz[~gap])) < 1e-6    # float32 mm on disk
    assert list(tr.events["label"]) == list(ev["label"])
    assert list(tr.events["context"]) == list(ev["context"])
    assert np.allclose(tr.events["t_s"], ev["t_s"], atol=1e-6)


def test_roundtrip_file_is_mm_with_vicon_gaps(written):
    import c3d

    p, xyz, _ = written
    with open(p, "rb") as fh, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = c3d.Reader(fh)
        assert r.get("POINT:UNITS").string_value.strip() == "mm"
        assert r.first_frame == 31
        pts = np.stack([q.copy() for _, q, _ in r.read_frames(check_nan=False)])
    assert np.allclose(pts[0, 0, :3], xyz[0, 0] * 1000.0, atol=1e-3)
    assert np.all(pts[10:14, 1, 3] == -1) and np.all(pts[10:14, 1, :3] == 0)
    assert pts[50, 3, 3] == -1
    assert np.all(pts[:10, 1, 3] >= 0)


def test_writer_is_deterministic_and_atomic(written, tmp_path):
    p, xyz, ev = written
    q = write_c3d(tmp_path / "again.c3d", ["LKNE", "RKNE", "POLE1", "TX"], xyz, 100.0,
                  events=ev, first_frame=31, subject_prefix="S01")
    assert p.read_bytes() == q.read_bytes()
    assert [f.name for f in tmp_path.iterdir()] == ["again.c3d"]   # no temp files left
    with pytest.raises(ValueError):
        write_c3d(tmp_path / "bad.c3d", ["A"], np.zeros((3, 2, 3)), 100.0)
    assert not (tmp_path / "bad.c3d").exists()


def test_first_frame_above_16_bits(tmp_path):
    xyz = np.zeros((5, 1, 3)) + 0.5
    p = write_c3d(tmp_path / "late.c3d", ["TX"], xyz, 200.0, first_frame=70001)
    tr = read_c3d(p)
    assert tr.first_frame == 70001
    assert tr.t[0] == pytest.approx(70000 / 200.0)


def test_describe_c3d_key_numbers(realdata):
    d = describe_c3d(realdata / "c3d" / "FunctionalWalk.c3d")
    assert (d["kind"], d["rate_hz"], d["n_frames"], d["units"]) == ("c3d", 120.0, 438, "mm")
    assert d["first_frame"] == 480 and d["last_frame"] == 917
    assert d["duration_s"] == pytest.approx(438 / 120)
    assert len(d["events"]) == 11 and d["events_source"] == "EVENT"
    assert d["n_markers"] == len(d["labels"]) and "LFEO" in d["labels"]
    assert all(isinstance(v, int) and v > 0 for v in d["gaps"].values())
    d4 = describe_c3d(realdata / "c3d" / "c3dorg_sample04_sub_labels.c3d")
    assert d4["prefix_stripped"] and d4["prefixes"] == ["Matt:"]
    dd = describe_c3d(realdata / "c3d" / "Gait_MotionAnalysis.c3d")
    assert dd["duplicates"]["LFOO"] == ["LFOO", "LFOO#2"]


# -- issue 33: sizes, rates and counts checked before ezc3d reads; text encodings ------------

def _set_param(data: bytes, group: str, name: str, value) -> bytes:
    """``data`` with the first value of parameter ``group:name`` replaced (its own type)."""
    import struct

    from gaitval.io.c3d_params import parse_parameters
    b = bytearray(data)
    ps, ds = (b[0] - 1) * 512, (int.from_bytes(b[16:18], "little") - 1) * 512
    p = parse_parameters(bytes(b[:ds]), ps, ds)[(group, name)]
    struct.pack_into({4: "<f", 2: "<h", 1: "<b"}[p.type], b, p.offset, value)
    return bytes(b)


@pytest.mark.parametrize("group, name, value, message", [
    ("ANALOG", "RATE", 3e9, "ANALOG:RATE is 3000000000.0 Hz; it must be at most 100,000 Hz"),
    ("POINT", "RATE", 3e9, "POINT:RATE is 3000000000.0 Hz; it must be above 0"),
    ("POINT", "RATE", 0.0, "POINT:RATE is 0.0"),
    ("POINT", "USED", 0, r"no markers \(POINT:USED is 0\)"),
    ("ANALOG", "RATE", 2000.0, "20 analog samples per frame, but the header says 10"),
    ("ANALOG", "USED", 37, r"ANALOG:USED \(37 channels\) x 10 samples per frame = 370"),
    ("POINT", "FRAMES", 40, "the header announces 94 frames"),
])
def test_issue33_reproducers_refused_quickly_naming_the_field(realdata, tmp_path, group, name,
                                                               value, message):
    """One parameter of a real PiG file changed: one clear error, before any allocation
    (ANALOG:RATE 3e9 used to make ezc3d allocate 15.5 GB for 69 s)."""
    import time

    from gaitval.cli import main
    src = realdata / "c3d" / "PiG_Calibration-FlatFoot-Full.c3d"
    path = tmp_path / f"{group}_{name}.c3d"
    path.write_bytes(_set_param(src.read_bytes(), group, name, value))
    t0 = time.monotonic()
    with pytest.raises(FileFormatError, match=message) as exc:
        read_c3d(path, trial="S01_T1")
    assert str(path) in str(exc.value) and "S01_T1" in str(exc.value)
    assert time.monotonic() - t0 < 2.0
    assert main(["inspect", str(path)]) == 1


def test_header_frame_count_below_the_stored_frames_is_refused(realdata, tmp_path):
    """A last-frame word cut to 4 used to load 4 of the 94 frames without a word."""
    b = bytearray((realdata / "c3d" / "PiG_Calibration-FlatFoot-Full.c3d").read_bytes())
    first = int.from_bytes(b[6:8], "little")
    b[8:10] = (first + 3).to_bytes(2, "little")
    b = bytearray(_set_param(bytes(b), "POINT", "FRAMES", 4))
    (tmp_path / "short.c3d").write_bytes(bytes(b))
    with pytest.raises(FileFormatError, match=r"announces 4 frames .* room for 94 frames"):
        read_c3d(tmp_path / "short.c3d")


def test_ezc3d_child_runs_under_an_address_space_limit():
    from gaitval.io.isolate import ChildError, run_isolated

    def hog(n):
        return len(bytearray(n))
    assert run_isolated(hog, 1 << 20, path="x.c3d", trial=None, what="t", timeout_s=30,
                        memory_bytes=256 << 20) == 1 << 20
    with pytest.raises(ChildError) as exc:
        run_isolated(hog, 2 << 30, path="x.c3d", trial=None, what="t", timeout_s=30,
                     memory_bytes=256 << 20)
    assert exc.value.type_name == "MemoryError"


def _analog_c3d(path: Path, units: str) -> None:
    """A small C3D with one analog channel whose ANALOG:UNITS is ``units`` (5 ASCII bytes
    that the caller patches)."""
    import ezc3d
    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [100]
    c["parameters"]["POINT"]["LABELS"]["value"] = ["A", "B", "C"]
    c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    c["parameters"]["ANALOG"]["RATE"]["value"] = [200]
    c["parameters"]["ANALOG"]["LABELS"]["value"] = ["acc"]
    c["parameters"]["ANALOG"]["UNITS"]["value"] = [units]
    rng = np.random.default_rng(0)
    pts = np.ones((4, 3, 50))
    pts[:3] = rng.normal(size=(3, 3, 50)) * 100 + np.array([0, 0, 1000])[:, None, None]
    c["data"]["points"] = pts
    c["data"]["analogs"] = rng.normal(size=(1, 1, 100))
    c.write(str(path))


def test_latin1_text_in_an_unused_parameter_loads(tmp_path):
    """ANALOG:UNITS "mm/s²" with ² as Latin-1 byte 0xB2 (as a real file of another lab
    holds it) used to be refused as "not UTF-8"; gaitval never reads analog channels."""
    from gaitval.io.inspect import describe, format_description
    _analog_c3d(tmp_path / "a.c3d", "mm/s2")
    data = (tmp_path / "a.c3d").read_bytes()
    assert data.count(b"mm/s2") == 1
    (tmp_path / "latin1.c3d").write_bytes(data.replace(b"mm/s2", b"mm/s\xb2"))
    tr = read_c3d(tmp_path / "latin1.c3d")
    assert tr.xyz.shape == (50, 3, 3) and tr.labels == ["A", "B", "C"]
    assert tr.meta["text_encodings"] == {"ANALOG:UNITS": "cp1252"}
    assert read_c3d(tmp_path / "a.c3d").meta["text_encodings"] == {}
    d = describe(tmp_path / "latin1.c3d")
    assert d["text_encodings"] == {"ANALOG:UNITS": "cp1252"}
    assert "ANALOG:UNITS cp1252" in format_description(d)


def test_latin1_marker_label_is_decoded(tmp_path):
    _analog_c3d(tmp_path / "a.c3d", "volts")
    data = (tmp_path / "a.c3d").read_bytes()
    tr = None
    from gaitval.io.c3d_params import parse_parameters
    ps, ds = (data[0] - 1) * 512, (int.from_bytes(data[16:18], "little") - 1) * 512
    p = parse_parameters(data[:ds], ps, ds)[("POINT", "LABELS")]
    b = bytearray(data)
    b[p.offset] = 0xC9                                          # "A" -> Latin-1 "É"
    (tmp_path / "label.c3d").write_bytes(bytes(b))
    tr = read_c3d(tmp_path / "label.c3d")
    assert tr.labels[0] == "É" and tr.meta["text_encodings"] == {"POINT:LABELS": "cp1252"}
