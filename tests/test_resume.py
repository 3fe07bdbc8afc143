"""Kill -9 at a random point, then the README's report command resumes by itself.

A power cut or a killed cluster job leaves Snakemake's lock in ``.snakemake/locks`` and,
possibly, job processes that keep writing.  ``python3 run.py report`` must see that no live
Snakemake holds the lock, clear it, and finish; the tables must be byte-identical to an
uninterrupted run's.  Runs the TUG branch of the tiny study (ingest, register, track,
evaluate, tables) to stay within a few minutes, on a copy of the session's simulated tiny
study (tests/conftest.py: both runs here read one data folder, so neither simulates).
"""
from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import copy_run

ROOT = Path(__file__).resolve().parents[1]
TARGETS = ["reports/tiny/tables/tug_table4.csv", "reports/tiny/tables/study_ingest_tiny.csv"]


def _report(workdir: Path, data: Path, **popen) -> list[str]:
    peer = (ROOT / ".." / "shared" / "realdata" / "peer-results" / "gailo_results.parquet")
    return [sys.executable, str(ROOT / "run.py"), "report", *TARGETS, "--directory",
            str(workdir), "--config", 'run=["tiny"]', f"data_dir={data}",
            f"peer_results={peer.resolve()}"]


@pytest.mark.slow
def test_kill_9_at_a_random_point_then_report_resumes_with_identical_tables(tiny_run,
                                                                             tmp_path):
    data = copy_run(tiny_run / "data", tmp_path / "data")
    t0 = time.monotonic()
    ref = subprocess.run(_report(tmp_path / "ref", data), capture_output=True, text=True,
                         timeout=1200)
    assert ref.returncode == 0, ref.stderr[-3000:]
    t_ref = time.monotonic() - t0
    work = tmp_path / "work"
    delay = random.uniform(2.0, max(3.0, 0.6 * t_ref))
    print(f"killing the run after {delay:.1f} s (the uninterrupted run took {t_ref:.0f} s)")
    with open(tmp_path / "killed.log", "w") as log:
        p = subprocess.Popen(_report(work, data), stdout=log, stderr=subprocess.STDOUT,
                             start_new_session=True)
        time.sleep(delay)
        os.killpg(p.pid, signal.SIGKILL)                   # the whole run, like a power cut
        p.wait()
    locked = any((work / ".snakemake" / "locks").glob("*"))
    res = subprocess.run(_report(work, data), capture_output=True, text=True, timeout=1200)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-3000:]
    if locked:
        assert "removing a stale Snakemake lock" in res.stdout
    tables = sorted((tmp_path / "ref" / "reports" / "tiny" / "tables").glob("*.csv"))
    assert tables
    for t in tables:
        assert (work / "reports" / "tiny" / "tables" / t.name).read_bytes() == t.read_bytes(), t.name


def test_a_live_snakemake_keeps_its_lock(tmp_path, monkeypatch):
    """run.py refuses to clear a lock while a Snakemake works in the folder."""
    sys.path.insert(0, str(ROOT))
    import run

    (tmp_path / ".snakemake" / "locks").mkdir(parents=True)
    (tmp_path / ".snakemake" / "locks" / "0.input.lock").write_text("x")
    fake = {4242: (1, "/venv/bin/python /venv/bin/snakemake --profile p", str(tmp_path))}
    monkeypatch.setattr(run, "_processes", lambda: fake)
    assert run.clear_stale_lock(["snakemake"], {}, tmp_path) is False
    assert (tmp_path / ".snakemake" / "locks" / "0.input.lock").exists()
