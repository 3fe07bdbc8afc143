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
def test_mutants_load_or_name_the_file(kind, realdata, tmp_path):
    H.warm_up()
    results = [H.fuzz_one((kind, 20260, i, str(tmp_path))) for i in range(BUDGET[kind])]
    bad = [f"{r['outcome']} {r['what']}: {r['detail']}" for r in results
           if r["outcome"] in H.FAILURES]
    assert not bad, "\n".join(bad)
    assert {r["outcome"] for r in results} & {"load", "error"}
