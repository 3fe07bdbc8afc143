"""Issue 37 scope 4: a sensor pose measured by hand, for a lab without calibration poles.

The tiny preset's TUG trials are copied into a study whose C3Ds have the POLE markers
removed and whose trial sheet gives the sensor pose by hand (``sensor_x_m``,
``sensor_y_m``, ``sensor_yaw_deg``: here the simulator's true pose, standing for a tape
measure).  Snakemake runs it to TUG Table 3; registration says ``manual`` and the
tracks are scored against ground truth built with that pose.  With the poles kept, the
same sheet's pose is checked against the pole fit and the difference recorded.
"""
from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from gaitval.io.c3d_read import read_c3d
from gaitval.io.c3d_write import write_c3d

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"
STUDY = "tug_by_hand"


def build_study(out: Path, *, drop_poles: bool) -> Path:
    from gaitval.simulate import generate_study

    sim = out.parent / "sim"
    if not (sim / "trials.csv").is_file():
        preset = yaml.safe_load((ROOT / "config" / "studies" / "tiny.yaml").read_text())
        preset = {k: v for k, v in preset.items()
                  if k not in ("mtst", "rollator", "ultrasonic")}
        generate_study(sim, preset)
    sheet = pd.read_csv(sim / "trials.csv", dtype=str, keep_default_na=False)
    sheet = sheet[sheet["protocol"] == "tug"].copy()
    pose = pd.read_csv(sim / "truth" / "sensor_pose.csv").set_index("trial")
    sheet["study"] = STUDY
    sheet["sensor_x_m"] = [f"{pose.loc[t, 'x_m']:.3f}" for t in sheet["trial"]]
    sheet["sensor_y_m"] = [f"{pose.loc[t, 'y_m']:.3f}" for t in sheet["trial"]]
    sheet["sensor_yaw_deg"] = [f"{math.degrees(pose.loc[t, 'yaw_rad']):.2f}"
                               for t in sheet["trial"]]
    for rel in sheet["sensor_file"]:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(sim / rel, out / rel)
    for rel in sheet["mocap_file"]:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        if not drop_poles:
            shutil.copy(sim / rel, out / rel)
            continue
        m = read_c3d(sim / rel)
        keep = [i for i, lb in enumerate(m.labels) if not lb.startswith("POLE")]
        assert len(keep) < len(m.labels)                  # the preset has poles to drop
        write_c3d(out / rel, [m.labels[i] for i in keep], m.xyz[:, keep, :], m.rate_hz,
                  events=m.events, first_frame=m.first_frame)
    shutil.copy(sim / "subjects.csv", out / "subjects.csv")
    sheet.to_csv(out / "trials.csv", index=False)
    return out / "trials.csv"


def run(work: Path, sheet: Path, *extra: str) -> subprocess.CompletedProcess:
    cf = work / "by_hand.yaml"
    cf.write_text(yaml.safe_dump({
        "studies": {STUDY: {"trial_sheet": str(sheet),
                            "subjects": str(sheet.parent / "subjects.csv")}},
        "run": [STUDY], "peer_results": ""}))
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(work),
           "--cores", "2", "--force-use-threads", "--configfile", str(cf), *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_a_study_without_poles_runs_on_a_hand_measured_pose(tmp_path):
    sheet = build_study(tmp_path / "data" / STUDY, drop_poles=True)
    res = run(tmp_path, sheet)
    assert res.returncode == 0, res.stderr[-4000:]
    regs = sorted((tmp_path / "results" / STUDY / "register").glob("*/*/registration.json"))
    assert regs
    truth = pd.read_csv(tmp_path / "data" / "sim" / "truth" / "sensor_pose.csv"
                        ).set_index("trial")
    for p in regs:
        r = json.loads(p.read_text())
        assert r["status"] == "ok", r["reason"]
        assert r["pose_source"] == "manual" and r["pole_residual_m"] is None
        t = truth.loc[r["trial"]]
        assert abs(r["x_m"] - t["x_m"]) < 1e-3 and abs(r["yaw_rad"] - t["yaw_rad"]) < 1e-3
    t3 = pd.read_csv(tmp_path / "reports" / STUDY / "tables" / "tug_table3.csv")
    assert len(t3) > 0
    summary = (tmp_path / "reports" / STUDY / "tables" / f"study_registration_{STUDY}.md")
    assert "manual" in summary.read_text()


@pytest.mark.slow
def test_with_poles_the_hand_measured_pose_is_checked_against_them(tmp_path):
    sheet = build_study(tmp_path / "data" / STUDY, drop_poles=False)
    res = run(tmp_path, sheet, "--until", "registration_summary")
    assert res.returncode == 0, res.stderr[-4000:]
    regs = sorted((tmp_path / "results" / STUDY / "register").glob("*/*/registration.json"))
    assert regs
    for p in regs:
        r = json.loads(p.read_text())
        assert r["pose_source"] == "poles"
        # the pole fit lands within centimetres and a degree of the true pose
        assert 0 <= r["manual_pose_diff_m"] < 0.05 and abs(r["manual_pose_diff_deg"]) < 1.0
    assert np.isfinite(pd.read_csv(tmp_path / "results" / STUDY / "registration.csv")
                       ["manual_pose_diff_m"]).all()
