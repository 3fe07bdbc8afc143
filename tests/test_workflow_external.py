"""Issue 37: gaitval's own tracks, exported in the leg-track exchange format and declared as
external methods (``tracking.external``), give the same TUG Tables 3-5 and MTST Table 3
rows as the method they came from.

The tiny study's TUG and MTST parts are run once (Snakemake in a temporary folder); then
tug_m1's tracks (TUG trials) and mtst_m1's (MTST trials) are exported with
``gaitval export-tracks`` as CSV on the sensor clock in the sensor frame (``ext_m1``: exact
equality), and tug_m2's as Parquet in millimetres, in the mocap field frame and on the
mocap clock (``ext_m2``, TUG only: converted back with each trial's registration, time
stamps snapped to the scans they name; counts exact, errors equal to 1e-9).  tug_m2 has a tracking-success trial in the tiny study, so Tables 4-5 compare
RMSEs, not only empty rows.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from gaitval.io.tracks import track_to_exchange, write_tracks

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"
TARGETS = ["reports/tiny/tables/tug_table4.csv", "reports/tiny/tables/mtst_table3.csv"]


def snakemake(work: Path, *configfiles: Path) -> subprocess.CompletedProcess:
    cmd = [str(SNAKEMAKE), *TARGETS, "--snakefile", str(ROOT / "Snakefile"), "--directory",
           str(work), "--cores", "2", "--force-use-threads", "--configfile", *map(str, configfiles)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


def to_mocap(track: pd.DataFrame, reg: dict) -> pd.DataFrame:
    """Exchange rows of a sensor-frame track in the mocap frame (mm) and clock."""
    rows = track_to_exchange(track)
    c, s = math.cos(reg["yaw_rad"]), math.sin(reg["yaw_rad"])
    x, y, vx, vy = rows["x"], rows["y"], rows["vx"], rows["vy"]
    drift = 1.0 + (reg.get("clock_drift_ppm") or 0.0) * 1e-6
    return rows.assign(x=(c * x - s * y + reg["x_m"]) * 1000,
                       y=(s * x + c * y + reg["y_m"]) * 1000,
                       vx=(c * vx - s * vy) * 1000, vy=(s * vx + c * vy) * 1000,
                       t_s=(rows["t_s"] - reg["clock_offset_s"]) / drift)


@pytest.fixture(scope="module")
def ext_run(tmp_path_factory):
    work = tmp_path_factory.mktemp("ext")
    base = work / "base.yaml"
    base.write_text(yaml.safe_dump({"run": ["tiny"], "peer_results": ""}))
    res = snakemake(work, base)
    assert res.returncode == 0, res.stderr[-4000:]
    study = work / "data" / "tiny"
    results = work / "results" / "tiny"
    trials = sorted(p.stem for p in (results / "track" / "tug_m1").glob("*.parquet"))
    assert trials
    mtst = sorted(p.stem for p in (results / "mtst_track" / "mtst_m1").glob("*.parquet"))
    assert mtst
    for t in trials + mtst:
        src = (results / "track" / "tug_m1" if t in trials else
               results / "mtst_track" / "mtst_m1") / f"{t}.parquet"
        r = subprocess.run([sys.executable, "-m", "gaitval", "export-tracks", str(src),
                            str(study / "ext" / f"{t}.tracks.csv")],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
    for t in trials:
        reg = json.loads((results / "register" / t / "registration.json").read_text())
        track = pd.read_parquet(results / "track" / "tug_m2" / f"{t}.parquet")
        write_tracks(to_mocap(track, reg), study / "ext2" / f"{t}.tracks.parquet",
                     units="mm", frame="mocap", clock="mocap")
    ext = work / "ext.yaml"
    ext.write_text(yaml.safe_dump({"tracking": {"external": {
        "ext_m1": {"path": "ext/{trial}.tracks.csv"},
        "ext_m2": {"path": "ext2/{trial}.tracks.parquet", "protocols": ["tug"]}}}}))
    res = snakemake(work, base, ext)
    assert res.returncode == 0, res.stderr[-4000:]
    return work, res.stdout + res.stderr


def _rows(t: pd.DataFrame, method: str) -> pd.DataFrame:
    return t[t["method"] == method].reset_index(drop=True)


def _results(t: pd.DataFrame) -> list[str]:
    """The numeric result columns (not the paper's values beside them)."""
    return [c for c in t.columns if t[c].dtype.kind in "fiub"
            and not c.endswith("_published")]


@pytest.mark.slow
@pytest.mark.parametrize("ext, own, exact", [("ext_m1", "tug_m1", True),
                                             ("ext_m2", "tug_m2", False)])
def test_external_rows_equal_the_methods_rows(ext_run, ext, own, exact):
    work, log = ext_run
    tables = work / "reports" / "tiny" / "tables"
    # only the external methods' jobs and the tables ran the second time
    for rule in ("track", "register", "mtst_track"):
        assert f"rule {rule}:" not in log, rule
    assert "rule track_external:" in log and "rule mtst_track_external:" in log
    for n in (3, 4, 5):
        t = pd.read_csv(tables / f"tug_table{n}.csv")
        a, b = _rows(t, own), _rows(t, ext)
        assert len(a) and len(a) == len(b), n
        cols = _results(t)
        assert "n_success" in cols or "n_steps" in cols or "time_steps" in cols
        counts = [c for c in cols if not c.startswith(("rmse", "success_rate",
                                                       "occlusion_rate"))]
        pd.testing.assert_frame_equal(a[counts], b[counts], check_exact=True)
        pd.testing.assert_frame_equal(a[cols], b[cols], check_exact=exact, rtol=1e-9,
                                      atol=1e-12)
        if n == 4 and own == "tug_m2":       # a success trial: real RMSEs compared
            assert a["n_success_trials"].iloc[0] >= 1
            assert np.isfinite(b["rmse_x_m"]).all() and (b["n_steps"] > 0).all()
    t2 = pd.read_csv(tables / "tug_table2.csv")
    assert ext not in set(t2["method"])        # no parameters of gaitval's


@pytest.mark.slow
def test_mtst_external_rows_equal_the_methods_rows(ext_run):
    work, _ = ext_run
    t = pd.read_csv(work / "reports" / "tiny" / "tables" / "mtst_table3.csv")
    a, b = _rows(t, "mtst_m1"), _rows(t, "ext_m1")
    assert len(a) and len(a) == len(b)
    assert "ext_m2" not in set(t["method"])           # protocols: [tug]
    cols = _results(t)
    assert "success_pct" in cols and "n_trials_stick" in cols
    pd.testing.assert_frame_equal(a[cols], b[cols], check_exact=True)
    assert (a["success"] == b["success"]).all()


@pytest.mark.slow
def test_per_scan_evaluation_identical_for_the_csv_round_trip(ext_run):
    work, _ = ext_run
    ev = work / "results" / "tiny" / "evaluate"
    for p in sorted((ev / "tug_m1").glob("*/frames.parquet")):
        a = pd.read_parquet(p).drop(columns="method")
        b = pd.read_parquet(ev / "ext_m1" / p.parent.name / "frames.parquet")
        pd.testing.assert_frame_equal(a, b.drop(columns="method"), check_exact=True)


@pytest.mark.slow
@pytest.mark.parametrize("paper, names", [
    ("tug", ("tug_table3", "tug_table4", "tug_table5")), ("mtst", ("mtst_table3",))])
def test_verdicts_ignore_external_rows(ext_run, paper, names):
    from gaitval.report.verdicts import mtst_verdicts, tug_verdicts

    build = {"tug": tug_verdicts, "mtst": mtst_verdicts}[paper]
    work, _ = ext_run
    tables = work / "reports" / "tiny" / "tables"
    t = {n: pd.read_csv(tables / f"{n}.csv") for n in names}
    assert all(d["method"].str.startswith("ext_").any() for d in t.values())
    rows = build(t)
    text = json.dumps(rows, default=str)
    assert rows and "ext_m" not in text
    own = {n: d[~d["method"].str.startswith("ext_")] for n, d in t.items()}
    assert json.dumps(build(own), default=str) == text


@pytest.mark.slow
@pytest.mark.parametrize("where", ["config", "study.yaml"])
def test_external_method_declared_wrongly_stops_at_start(tmp_path, where):
    """A name that is already a method, or tracking.external in a study.yaml (where the
    workflow does not see it), stops the run before any job, naming the key."""
    sheet = tmp_path / "study" / "trials.csv"
    sheet.parent.mkdir()
    sheet.write_text("study\n")
    cf = tmp_path / "c.yaml"
    doc = {"run": ["mine"], "peer_results": "",
           "studies": {"mine": {"trial_sheet": str(sheet),
                                "subjects": str(sheet.parent / "subjects.csv")}}}
    if where == "config":
        doc["tracking"] = {"external": {"tug_m2": {"path": "x/{trial}.tracks.csv"}}}
        words = ["tracking.external.tug_m2", "already a tracking method"]
    else:
        (sheet.parent / "study.yaml").write_text(
            "tracking:\n  external:\n    mine: {path: 'x/{trial}.tracks.csv'}\n")
        words = ["study.yaml", "declared in the workflow config"]
    cf.write_text(yaml.safe_dump(doc))
    res = subprocess.run([str(SNAKEMAKE), "-n", "--snakefile", str(ROOT / "Snakefile"),
                          "--directory", str(tmp_path), "--cores", "1", "--force-use-threads", "--configfile",
                          str(cf)], capture_output=True, text=True, timeout=300)
    assert res.returncode != 0
    for w in words:
        assert w in res.stdout + res.stderr, (w, res.stderr[-2000:])
