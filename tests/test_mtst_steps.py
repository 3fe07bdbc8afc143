"""The MTST steps (gaitval.pipeline.mtst) on the tiny simulated study: with mocap, on a trial
sheet with annotations only (no mocap: poles from study.yaml, clock from the sheet), the
bad inputs of issue 11 Scope 7, and the published values against the seed text."""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pandas as pd
import pytest
import yaml

from gaitval.errors import ConfigError, FileFormatError
from gaitval.pipeline.steps.config import ANALYSIS_SECTIONS, study_config
from gaitval.pipeline.steps.register import register_step
from gaitval.pipeline.mtst import (keep_every, load_targets, mtst_evaluate_step,
                                mtst_tables_step, mtst_track_step)

ROOT = Path(__file__).resolve().parents[1]
TRIAL = "mtst_E01_t1"
METHOD = "mtst_proposed"


@pytest.fixture(scope="module")
def tiny(tiny_simulated, tmp_path_factory):
    from gaitval.io.ingest import ingest_trial
    from gaitval.io.trialsheet import load_trial_sheet

    out = tmp_path_factory.mktemp("mtst")
    study = out / "tiny"
    study.symlink_to(tiny_simulated, target_is_directory=True)   # read only here
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    cj = out / "config.json"
    study_config({k: cfg[k] for k in ANALYSIS_SECTIONS if k in cfg}, study / "trials.csv", cj)
    row = load_trial_sheet(study / "trials.csv").loc[TRIAL].to_dict()
    ingest_trial(row, out / "ingest")
    register_step(out / "ingest", study / "trials.csv", study / "subjects.csv", TRIAL, cj,
                  out / "register")
    return out


def _run(tiny, sheet, cj, reg, gt, name):
    subjects = tiny / "tiny" / "subjects.csv"
    sensor = Path(sheet).parent / "lrs" / f"{TRIAL}.scan.parquet"
    track = tiny / name / "track.parquet"
    mtst_track_step(sensor, sheet, subjects, TRIAL, METHOD, cj, reg, track)
    return mtst_evaluate_step(track, sheet, subjects, TRIAL, METHOD, cj, reg, gt,
                              tiny / name / "eval").iloc[0]


@pytest.mark.slow
def test_the_steps_run_with_mocap_and_render_the_tables(tiny):
    s = _run(tiny, tiny / "tiny" / "trials.csv", tiny / "config.json",
             tiny / "register" / "registration.json", tiny / "register" / "groundtruth.parquet",
             "mocap")
    assert s["has_mocap"] and s["has_annotations"] and s["has_targets"]
    assert s["category_mocap"] == "success" and s["category_annotations"] == "success"
    assert s["n_steps"] > 10 and s["non_judgement"] == 0
    paths = mtst_tables_step([tiny / "mocap" / "eval"], tiny / "rep" / "tables",
                             tiny / "rep" / "figures", tiny / "rep", methods=[METHOD],
                             config_json=tiny / "config.json")
    names = {p.name for p in paths}
    assert {"mtst_table1.csv", "mtst_table3.csv", "mtst_table4.csv", "mtst_trial.png"} <= names
    t1 = pd.read_csv(tiny / "rep" / "tables" / "mtst_table1.csv")
    assert t1["n_leg_scans"].sum() > 0 and len(t1) == 4


def test_a_trial_sheet_with_annotations_only(tiny):
    """No mocap: pose from mtst.poles_m (study.yaml, written by the simulator), clock from
    the sheet's clock_offset_s; the rater verdict and the judgements are still there."""
    study = tiny / "nomocap"
    shutil.copytree(tiny / "tiny", study, ignore=shutil.ignore_patterns("mocap", "truth"))
    sheet = pd.read_csv(study / "trials.csv", dtype=str, keep_default_na=False)
    sheet = sheet[sheet["trial"] == TRIAL]
    rec = json.loads((tiny / "register" / "registration.json").read_text())
    sheet["clock_offset_s"] = f"{rec['clock_offset_s']:.6f}"   # the lab's synchronisation
    sheet.to_csv(study / "trials.csv", index=False)
    cj = tiny / "nomocap.json"
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    study_config({k: cfg[k] for k in ANALYSIS_SECTIONS if k in cfg}, study / "trials.csv", cj)
    s = _run(tiny, study / "trials.csv", cj, None, None, "nomocap_run")
    assert not s["has_mocap"] and s["category_mocap"] == ""
    assert s["category_annotations"] == "success" and s["n_steps"] > 10


def test_bad_inputs_name_the_file_and_trial(tiny, tmp_path):
    study = tmp_path / "bad"
    shutil.copytree(tiny / "tiny", study, ignore=shutil.ignore_patterns("mocap", "truth",
                                                                        "ultrasonic"))
    s = {"targets": "targets/{trial}.targets.csv"}
    (study / "targets" / f"{TRIAL}.targets.csv").unlink()
    with pytest.raises(FileFormatError, match=rf"\[file .*{TRIAL}.targets.csv, trial "
                                              rf"{TRIAL}\] target layout file not found"):
        load_targets(s, study / "trials.csv", TRIAL, required=True)
    assert load_targets(s, study / "trials.csv", TRIAL, required=False) is None
    with pytest.raises(ConfigError, match=rf"trial {TRIAL}\] no target layout"):
        load_targets({"targets": None}, study / "trials.csv", TRIAL, required=True)
    shutil.copy(tiny / "tiny" / "targets" / f"{TRIAL}.targets.csv", study / "targets")
    # an annotation file with an event type an MTST evaluation does not know
    ann = study / "annotations" / f"{TRIAL}.annotations.csv"
    text = ann.read_text()
    ann.write_text(re.sub(r",foot_contact,", ",heel_rise,", text, count=1))
    track = tiny / "mocap" / "track.parquet"
    if not track.is_file():
        pytest.skip("needs the mocap run's track")
    with pytest.raises(FileFormatError, match=rf"annotations.csv, trial {TRIAL}\] unknown "
                                              "annotation event type"):
        mtst_evaluate_step(track, study / "trials.csv", study / "subjects.csv", TRIAL, METHOD,
                           tiny / "config.json", tiny / "register" / "registration.json",
                           None, tmp_path / "e")
    # a trial without annotations
    sheet = pd.read_csv(study / "trials.csv", dtype=str, keep_default_na=False)
    sheet.loc[sheet["trial"] == TRIAL, "annotation_file"] = ""
    sheet.to_csv(study / "trials.csv", index=False)
    with pytest.raises(FileFormatError, match=rf"trials.csv, trial {TRIAL}\] the MTST trial "
                                              "has no rater annotations"):
        mtst_evaluate_step(track, study / "trials.csv", study / "subjects.csv", TRIAL, METHOD,
                           tiny / "config.json", tiny / "register" / "registration.json",
                           None, tmp_path / "e")


def test_a_40hz_log_keeps_every_second_scan():
    import numpy as np

    from gaitval.types import ScanSeries
    t = np.arange(0, 2, 0.025)
    scans = ScanSeries(t=t, ranges=np.zeros((len(t), 3)), angle_min=0.0, angle_increment=0.1,
                       range_min=0.1, range_max=30.0)
    kept = keep_every(scans, 0.05, trial="T")
    assert np.allclose(np.diff(kept.t), 0.05) and kept.n_scans == len(t) // 2
    assert keep_every(kept, 0.05, trial="T") is kept


def test_published_values_match_the_seed_text():
    """Tables 3 and 4 as transcribed, against the seed text's own cells."""
    from gaitval.tables import _published_yorozu2015b as P
    text = (ROOT / ".." / "shared" / "seeds" / "001_8b8739c5501e2bab.txt")
    if not text.is_file():
        pytest.skip("seed text absent")
    cells = [c.strip() for c in text.read_text().split("\n") if c.strip()]
    i = cells.index("Method 1")
    for name, m in zip(("Method 1", "Method 2", "Method 3", "Proposed"),
                       ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed")):
        j = cells.index(name, i)
        nums = cells[j + 3:j + 8]
        pub = P.TABLE3[m]
        assert [int(x) for x in nums[:4]] == list(pub[:4]), name
        assert nums[4] == pub[5].split(" [")[0]
    k = cells.index("Target step judgment")
    assert [int(x) for x in cells[k + 1:k + 5]] == list(P.TABLE4["target_step"][:4])
    assert cells[k + 5:k + 7] == list(P.TABLE4["target_step"][4:])
    k = cells.index("Cross step detection", k)
    assert [int(x) for x in cells[k + 1:k + 5]] == list(P.TABLE4["cross_step"][:4])


def test_mtst_defaults_match_the_schema():
    from gaitval.configcheck import check_config, load_schema
    from gaitval.evaluate.mtst_trial import DEFAULTS

    schema = load_schema(ROOT / "workflow" / "schemas" / "config.schema.yaml")

    def defaults(node):
        if "$ref" in node:
            node = {**schema["$defs"][node["$ref"].rsplit("/", 1)[-1]], **node}
        if "default" in node:
            return node["default"]
        return {k: defaults(v) for k, v in (node.get("properties") or {}).items()}

    assert defaults(schema["$defs"]["mtst"]) == DEFAULTS
    check_config({"studies": {}, "run": ["x"], "mtst": DEFAULTS}, schema=schema)
    shipped = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["mtst"]
    assert shipped == DEFAULTS


def test_ingested_files_do_not_depend_on_where_the_study_folder_sits(tiny, tmp_path):
    # a reviewer's rerun in another folder (or on another machine) gives the same bytes;
    # the steps that have the sheet's row still name the C3D by its absolute path
    from gaitval.io.ingest import ingest_trial
    from gaitval.io.trialsheet import load_trial_sheet
    from gaitval.pipeline.steps.trials import load_ingested

    moved = tmp_path / "elsewhere" / "tiny"
    shutil.copytree(tiny / "tiny", moved)
    row = load_trial_sheet(moved / "trials.csv").loc[TRIAL].to_dict()
    ingest_trial(row, tmp_path / "ingest")
    for name in ("mocap.parquet", "sensor.parquet", "events.csv", "ingest.json"):
        assert (tmp_path / "ingest" / name).read_bytes() == \
            (tiny / "ingest" / name).read_bytes(), name
    mocap, _ = load_ingested(tmp_path / "ingest", row)
    assert mocap.path == row["mocap_path"] == str((moved / row["mocap_file"]).resolve())


def test_a_refused_registration_leaves_the_trial_out_with_its_reason(tiny):
    """A trial whose registration was refused, with no mtst.poles_m pose or no sheet clock
    offset to place it otherwise, gets an empty track and a ``not_registered`` evaluation
    instead of stopping its batch job; the tables leave it out and say why."""
    rec = json.loads((tiny / "register" / "registration.json").read_text())
    rec.update(status="refused", reason="[trial mtst_E01_t1] pole POLE2 not found",
               x_m=None, y_m=None, yaw_rad=None, clock_offset_s=None)
    reg = tiny / "refused" / "registration.json"
    reg.parent.mkdir(parents=True)
    reg.write_text(json.dumps(rec))
    subjects = tiny / "tiny" / "subjects.csv"
    sheet = tiny / "tiny" / "trials.csv"
    sensor = tiny / "tiny" / "lrs" / f"{TRIAL}.scan.parquet"
    track = mtst_track_step(sensor, sheet, subjects, TRIAL, "mtst_m1", tiny / "config.json",
                            reg, tiny / "refused" / "track.parquet")
    assert track.empty and list(track.columns[:2]) == ["trial", "method"]
    s = mtst_evaluate_step(tiny / "refused" / "track.parquet", sheet, subjects, TRIAL,
                           "mtst_m1", tiny / "config.json", reg, None,
                           tiny / "refused" / "eval").iloc[0]
    assert s["category_mocap"] == "not_registered" and not s["has_annotations"]
    if not (tiny / "mocap" / "eval" / "summary.parquet").is_file():
        _run(tiny, sheet, tiny / "config.json", tiny / "register" / "registration.json",
             tiny / "register" / "groundtruth.parquet", "mocap")
    mtst_tables_step([tiny / "mocap" / "eval", tiny / "refused" / "eval"],
                     tiny / "rep2" / "tables", tiny / "rep2" / "figures", tiny / "rep2",
                     methods=[METHOD, "mtst_m1"], config_json=tiny / "config.json")
    t3 = pd.read_csv(tiny / "rep2" / "tables" / "mtst_table3.csv")
    assert set(t3["method"]) == {METHOD}             # the refused (trial, method) has no row
    md = (tiny / "rep2" / "tables" / "mtst_table3.md").read_text()
    assert f"1 trial(s) left out of every row: {TRIAL} (registration refused)" in md
