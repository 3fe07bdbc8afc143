"""What a warm worker remembers of the files it read (gaitval.pipeline.memo, issue 13): a
file rewritten in any way is read again, and a caller can never change what the next
caller gets."""
from __future__ import annotations

import os

import numpy as np
import pandas as pd

import pytest

from gaitval.io.atomic import write_parquet
from gaitval.pipeline.memo import FileMemo
from gaitval.io.parquet import read_parquet
from gaitval.io.scanlog import read_scanlog, write_scanlog
from gaitval.pipeline.mtst import read_scans
from gaitval.types import ScanSeries


def _series(scale: float = 1.0) -> ScanSeries:
    r = np.random.default_rng(5).uniform(0.5, 6.0, size=(8, 13)) * scale
    return ScanSeries(t=np.arange(8) * 0.025, ranges=r, angle_min=-1.0, angle_increment=0.1,
                      range_min=0.1, range_max=30.0, sensor_model="test",
                      mounting_height_m=0.27)


def test_read_parquet_gives_what_pandas_reads(tmp_path):
    df = pd.DataFrame({"trial": ["a", "b", "c"], "x_m": [0.1, np.nan, -2.5],
                       "k": np.array([1, 2, 3], dtype=np.int64), "ok": [True, False, True]})
    p = write_parquet(df, tmp_path / "t.parquet")
    ours, theirs = read_parquet(p), pd.read_parquet(p)
    pd.testing.assert_frame_equal(ours, theirs)
    assert list(ours.dtypes) == list(theirs.dtypes)
    pd.testing.assert_frame_equal(read_parquet(p, ["x_m"]), pd.read_parquet(p, columns=["x_m"]))


def test_a_caller_changing_its_frame_does_not_change_the_next_read(tmp_path):
    p = write_parquet(pd.DataFrame({"x_m": [1.0, 2.0]}), tmp_path / "t.parquet")
    first = read_parquet(p)
    first.loc[0, "x_m"] = 99.0
    assert read_parquet(p)["x_m"].tolist() == [1.0, 2.0]


def test_a_rewritten_parquet_file_is_read_again(tmp_path):
    p = tmp_path / "t.parquet"
    write_parquet(pd.DataFrame({"x_m": [1.0]}), p)
    assert read_parquet(p)["x_m"].tolist() == [1.0]
    write_parquet(pd.DataFrame({"x_m": [2.0]}), p)          # atomic: a new file (inode)
    assert read_parquet(p)["x_m"].tolist() == [2.0]


@pytest.mark.parametrize("read", [read_scanlog, lambda p: read_scans(p, {"trial": "t"})],
                         ids=["io", "step"])
def test_a_scan_log_edited_in_place_is_read_again(tmp_path, read):
    p = write_scanlog(tmp_path / "a.scan.parquet", _series())
    before = read(p)
    other = write_scanlog(tmp_path / "b.scan.parquet", _series(1.1))
    data = other.read_bytes()
    st = os.stat(p)
    with open(p, "r+b") as fh:                              # same inode, new contents
        fh.write(data)
        fh.truncate()
    os.utime(p, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))
    after = read(p)
    assert not np.allclose(before.ranges, after.ranges)
    assert np.allclose(after.ranges, read_scanlog(other).ranges)


def test_a_scan_log_read_twice_by_a_step_gives_independent_equal_copies(tmp_path):
    p = write_scanlog(tmp_path / "a.scan.parquet", _series())
    a = read_scans(p, {"trial": "t"})
    a.ranges[:] = 0.0
    a.meta["range_unit"] = "changed"
    b = read_scans(p, {"trial": "t"})
    assert np.nanmin(b.ranges) > 0.4 and b.meta["range_unit"] == "mm"
    assert b.ranges is not read_scans(p, {"trial": "t"}).ranges
    assert np.array_equal(b.ranges, read_scanlog(p).ranges, equal_nan=True)


def test_the_memo_keeps_to_its_byte_budget_oldest_out_first(tmp_path):
    memo = FileMemo(100)
    keys = []
    for i in range(4):
        f = tmp_path / f"{i}.bin"
        f.write_bytes(b"x")
        keys.append(memo.key(f))
        memo.put(keys[-1], i, 40)
    assert [memo.get(k) for k in keys] == [None, None, 2, 3]
    memo.put(memo.key(tmp_path / "0.bin"), "big", 101)      # over the budget: not kept
    assert memo.get(memo.key(tmp_path / "0.bin")) is None
    assert memo.key(tmp_path / "missing") is None and memo.get(None) is None


def test_annotations_read_twice_by_a_step_are_independent_copies(tmp_path):
    from gaitval.io.annotations import write_annotations
    from gaitval.pipeline.mtst import _annotations

    ev = pd.DataFrame({"t_s": [1.0, 2.5], "event": ["contact", "contact"], "side": ["L", "R"]})
    p = write_annotations(tmp_path / "a.annotations.csv", ev, time_offset_s=0.5)
    row, s = {"annotation_path": str(p)}, {"require_annotations": True}
    a, meta, _ = _annotations(row, s, "t1", tmp_path / "trials.csv")
    a.loc[0, "t_s"] = -1.0
    meta["rater"] = "changed"
    b, meta_b, _ = _annotations(row, s, "t1", tmp_path / "trials.csv")
    assert b["t_s"].tolist() == [1.0, 2.5] and b["t_mocap_s"].tolist() == [1.5, 3.0]
    assert meta_b["rater"] == "R1"


def test_a_target_layout_without_the_trial_is_none_or_an_error_as_asked(tmp_path):
    """The layout is remembered per trial and per `required`: a file without the trial's
    targets gives None when targets are optional, and still the error when they are not."""
    import pytest

    from gaitval.errors import FileFormatError
    from gaitval.pipeline.mtst import load_targets

    (tmp_path / "targets.csv").write_text(
        "trial,target,x_m,y_m,color,assigned\nother,T1,0.5,0.2,red,true\n")
    s = {"targets": "targets.csv"}
    sheet = tmp_path / "trials.csv"
    assert load_targets(s, sheet, "mine", required=False) is None
    assert load_targets(s, sheet, "mine", required=False) is None
    with pytest.raises(FileFormatError, match="no targets for this trial"):
        load_targets(s, sheet, "mine", required=True)
    got = load_targets(s, sheet, "other", required=True)
    got.loc[0, "x_m"] = 9.0
    assert load_targets(s, sheet, "other", required=True)["x_m"].tolist() == [0.5]
