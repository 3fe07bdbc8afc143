"""The fuzz harness on a small budget (CI): every mutant of every file kind gaitval reads
ends as a load or a gaitval error naming the file — no crash, hang or foreign exception.

The full run (10,000 mutants, counts per file type) is ``tests/fuzz/run_fuzz.py``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "fuzz"))
import fuzz_harness as H  # noqa: E402

#: mutants per kind: ~45 s on one core (a bag takes ~1 s to read)
BUDGET = {"c3d": 24, "bag": 4, "scanlog": 16, "ultrasonic": 16, "annotations": 16,
          "sheet": 16}


@pytest.mark.realdata
@pytest.mark.parametrize("kind", H.KINDS)
@pytest.mark.slow
def test_mutants_load_or_name_the_file(kind, realdata, tmp_path):
    H.warm_up()
    results = [H.fuzz_one((kind, 20260, i, str(tmp_path))) for i in range(BUDGET[kind])]
    bad = [f"{r['outcome']} {r['what']}: {r['detail']}" for r in results
           if r["outcome"] in H.FAILURES]
    assert not bad, "\n".join(bad)
    assert {r["outcome"] for r in results} & {"load", "error"}


def test_a_silently_short_or_non_finite_load_is_a_failure():
    """The harness' own verdicts (issue 33): "loaded but short" is not a success."""
    base = {"scans": {"/a": {"n_scans": 435, "rate_hz": 7.5, "duration_s": 58.0,
                             "t_start_s": 1.0}}, "warnings": []}
    short = {"scans": {"/a": {**base["scans"]["/a"], "n_scans": 82}}, "warnings": []}
    assert H.judge_load("bag", short, base)["outcome"] == "short"
    assert "n_scans 82 of 435" in H.judge_load("bag", short, base)["detail"]
    gone = {"scans": {}, "warnings": []}
    assert H.judge_load("bag", gone, base)["outcome"] == "short"
    loud = {**short, "warnings": ["topic /a: 1 gap(s) longer than 5 x ..."]}
    assert H.judge_load("bag", loud, base)["outcome"] == "warned"
    assert H.judge_load("bag", base, base)["outcome"] == "load"
    nan = {"scans": {"/a": {**base["scans"]["/a"], "rate_hz": None}}, "warnings": []}
    assert H.judge_load("bag", nan, base)["outcome"] == "nonfinite"
    c3d = {"rate_hz": 100.0, "n_frames": 94, "n_markers": 0, "t_start_s": 0.0,
           "t_end_s": 0.93, "duration_s": 0.94, "warnings": ["duplicate marker labels"]}
    seed = {**c3d, "n_markers": 137}
    assert H.judge_load("c3d", c3d, seed)["outcome"] == "short"   # the seed's own warning
    assert set(H.FAILURES) >= {"short", "nonfinite", "crash", "hang", "foreign", "unnamed"}


def test_a_sheet_that_loads_with_an_unsafe_id_is_a_failure():
    """Issue 33: the harness counts a trial sheet accepted with an id such as '..' or
    'x$(id)' as a failure, not as a load."""
    import fuzz_mutators as M
    import numpy as np
    assert H.judge_load("sheet", {"ids": ["s", "S01", ".."]}, None)["outcome"] == "unsafe"
    assert "unsafe" in H.FAILURES
    assert H.judge_load("sheet", {"ids": ["s", "S01", "tug_S01_1"]}, None)["outcome"] == "load"
    data, what = M.sheet_id_mutation("h,a,b,c\ns,tug,S01,t1\n", np.random.default_rng(1))
    assert "id column" in what and data.decode().count("\n") == 2
