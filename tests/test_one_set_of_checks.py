"""`gaitval validate` and the run use the same checks, and a missing file is one line.

The study.yaml beside a sheet is checked against the config schema as the run checks it at
start; a track file whose positions cannot be metres is refused by ``validate --deep`` as
the run refuses it; ``export-tracks`` on a missing file and a sheet whose file vanished
before the run each give one line naming the file (and trial), no traceback."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.pipeline.steps.checks import _units_problem, study_yaml_problems


def test_a_study_yaml_typo_is_a_validate_problem_naming_key_and_suggestion(tmp_path):
    (tmp_path / "study.yaml").write_text("registration:\n  pole_diametre_m: 0.05\n")
    probs = study_yaml_problems(tmp_path / "trials.csv")
    assert len(probs) == 1
    text = str(probs[0])
    assert "pole_diametre_m" in text and "did you mean registration.pole_diameter_m" in text
    (tmp_path / "study.yaml").write_text("registration:\n  pole_diameter_m: 0.05\n")
    assert study_yaml_problems(tmp_path / "trials.csv") == []


def test_tracks_declared_in_metres_but_written_in_millimetres_are_refused():
    rng = np.random.default_rng(0)
    legs_m = pd.DataFrame({"x_m": 2.0 + rng.normal(0, 0.3, 200),
                           "y_m": rng.normal(0, 0.3, 200)})
    _units_problem(legs_m, {"units": "m", "frame": "sensor"}, "t.tracks.csv", "T1")
    legs_mm = legs_m * 1000.0
    with pytest.raises(FileFormatError, match="beyond any room.*'m'") as e:
        _units_problem(legs_mm, {"units": "m", "frame": "sensor"}, "t.tracks.csv", "T1")
    assert "t.tracks.csv" in str(e.value) and "T1" in str(e.value)
    assert "units: mm" in str(e.value)


def test_export_tracks_of_a_missing_file_is_one_clean_line(tmp_path):
    res = subprocess.run([sys.executable, "-m", "gaitval", "export-tracks",
                          str(tmp_path / "gone.parquet"), str(tmp_path / "out.tracks.csv")],
                         capture_output=True, text=True)
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "gone.parquet" in lines[0] and "not found" in lines[0]
    assert "Traceback" not in res.stderr and "Errno" not in res.stderr
