"""A lab's own study with the sensor pose typed wrong: each usual mistake is refused at
registration with its probable cause named, and the correct study passes.

The study is built from real motion capture (``../shared/realdata/c3d/``, three real walks;
the laser logs rendered from them by the ``replay`` preset: ``tests/own_study.py``), its
pose measured by hand (no calibration poles).  These tests run the pipeline's registration
step (``gaitval register``'s function) on the ingested files; the end-to-end run with its
exit code and report top box is ``test_refused_trials_are_loud`` in
``tests/test_workflow_refusals.py``.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

import own_study as O
from gaitval.io.ingest import ingest_trial
from gaitval.pipeline.steps.register import register_step
from gaitval.pipeline.steps.trials import trial_row

#: variant -> words the refusal must contain (the probable cause named)
CAUSES = {"mm": "millimetres", "rad": "radians", "swap": "x and y look exchanged",
          "yaw180": "180 degrees", "other": "copied",
          "clock": "clock offset in the sheet"}


@pytest.fixture(scope="module")
def replay(replay_simulated) -> Path:
    return replay_simulated


def _register(replay: Path, out: Path, variant, trial: str) -> dict:
    sheet = O.build(replay, out / "data", variant)
    subjects = sheet.parent / "subjects.csv"
    ing = out / "ingest" / trial
    ingest_trial(trial_row(sheet, subjects, trial), ing)
    cfg = out / "config.json"
    cfg.write_text("{}")
    return register_step(ing, sheet, subjects, trial, cfg, out / "register" / trial)


def test_the_correct_pose_is_registered_and_plausible(replay, tmp_path):
    rec = _register(replay, tmp_path, None, O.TARGET)
    assert rec["status"] == "ok", rec["reason"]
    assert rec["pose_source"] == "manual"
    assert rec["legs_in_view"] >= 0.9 and rec["legs_seen"] >= 0.9   # far above the 0.5 bar
    written = json.loads((tmp_path / "register" / O.TARGET / "registration.json").read_text())
    assert written["legs_seen"] == pytest.approx(rec["legs_seen"])


@pytest.mark.parametrize("variant", O.VARIANTS)
def test_a_wrong_pose_is_refused_with_its_probable_cause(replay, tmp_path, variant):
    rec = _register(replay, tmp_path, variant, O.TARGET)
    assert rec["status"] == "refused"
    reason = rec["reason"]
    assert CAUSES[variant] in reason, reason
    assert O.TARGET in reason and ".scan.parquet" in reason        # trial and file named
    if variant != "clock":     # a pose mistake never sends the user to a manual clock offset
        assert "give the offset by hand" not in reason


def test_the_other_trials_of_a_wrong_study_still_pass(replay, tmp_path):
    """Only the mistaken row is refused: the mm study's other trials register."""
    rec = _register(replay, tmp_path, "mm", O.OTHER)
    assert rec["status"] == "ok", rec["reason"]


def test_validate_flags_the_unit_mistakes_from_the_sheet_alone(replay, tmp_path):
    from gaitval.io.trialsheet import sheet_problems, sheet_warnings

    mm = O.build(replay, tmp_path / "mm", "mm")
    df, problems = sheet_problems(mm)
    assert not problems                     # legal, but flagged: the run refuses the trial
    text = " ".join(sheet_warnings(df))
    assert "beyond any motion-capture room" in text and "sensor_x_m" in text
    rad = O.build(replay, tmp_path / "rad", "rad")
    df, problems = sheet_problems(rad)
    assert not problems
    assert any("radians" in w for w in sheet_warnings(df))
    ok = O.build(replay, tmp_path / "ok", None)
    df, problems = sheet_problems(ok)
    assert not problems and not sheet_warnings(df)
