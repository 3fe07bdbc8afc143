"""Issue 37: a study's external trackers and detectors may be declared in ``external.yaml``
beside its trial sheet, a file gaitval never writes.  A simulated study's ``study.yaml`` is
the simulator's (rewritten by every simulation), so this is where such a study declares
them -- before its first run, too -- merged with study.yaml's entries and checked the same
way before any job runs."""
from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml

from gaitval.errors import ConfigError
from gaitval.pipeline.steps.config import analysis_config
from gaitval.pipeline.steps.declarations import (external_declarations, study_external,
                                                 study_side_problems)

ENTRY = {"path": "ext/{trial}.tracks.csv", "protocols": ["tug"]}


def study(tmp_path: Path, own: dict | None, side: dict | None) -> Path:
    folder = tmp_path / "s"
    folder.mkdir()
    sheet = folder / "trials.csv"
    sheet.write_text("study,protocol,subject,trial\ns,tug,S1,tug_a\n")
    if own is not None:
        (folder / "study.yaml").write_text(yaml.safe_dump(own))
    if side is not None:
        (folder / "external.yaml").write_text(yaml.safe_dump(side))
    return sheet


def test_the_side_files_entries_join_the_study_yamls(tmp_path):
    sheet = study(tmp_path, {"seed": 1, "external_methods": {"a": ENTRY}},
                  {"external_methods": {"b": ENTRY},
                   "external_detections": {"d": {"path": "det/{trial}.bag"}}})
    assert study_external(sheet) == {"a": ENTRY, "b": ENTRY}
    assert study_external(sheet, "external_detections") == {"d": {"path": "det/{trial}.bag"}}
    assert external_declarations({}, {"s": sheet}, set()) == {"s": {"a": ENTRY, "b": ENTRY}}
    # the jobs' config (rule config_view) sees them as tracking.external
    assert set(analysis_config({}, sheet)["tracking"]["external"]) == {"a", "b"}
    # without a study.yaml (a simulated study before its simulation) too
    (sheet.parent / "study.yaml").unlink()
    assert analysis_config({}, sheet)["tracking"]["external"] == {"b": ENTRY}


def test_a_name_in_both_files_and_a_bad_key_are_named(tmp_path):
    sheet = study(tmp_path, {"external_methods": {"a": ENTRY}},
                  {"external_methods": {"a": ENTRY}, "registration": {}})
    with pytest.raises(ConfigError) as exc:
        study_external(sheet)
    msg = str(exc.value)
    for w in ("external.yaml", "external_methods.a", "also declared in", "study.yaml"):
        assert w in msg, (w, msg)
    with pytest.raises(ConfigError, match=r"external.yaml\] unknown key registration"):
        study_side_problems(sheet)


@pytest.mark.slow
def test_a_simulated_study_declares_an_external_method_before_its_first_run(
        tiny_run, tmp_path):
    """external.yaml written into data/tiny before anything was simulated: the simulation
    leaves it as it is (and its study.yaml without the entry), the run then names the
    missing track files before any job, and once they are there plans the method's job."""
    from conftest import tiny_workflow
    from gaitval.io.tracks.write import track_to_exchange, write_tracks

    tiny = tmp_path / "data" / "tiny"
    tiny.mkdir(parents=True)
    side = tiny / "external.yaml"
    side.write_text(yaml.safe_dump({"external_methods": {"ext_csv": ENTRY}}))
    before = side.read_bytes()
    res = tiny_workflow(tmp_path, targets=["data/tiny/trials.csv"])
    assert res.returncode == 0, res.stderr[-3000:]
    assert side.read_bytes() == before
    assert "external_methods" not in yaml.safe_load((tiny / "study.yaml").read_text())
    res = tiny_workflow(tmp_path, "-n", targets=["results/tiny/evaluate/ext_csv"])
    out = res.stdout + res.stderr
    assert res.returncode != 0
    for w in ("ConfigError", "external.yaml] external_methods ext_csv",
              "trials' track files are missing"):
        assert w in out, (w, out[-3000:])
    done = tiny_run / "results" / "tiny" / "track" / "tug_m1"
    for f in sorted(done.glob("*.parquet")):    # the same preset and seed: the same trials
        write_tracks(track_to_exchange(pd.read_parquet(f)),
                     tiny / "ext" / f"{f.stem}.tracks.csv")
    res = tiny_workflow(tmp_path, "-n", targets=["results/tiny/evaluate/ext_csv"])
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    assert "rule track_external:" in out and "method=ext_csv" in out


def test_validate_reports_the_side_files_detectors(tmp_path):
    """``gaitval validate`` (external_problems) names an external.yaml detector's missing
    files, and with --deep each detections file that does not read."""
    from gaitval.pipeline.steps.checks import external_problems

    sheet = study(tmp_path, None, {"external_detections": {
        "d": {"path": "det/{trial}.detections.csv", "protocols": ["tug"]}}})
    probs = external_problems(sheet)
    assert len(probs) == 1
    for w in ("external.yaml] external_detections d", "1 of 1 trials' detection files"):
        assert w in probs[0], (w, probs[0])
    (sheet.parent / "det").mkdir()
    (sheet.parent / "det" / "tug_a.detections.csv").write_text(
        "# gaitval-detections v1\n# units: inch\n# frame: sensor\n# clock: sensor\n"
        "t_s,x,y\n0.0,1.0,0.1\n")
    assert external_problems(sheet) == []
    probs = external_problems(sheet, deep=True)
    assert len(probs) == 1
    for w in ("external_detections.d", "tug_a.detections.csv", "trial tug_a",
              "'units' is 'inch'", "(line 2)"):
        assert w in probs[0], (w, probs[0])
