"""Issue 37: another system's heel trajectory (gaitval/io/foot.py, docs/formats_external.md "Foot
trajectories"): an exact round trip, the header's units and third-clock offset, one clear
error per kind of bad file, and a declaration that mixes the treadmill with leg
protocols refused."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import ConfigError, FileFormatError
from gaitval.io.foot import read_foot, ukf_track_to_foot, write_foot


def ukf_like(n: int = 50) -> pd.DataFrame:
    rng = np.random.default_rng(7)
    t = np.arange(n) * 0.02 + 3.0
    xyz = rng.normal(0.0, 0.3, (n, 3))
    xyz[:2] = np.nan                                # before the filter starts
    return pd.DataFrame({"t_s": t, "x_m": xyz[:, 0], "y_m": xyz[:, 1], "z_m": xyz[:, 2]})


@pytest.mark.parametrize("ext", ["csv", "parquet"])
def test_round_trip_is_exact(tmp_path, ext):
    track = ukf_like()
    p = write_foot(ukf_track_to_foot(track), tmp_path / f"a.foot.{ext}", source="test")
    rows, meta = read_foot(p)
    assert (meta["units"], meta["frame"], meta["clock"], meta["source"]) == \
        ("m", "sensor", "sensor", "test")
    pd.testing.assert_frame_equal(rows, track, check_exact=True)


def test_millimetres_and_third_clock(tmp_path):
    track = ukf_like()
    rows = ukf_track_to_foot(track)
    mm = rows.assign(t_s=rows["t_s"] + 500.0, x=rows["x"] * 1000, y=rows["y"] * 1000,
                     z=rows["z"] * 1000)
    p = write_foot(mm, tmp_path / "b.foot.csv", units="mm", clock="mocap",
                   clock_offset_s=-500.0)
    assert p.read_text().splitlines()[:5] == ["# gaitval-foot v1", "# units: mm",
                                              "# frame: sensor", "# clock: mocap",
                                              "# clock_offset_s: -500.0"]
    back, meta = read_foot(p)
    assert meta["clock"] == "mocap" and meta["clock_offset_s"] == -500.0
    np.testing.assert_allclose(back["t_s"], track["t_s"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(back["x_m"], track["x_m"], rtol=1e-12)


def _csv(tmp_path, lines):
    p = tmp_path / "bad.foot.csv"
    p.write_text("\n".join(lines) + "\n")
    return p


HEAD = ["# gaitval-foot v1", "# units: m", "# frame: sensor", "# clock: sensor"]
GOOD = ["t_s,x,y,z"] + [f"{0.02 * i:.2f},{0.1 * i:.1f},0.0,0.1" for i in range(12)]


@pytest.mark.parametrize("lines, words", [
    (["# gaitval-tracks v1"] + HEAD[1:] + GOOD, "line 1 is '# gaitval-tracks v1'"),
    (HEAD[:1] + HEAD[2:] + GOOD, "header field 'units' is missing"),
    (HEAD[:3] + ["# clock: watch"] + GOOD, "header field 'clock' is 'watch' (line 4)"),
    (HEAD + ["t_s,x,y"] + GOOD[1:], "line 6: 4 cells, the header has 3"),
    (HEAD + ["t_s,x,y,z,side"] + [r + ",L" for r in GOOD[1:]], "unknown column(s) 'side'"),
    (HEAD + ["t_s,x,y"] + [r.rsplit(",", 1)[0] for r in GOOD[1:]], "column 'z' is missing"),
    (HEAD + GOOD[:3] + ["0.02,1,1,1"] + GOOD[4:], "line 8: time stamp 0.02 s is not after"),
    (HEAD + GOOD[:2] + ["0.02,0.1,,0.1"] + GOOD[3:], "line 7: some of 'x', 'y', 'z' are empty"),
    (HEAD + GOOD[:2] + ["0.02,abc,0,0.1"] + GOOD[3:], "column 'x', line 7: 'abc' is not a number"),
    (HEAD + GOOD[:5], "4 rows with a position"),
    (HEAD + ["# clock_offset_s: later"] + GOOD, "'clock_offset_s' is 'later' (line 5)"),
])
def test_bad_file_one_clear_error(tmp_path, lines, words):
    p = _csv(tmp_path, lines)
    with pytest.raises(FileFormatError) as exc:
        read_foot(p, trial="us_S1_normal")
    msg = str(exc.value)
    assert words in msg and str(p) in msg and "trial us_S1_normal" in msg, msg


def test_wrong_extension_and_missing_file(tmp_path):
    with pytest.raises(FileFormatError, match="no such file"):
        read_foot(tmp_path / "none.foot.csv")
    q = tmp_path / "x.foot.txt"
    q.write_text("x")
    with pytest.raises(FileFormatError, match=r"\*\.foot\.csv or \*\.foot\.parquet"):
        read_foot(q)


@pytest.mark.parametrize("protocols, ok", [(["treadmill"], True), (["tug", "mtst"], True),
                                           (["treadmill", "tug"], False)])
def test_treadmill_entries_cover_no_other_protocol(protocols, ok):
    from gaitval.pipeline.steps.declarations import foot_entry_problem
    entry = {"path": "feet/{trial}.foot.csv", "protocols": protocols}
    if ok:
        foot_entry_problem("mine", entry)
        return
    with pytest.raises(ConfigError, match=r"external_methods\.mine\.protocols.*two methods"):
        foot_entry_problem("mine", entry)


def test_validate_deep_reads_heel_trajectories(tmp_path):
    """`gaitval validate --deep` on a study declaring a treadmill system reads its files:
    a missing one and a bad one are each named."""
    from gaitval.pipeline.steps.checks import external_problems
    sheet = tmp_path / "trials.csv"
    sheet.write_text("trial,protocol,mocap_path\nus_A_normal,treadmill,a.c3d\n"
                     "us_B_normal,treadmill,b.c3d\ntug_A,tug,c.c3d\n")
    (tmp_path / "study.yaml").write_text(
        'external_methods:\n  my_feet: {path: "feet/{trial}.foot.csv", '
        'protocols: [treadmill]}\n')
    (tmp_path / "feet").mkdir()
    (tmp_path / "feet" / "us_A_normal.foot.csv").write_text("\n".join(HEAD + GOOD) + "\n")
    probs = external_problems(sheet, deep=True)
    assert len(probs) == 1 and "1 of 2 trials' heel trajectories are missing" in probs[0]
    (tmp_path / "feet" / "us_B_normal.foot.csv").write_text(
        "\n".join(HEAD + GOOD[:2] + ["0.0,1,1,1"]) + "\n")
    probs = external_problems(sheet, deep=True)
    assert len(probs) == 1 and "us_B_normal" in probs[0] and "not after" in probs[0], probs


def _checked(tmp_path, rows, **head):
    from gaitval.io.foot import check_foot
    p = write_foot(rows, tmp_path / "c.foot.csv", **head)
    foot, meta = read_foot(p, trial="us_S1_normal")
    check_foot(foot, meta, t_range=(3.0, 3.9), tolerance_s=0.02,
               centre=np.array([0.0, 0.0, 0.0]), path=p, trial="us_S1_normal")
    return p


def test_heel_trajectory_inside_the_recording_and_in_metres(tmp_path):
    """The recording and units checks of an external system's heel trajectory: a file
    on another clock (no offset), in millimetres declared as metres, or in metres
    declared as millimetres is one error naming the file, the row and the header."""
    rows = ukf_track_to_foot(ukf_like()).fillna(0.1)     # 3.00-3.98 s, ~0.3 m from 0
    _checked(tmp_path, rows)                              # most stamps inside: accepted
    late = rows.assign(t_s=rows["t_s"] + 1.7e9)
    with pytest.raises(FileFormatError) as exc:
        _checked(tmp_path, late)
    msg = str(exc.value)
    for w in ("line 6, column 't_s'", "outside the recording", "sensor clock",
              "at least 10 must be inside", "trial us_S1_normal", "c.foot.csv"):
        assert w in msg, (w, msg)
    _checked(tmp_path, late, clock_offset_s=-1.7e9)       # the third clock's offset given
    mm = rows.assign(x=rows["x"] * 1000, y=rows["y"] * 1000, z=rows["z"] * 1000)
    with pytest.raises(FileFormatError, match=r"from the receivers' centre.*units 'm'"):
        _checked(tmp_path, mm)
    with pytest.raises(FileFormatError, match=r"within 2 cm of the receivers' centre"):
        _checked(tmp_path, rows, units="mm")


def test_export_tracks_writes_an_ultrasonic_track_as_a_heel_trajectory(tmp_path):
    """`gaitval export-tracks <ultrasonic track> OUT.foot.csv`: the UKF's trajectory, read
    back exactly (millimetres too); a leg track asked for as a foot file is refused."""
    from gaitval.cli import main

    track = ukf_like().assign(vx_mps=0.0)          # as the UKF writes it, extra columns
    src = tmp_path / "us_S1_normal.parquet"
    track.to_parquet(src)
    assert main(["export-tracks", str(src), str(tmp_path / "a.foot.csv")]) == 0
    rows, meta = read_foot(tmp_path / "a.foot.csv")
    pd.testing.assert_frame_equal(rows, track[["t_s", "x_m", "y_m", "z_m"]],
                                  check_exact=True)
    assert meta["source"] == "gaitval ultrasonic UKF"
    assert main(["export-tracks", str(src), str(tmp_path / "b.foot.parquet"),
                 "--units", "mm"]) == 0
    mm, meta = read_foot(tmp_path / "b.foot.parquet")
    assert meta["units"] == "mm"
    np.testing.assert_allclose(mm["x_m"], track["x_m"], rtol=1e-12)
    legs = tmp_path / "legs.parquet"
    pd.DataFrame({"t_sensor_s": [0.0], "k": [0], "side": ["L"], "x_m": [1.0],
                  "y_m": [0.0]}).to_parquet(legs)
    assert main(["export-tracks", str(legs), str(tmp_path / "c.foot.csv")]) == 1
