"""A refused trial is loud: the README's report command (``run.py report``) on a lab's own
study built from real motion capture with six mistyped rows (``tests/own_study.py``:
millimetres, radians, x/y exchanged, yaw off by 180 degrees, another trial's pose, a clock
5 s off) ends with each of those trials refused and its probable cause named, a summary on
the console, exit code 3 and the count in the report's top box; ``--accept-refusals``
accepts them (exit 0); and the tables hold the analysed trials only."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

import own_study as O

ROOT = Path(__file__).resolve().parents[1]
CAUSES = {"mm": "millimetres", "rad": "radians", "swap": "x and y look exchanged",
          "yaw180": "180 degrees", "other": "copied",
          "clock": "clock offset in the sheet"}


def run_report(work: Path, sheet: Path, *extra: str) -> subprocess.CompletedProcess:
    cf = work / "own.yaml"
    cf.write_text(yaml.safe_dump({
        "studies": {O.STUDY: {"trial_sheet": str(sheet),
                              "subjects": str(sheet.parent / "subjects.csv")}},
        "run": [O.STUDY], "tug": {"methods": ["tug_m1"]}}))
    cmd = [sys.executable, str(ROOT / "run.py"), "report", "--directory", str(work),
           "--configfile", str(cf), *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=1500)


@pytest.mark.slow
def test_refused_trials_are_loud(replay_simulated, tmp_path):
    sim = replay_simulated
    sheet = O.build_mixed(sim, tmp_path / "data" / O.STUDY)
    res = run_report(tmp_path, sheet)
    out = res.stdout + res.stderr
    assert res.returncode == 3, out[-4000:]
    n = 3 + len(O.VARIANTS)
    assert f"analysed 3 of {n} trials; {len(O.VARIANTS)} refused" in out
    rep = tmp_path / "reports" / O.STUDY
    rec = json.loads((rep / "analysed.json").read_text())[O.STUDY]
    assert rec["trials"] == n and rec["analysed"] == 3
    for v, words in CAUSES.items():
        tid = f"{O.TARGET}_{v}"
        assert words in rec["refused"][tid]["reason"], (v, rec["refused"][tid])
        assert f"REFUSED {O.STUDY}/{tid}" in out
    top = (rep / "index.md").read_text().split("## Verdicts")[0]
    assert f"3 of {n} trials analysed; {len(O.VARIANTS)} refused at registration" in top
    # the tables hold the analysed trials only
    t3 = pd.read_csv(rep / "tables" / "tug_table3.csv")
    assert set(t3["n_trials"]) == {3}, t3[["method", "n_trials"]]
    assert "peer_agreement.csv" not in {p.name for p in (rep / "tables").iterdir()}
    # accepted: the same command with --accept-refusals exits 0 (nothing reruns)
    again = run_report(tmp_path, sheet, "--accept-refusals")
    assert again.returncode == 0, (again.stdout + again.stderr)[-3000:]
    assert f"analysed 3 of {n} trials" in again.stdout


@pytest.mark.slow
def test_the_correct_study_exits_0_with_every_trial_analysed(replay_simulated, tmp_path):
    sim = replay_simulated
    sheet = O.build(sim, tmp_path / "data" / O.STUDY, None)
    res = run_report(tmp_path, sheet)
    assert res.returncode == 0, (res.stdout + res.stderr)[-4000:]
    assert "analysed 3 of 3 trials" in res.stdout
    rec = json.loads((tmp_path / "reports" / O.STUDY / "analysed.json").read_text())
    assert rec[O.STUDY] == {"trials": 3, "analysed": 3, "refused": {}}
    top = (tmp_path / "reports" / O.STUDY / "index.md").read_text().split("## Verdicts")[0]
    assert "refused" not in top
