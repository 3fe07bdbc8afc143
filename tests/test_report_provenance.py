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


# -- portable provenance (issue 35, scope 6) ---------------------------------------------
def test_input_list_is_relative_to_the_working_folder(tmp_path, monkeypatch):
    """inputs.txt (so inputs.sha256) names files relative to the working folder, ../ for
    a file beside it: `sha256sum -c` works in another checkout with the same layout."""
    from types import SimpleNamespace

    from gaitval.report.provenance import write_workflow_record

    work = tmp_path / "checkout"
    (work / "data").mkdir(parents=True)
    (work / "data" / "trials.csv").write_text("trial\n")
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "elsewhere" / "peer.parquet").write_bytes(b"x")
    (tmp_path / "shared").symlink_to(tmp_path / "elsewhere")    # a link stays a link
    monkeypatch.chdir(work)
    prov = work / "reports" / "tiny" / "provenance"
    out = SimpleNamespace(config=prov / "config.yaml", inputs=prov / "inputs.txt",
                          rebuild=prov / "rebuild.json")
    write_workflow_record({"run": ["tiny"]}, [str(work / "data" / "trials.csv"),
                                              "../shared/peer.parquet"], out,
                          str(tmp_path / "log"), command="python3 run.py report",
                          chash="abc")
    assert (prov / "inputs.txt").read_text() == "data/trials.csv\n../shared/peer.parquet\n"
    text, n, _ = input_manifest((prov / "inputs.txt").read_text().split())
    assert n == 2 and "  data/trials.csv\n" in text and str(tmp_path) not in text


def test_report_provenance_has_the_lock_the_tables_and_a_reproduce_script(tmp_path):
    import shutil
    import subprocess

    from gaitval.report.provenance import REPO, lock_versions

    rd, _, _ = _report(tmp_path)
    build_index(rd, study_names=["tiny"])
    prov = rd / "provenance"
    rec = json.loads((prov / "report.json").read_text())
    lock = (prov / "requirements.lock").read_text()
    assert lock == (REPO / "requirements.lock").read_text()
    assert rec["lock_sha256"] == hashlib.sha256(lock.encode()).hexdigest()
    env = (prov / "environment.txt").read_text().splitlines()
    assert not any(ln.lower().startswith(("gaitval==", "pip==")) for ln in env)
    # the environment the tests run in is the lock's (run.py installs it)
    assert rec["environment_vs_lock"]["differ"] == [], rec["environment_vs_lock"]
    assert lock_versions(lock)["pandas"] == version("pandas")
    # tables.sha256 checks from the report folder
    tables = (prov / "tables.sha256").read_text().splitlines()
    assert tables and all(ln.split("  ", 1)[1].startswith("tables/") for ln in tables)
    if shutil.which("sha256sum"):
        assert subprocess.run(["sha256sum", "-c", "--quiet", "provenance/tables.sha256"],
                              cwd=rd).returncode == 0
    script = (prov / "reproduce.sh").read_text()
    commit = rec["git_commit"].removesuffix("+dirty")
    assert f"COMMIT={commit}" in script and 'git clone --quiet "$REPO" "$DEST"' in script
    assert 'cmp -s requirements.lock "$PROV/requirements.lock"' in script
    assert "\npython3 run.py report --config 'run=[\"tiny\"]'\n" in script
    assert 'sha256sum -c --quiet "$PROV/inputs.sha256"' in script
    assert 'sha256sum -c --quiet "$PROV/tables.sha256"' in script
    if shutil.which("bash"):
        assert subprocess.run(["bash", "-n", str(prov / "reproduce.sh")]).returncode == 0
    text = (rd / "index.md").read_text()
    assert "bash provenance/reproduce.sh" in text and "(absolute paths)" not in text


def test_the_lock_pins_every_dependency_of_pyproject_with_hashes():
    """requirements.lock covers pyproject.toml's dependencies and test extra (a new
    dependency without a new lock fails here: rerun the command in its head)."""
    import re
    import tomllib

    from gaitval.report.provenance import REPO, lock_versions

    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    wanted = project["dependencies"] + project["optional-dependencies"]["test"]
    text = (REPO / "requirements.lock").read_text()
    locked = lock_versions(text)
    for req in wanted:
        name = re.split(r"[<>=!~ \[;]", req, maxsplit=1)[0].lower().replace("_", "-")
        assert name in locked, (req, "not in requirements.lock")
    pins = [ln for ln in text.splitlines() if "==" in ln and not ln.startswith(("#", " "))]
    assert len(pins) == len(locked) and all(ln.rstrip().endswith("\\") for ln in pins)


def test_the_source_digest_changes_with_gaitvals_code_and_nothing_else(tmp_path):
    """The workflow puts gaitval's source digest into every job's config-view params, so
    that new code reruns the jobs (Snakemake's `code` trigger sees only a rule's own code):
    the digest follows every file's path and content, data files included, and ignores
    ``__pycache__``; the installed package's digest is the workflow's."""
    from pathlib import Path

    import gaitval
    from gaitval.report.provenance import source_digest

    pkg = tmp_path / "gaitval"
    (pkg / "track" / "data").mkdir(parents=True)
    (pkg / "methods.py").write_text('METHODS = {"people": {"motion": "cv"}}\n')
    (pkg / "track" / "data" / "forest.npz").write_bytes(b"\x00\x01")
    d0 = source_digest(pkg)
    assert len(d0) == 12 and source_digest(pkg) == d0
    (pkg / "__pycache__").mkdir()
    (pkg / "__pycache__" / "methods.cpython-311.pyc").write_bytes(b"compiled")
    assert source_digest(pkg) == d0
    (pkg / "methods.py").write_text('METHODS = {"people": {"motion": "gait"}}\n')
    d1 = source_digest(pkg)
    assert d1 != d0
    (pkg / "track" / "data" / "forest.npz").write_bytes(b"\x00\x02")
    assert source_digest(pkg) not in (d0, d1)
    assert source_digest() == source_digest(Path(gaitval.__file__).parent)
    smk = (Path(__file__).resolve().parents[1] / "workflow" / "rules" / "common.smk").read_text()
    assert 'sections["gaitval_source"] = SOURCE_DIGEST' in smk
