"""Rebuild tests/data/tiny_reference/ (the tiny study's report tables that
tests/test_workflow.py compares a fresh run against, docs/numerics.md).

Run it when a change is *meant* to alter the numbers (a simulator, tracker or table
change), then review ``git diff tests/data/tiny_reference`` and commit it with the change::

    .venv/bin/python tests/data/regenerate_tiny_reference.py

It runs the whole workflow on the tiny study in a scratch folder, exactly as the test does
(tests/test_workflow.py ``run_workflow``), and copies ``reports/tiny/tables/*.csv`` and
``reports/tiny/verdicts.csv``.
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from test_workflow import run_workflow  # noqa: E402

OUT = HERE / "tiny_reference"


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        res = run_workflow(work)
        if res.returncode != 0:
            print(res.stderr[-4000:], file=sys.stderr)
            return 1
        report = work / "reports" / "tiny"
        if OUT.exists():
            shutil.rmtree(OUT)
        (OUT / "tables").mkdir(parents=True)
        for p in sorted((report / "tables").glob("*.csv")):
            shutil.copyfile(p, OUT / "tables" / p.name)
        shutil.copyfile(report / "verdicts.csv", OUT / "verdicts.csv")
    n = len(list(OUT.rglob("*.csv")))
    print(f"wrote {n} tables to {OUT}; review with: git diff --stat {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
