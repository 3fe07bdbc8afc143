"""Provenance once per report (issue 14, scope 5): resolved config, SHA-256 of every
input file, exact package versions, git commit and the one rebuild command."""
from __future__ import annotations

import hashlib
import json
from importlib.metadata import version

import pandas as pd

from gaitval.report.index import build_index
from gaitval.report.provenance import (input_manifest, rebuild_command, stamp,
                                       study_input_files)
from gaitval.tables import write_table


def _report(tmp_path, with_workflow_files=True):
    rd = tmp_path / "reports" / "tiny"
    paths = write_table(pd.DataFrame({"a": [1.5]}), rd / "tables" / "tug_table4",
                        caption="Occlusion rate")
    long_cmd = "gaitval tug-tables " + " ".join(f"/r/{i}" for i in range(140))
    stamp("tug_tables", paths, rd, config_hash_="abc", command=long_cmd)
    data = tmp_path / "data"
    (data / "bag").mkdir(parents=True)
    (data / "trials.csv").write_text("trial\nt1\n")
    (data / "bag" / "a.db3").write_bytes(b"\x00\x01")
    if with_workflow_files:
        prov = rd / "provenance"
        (prov / "inputs.txt").write_text(f"{data / 'trials.csv'}\n{data / 'bag'}\n")
        (prov / "config.yaml").write_text("run: [tiny]\n")
        (prov / "rebuild.json").write_text(json.dumps(
            {"command": "python3 run.py report --config 'run=[\"tiny\"]'",
             "config_hash": "0e46"}))
    return rd, data, long_cmd


def test_report_provenance_once_with_checksums_versions_and_command(tmp_path):
    rd, data, long_cmd = _report(tmp_path)
    md, html = build_index(rd, study_names=["tiny"])
    text = md.read_text()
    manifest = (rd / "provenance" / "inputs.sha256").read_text().splitlines()
    want = hashlib.sha256((data / "trials.csv").read_bytes()).hexdigest()
    assert f"{want}  {data / 'trials.csv'}" in manifest
    assert any(ln.endswith(str(data / "bag" / "a.db3")) for ln in manifest)   # folder
    env = (rd / "provenance" / "environment.txt").read_text().splitlines()
    assert f"pandas=={version('pandas')}" in env
    rec = json.loads((rd / "provenance" / "report.json").read_text())
    assert rec["n_input_files"] == 2 and rec["git_commit"]
    assert text.count("python3 run.py report --config 'run=[\"tiny\"]'") == 1
    assert "## Provenance" in text and "provenance/config.yaml" in text
    assert f"`pandas=={version('pandas')}`" in text
    assert long_cmd not in text and "/r/139" not in text   # no per-item command lines
    assert 'id="provenance"' in html.read_text()


def test_an_index_built_by_hand_says_it_has_no_report_provenance(tmp_path):
    rd, _, _ = _report(tmp_path, with_workflow_files=False)
    md, _ = build_index(rd, study_names=["tiny"])
    assert "No report provenance" in md.read_text()
    assert not (rd / "provenance" / "inputs.sha256").exists()


def test_a_missing_input_is_named_in_the_manifest(tmp_path):
    text, n, _ = input_manifest([tmp_path / "gone.c3d"])
    assert n == 0 and text == f"MISSING  {tmp_path / 'gone.c3d'}\n"


def test_study_inputs_and_rebuild_command(tmp_path):
    (tmp_path / "study.yaml").write_text("x: 1\n")
    trials = pd.DataFrame({"mocap_path": ["m.c3d"], "sensor_path": ["s.parquet"],
                           "annotation_path": [""]})
    files = study_input_files(tmp_path / "trials.csv", tmp_path / "subjects.csv", trials)
    assert files == [str(tmp_path / "trials.csv"), str(tmp_path / "subjects.csv"),
                     str(tmp_path / "study.yaml"), "m.c3d", "s.parquet"]
    cmd = rebuild_command([], {"run": ["tiny", "default"], "data_dir": "/d x"}, tmp_path,
                          repo=tmp_path)
    assert cmd == "python3 run.py report --config 'run=[\"tiny\", \"default\"]' 'data_dir=/d x'"
    assert "--directory" in rebuild_command([], {}, tmp_path / "w", repo=tmp_path)
