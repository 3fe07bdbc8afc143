"""Issue 11: the whole workflow on an MTST study with rater annotations and no mocap at all.

The study is derived from the tiny simulated one at test time: the tiny preset's MTST part
is simulated, and its trials' scan logs, annotation files and target layouts are copied
into a study folder whose trial sheet leaves ``mocap_file`` empty (:func:`build_study`).
Snakemake then runs it to a report: the MTST tables are built against the rater
annotations, no ingest or register job runs, and the TUG / rollator / ultrasonic parts
and the mocap-only study tables are absent.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

from gaitval.evaluate.mtst_tracking import CATEGORIES

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"
STUDY = "mtst_annot"
#: config mtst.methods (the paper's four, people and people_offline)
METHODS = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["mtst"]["methods"]


def build_study(out: Path, sim: Path | None = None) -> Path:
    """An annotations-only MTST study in ``out`` (returns its trial sheet).

    Parameters
    ----------
    out : Path
        Study folder (created): ``trials.csv`` (``mocap_file`` empty), ``subjects.csv``,
        ``study.yaml`` (``mtst``: mat, poles_m, targets; ``registration``: pole diameter),
        ``lrs/``, ``annotations/``, ``targets/``.
    sim : Path, optional
        Where the tiny preset's MTST part is simulated (default ``out.parent / "sim"``).

    Notes
    -----
    The sheet's ``clock_offset_s`` stands for the lab's hardware synchronisation of the
    sensor and video clocks; here it is the simulator's true offset (``truth/``), which a
    study without mocap cannot estimate itself.  Nothing else is taken from ``truth/``.
    """
    from gaitval.simulate import generate_study

    sim = Path(sim or out.parent / "sim")
    preset = yaml.safe_load((ROOT / "config" / "studies" / "tiny.yaml").read_text())
    preset = {k: v for k, v in preset.items() if k not in ("tug", "rollator", "ultrasonic")}
    generate_study(sim, preset)
    sheet = pd.read_csv(sim / "trials.csv", dtype=str, keep_default_na=False)
    sheet = sheet[sheet["protocol"] == "mtst"].copy()
    clock = pd.read_csv(sim / "truth" / "sensor_pose.csv").set_index("trial")["clock_offset_s"]
    sheet["study"] = STUDY
    sheet["mocap_file"] = ""
    sheet["clock_offset_s"] = [f"{clock[t]:.4f}" for t in sheet["trial"]]
    for col in ("sensor_file", "annotation_file"):
        for rel in sheet[col]:
            (out / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(sim / rel, out / rel)
    study = yaml.safe_load((sim / "study.yaml").read_text())
    targets = study["mtst"]["targets"]
    for t in sheet["trial"]:
        rel = targets.replace("{trial}", t)
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(sim / rel, out / rel)
    subjects = pd.read_csv(sim / "subjects.csv", dtype=str, keep_default_na=False)
    subjects[subjects["subject"].isin(sheet["subject"])].to_csv(out / "subjects.csv",
                                                                index=False)
    keep = {"mtst": study["mtst"], "registration": study["registration"]}
    (out / "study.yaml").write_text(yaml.safe_dump(keep, sort_keys=True))
    sheet.to_csv(out / "trials.csv", index=False)
    return out / "trials.csv"


def run_workflow(workdir: Path, configfile: Path, *extra: str) -> subprocess.CompletedProcess:
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(workdir),
           "--cores", "2", "--force-use-threads", "--configfile", str(configfile), *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


@pytest.fixture(scope="module")
def annot_run(tmp_path_factory):
    work = tmp_path_factory.mktemp("annot")
    sheet = build_study(work / "data" / STUDY)
    cf = work / "annot.yaml"
    cf.write_text(yaml.safe_dump({
        "studies": {STUDY: {"trial_sheet": str(sheet),
                            "subjects": str(sheet.parent / "subjects.csv")}},
        "run": [STUDY], "peer_results": ""}))
    res = run_workflow(work, cf)
    assert res.returncode == 0, res.stderr[-4000:]
    return work, res.stdout + res.stderr


@pytest.mark.slow
def test_mtst_tables_carry_rater_values_for_every_method(annot_run):
    work, _ = annot_run
    rd = work / "reports" / STUDY
    for name in ("mtst_table1.csv", "mtst_table3.csv", "mtst_table4.csv"):
        assert (rd / "tables" / name).is_file(), name
    assert (rd / "figures" / "mtst_trial.png").is_file()
    t3 = pd.read_csv(rd / "tables" / "mtst_table3.csv")
    assert sorted(t3["method"]) == sorted(METHODS)
    assert set(t3["reference"]) == {"rater events"}
    assert (t3["n_trials_no_stick"] + t3["n_trials_stick"] > 0).all()
    assert t3["success_pct"].notna().all()
    t1 = pd.read_csv(rd / "tables" / "mtst_table1.csv")
    assert t1["n_leg_scans"].sum() > 0
    t4 = pd.read_csv(rd / "tables" / "mtst_table4.csv").set_index("row")
    assert t4.loc["target_step", "n_trials"] > 0
    assert t4.loc["target_step", "success_pct"] > 0
    md3 = (rd / "tables" / "mtst_table3.md").read_text()
    assert "mocap truth: not available" in md3
    summaries = sorted((work / "results" / STUDY / "mtst_eval").glob("*/*/summary.parquet"))
    s = pd.concat([pd.read_parquet(p) for p in summaries])
    assert sorted(s["method"].unique()) == sorted(METHODS)
    assert not s["has_mocap"].astype(bool).any() and s["has_annotations"].astype(bool).all()
    assert s["category_annotations"].isin(CATEGORIES).all()


@pytest.mark.slow
def test_no_ingest_or_register_job_and_no_mocap_parts(annot_run):
    work, log = annot_run
    assert log.count("rule mtst_track:") == len(METHODS)     # the log names every job
    for rule in ("ingest", "register", "ingest_summary", "registration_summary", "track",
                 "rollator_track", "ultrasonic_noise"):
        assert f"rule {rule}:" not in log, rule
    assert not (work / "results" / STUDY / "ingest").exists()
    assert not (work / "results" / STUDY / "register").exists()
    rd = work / "reports" / STUDY
    index = (rd / "index.md").read_text()
    assert "### mtst_table3" in index and "### mtst_table4" in index
    for absent in ("study_ingest_", "study_registration_", "tug_", "rollator_",
                   "ultrasonic_"):
        assert f"### {absent}" not in index, absent
    assert "Not produced yet" not in index and "## TUG leg tracking" not in index
    verdicts = pd.read_csv(rd / "verdicts.csv").set_index("study")
    assert (verdicts.loc[["tug", "rollator", "ultrasonic"], "reproduced"] == "not run").all()
    assert verdicts.loc["mtst", "comparison"].str.contains("mocap truth: not available").any()
    assert not list((rd / "tables").glob("tug_*")) + list((rd / "tables").glob("rollator_*"))
