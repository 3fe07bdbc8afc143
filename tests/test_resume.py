"""Kill -9 anywhere, then the README's report command resumes to the complete report.

A power cut or a killed cluster job leaves Snakemake's lock in ``.snakemake/locks``, the
outputs of the jobs it was running marked incomplete in ``.snakemake/incomplete``, and
possibly job processes.  ``python3 run.py report`` must clear the dead run's lock, redo
what it left unfinished (``gaitval/jobs/resume.py``), leave no process of the dead run
at work (``gaitval/jobs/lifeline.py``), and finish with tables and figures identical to
an uninterrupted run's.

The kill test runs the tiny study's report once, killing it as each rule starts, every
rule in turn and in both ways (``kill -9`` of the whole process group, like a power cut,
and of Snakemake alone), then lets the same command finish, and compares with the
session's uninterrupted run of the same study (``tiny_run``, tests/conftest.py).  One
chain of runs, not one run per kill: each resumed run is killed at the next rule it
starts.  A rule is killed both ways in a row: first the whole process group as it starts;
the next run starts it again (``--forcerun`` of that rule, for its jobs that finished
before the kill; its killed job is redone anyway) and Snakemake alone is killed as it
does.  So the whole test costs one report plus a Snakemake start per kill (it used to run
the chain twice from the simulated data, one pass per way: two reports).  The suite kills
at six rules each way (the audit's ``ultrasonic_tables`` and five drawn by a seeded
sample) to keep CI's time; ``GAITVAL_EXHAUSTIVE_KILLS=1`` kills at every rule in turn.
"""
from __future__ import annotations

import base64
import json
import os
import random
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import PEER, copy_run

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _report(workdir: Path) -> list[str]:
    return [sys.executable, str(ROOT / "run.py"), "report", "--directory", str(workdir),
            "--config", 'run=["tiny"]', f"peer_results={PEER}"]


def _session(sid: int) -> list[str]:
    """The processes still alive in session ``sid`` (zombies left out)."""
    out = subprocess.run(["ps", "-eo", "pid=,sid=,stat=,args="], capture_output=True,
                         text=True).stdout
    return [ln.strip() for ln in out.splitlines()
            if ln.split()[1:2] == [str(sid)] and not ln.split()[2].startswith("Z")]


def _snakemake_of(run_pid: int) -> int | None:
    """The Snakemake process run.py (``run_pid``) started."""
    for _ in range(200):
        kids = subprocess.run(["pgrep", "-P", str(run_pid)], capture_output=True,
                              text=True).stdout.split()
        for k in kids:
            try:
                if "snakemake" in Path(f"/proc/{k}/cmdline").read_text(errors="replace"):
                    return int(k)
            except OSError:
                continue
        time.sleep(0.05)
    return None


def _run_until_rule(work: Path, pending: dict[str, list[str]], rng: random.Random,
                    log, extra: list[str] = ()) -> tuple[str, str] | None:
    """Start the report command (``extra``: more Snakemake arguments); when a rule of
    ``pending`` (mode -> rules: "group": kill the whole run; "snakemake": Snakemake alone)
    starts, kill it in the first mode that still lists it after a short random delay and
    return (that rule, the mode); None when the run ended before any of them started (it
    must then have succeeded)."""
    # Snakemake's own console (rule by rule), not gaitval's one line per finished step
    p = subprocess.Popen([*_report(work), *extra], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, start_new_session=True,
                         env={**os.environ, "GAITVAL_CONSOLE": "raw"})
    hit = mode = None
    for line in p.stdout:
        log.write(line)
        m = re.match(r"^(?:local)?rule (\w+):", line)
        if m:
            mode = next((md for md in ("group", "snakemake") if m.group(1) in pending[md]),
                        None)
            if mode:
                hit = m.group(1)
                break
    if hit is None:
        rc = p.wait()
        assert rc == 0, f"the run ended with {rc} (log: {log.name})"
        return None
    time.sleep(rng.uniform(0.0, 1.5))
    if mode == "group":
        os.killpg(p.pid, signal.SIGKILL)
    else:
        sm = _snakemake_of(p.pid)
        assert sm is not None, "no Snakemake process under run.py"
        os.kill(sm, signal.SIGKILL)
    p.stdout.close()
    p.wait()
    # nothing of the dead run keeps working: the pool's forkserver and workers, a shell
    # job's gaitval, end with their Snakemake (gaitval/jobs/lifeline.py)
    deadline = time.monotonic() + 15
    while _session(p.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    left = _session(p.pid)
    assert not left, f"killed at {hit} ({mode}), still running: {left}"
    log.write(f"\n### killed at rule {hit} ({mode})\n")
    return hit, mode


def _rules_of(run: Path) -> list[str]:
    """The rules an uninterrupted run of the tiny study ran (its Snakemake log), in the
    order they first started."""
    logs = sorted((run / ".snakemake" / "log").glob("*.snakemake.log"))
    seen: list[str] = []
    for lg in logs:
        for m in re.finditer(r"^(?:local)?rule (\w+):", lg.read_text(), re.M):
            if m.group(1) not in seen and m.group(1) not in ("all", "simulate"):
                seen.append(m.group(1))
    return seen


@pytest.mark.slow
def test_killed_at_each_rule_in_turn_both_ways_resumes_to_the_same_report(tiny_run, tmp_path):
    rules = _rules_of(tiny_run)
    assert len(rules) > 10, rules
    all_rules = rules
    if os.environ.get("GAITVAL_EXHAUSTIVE_KILLS") != "1":
        # CI's time: the audit's rule (ultrasonic_tables) and five others drawn by a
        # seeded sample, each way; GAITVAL_EXHAUSTIVE_KILLS=1 kills at every rule
        others = [r for r in rules if r != "ultrasonic_tables"]
        rules = [r for r in rules if r == "ultrasonic_tables"
                 or r in random.Random(5252).sample(others, 5)]
    work = tmp_path / "work"
    work.mkdir()
    copy_run(tiny_run / "data", work / "data")        # the same study: nothing simulated
    rng = random.Random(52)
    killed: list[tuple[str, str]] = []
    pending = {"group": list(rules), "snakemake": list(rules)}
    with open(tmp_path / "runs.log", "w") as log:
        while pending["group"] or pending["snakemake"]:
            # the rules killed as a whole and not yet with Snakemake alone start again
            again = [r for r in pending["snakemake"] if r not in pending["group"]]
            got = _run_until_rule(work, pending, rng, log,
                                  ["--forcerun", *again] if again else [])
            if got is None:
                break                       # the rest had already run to the end
            hit, mode = got
            pending[mode].remove(hit)
            killed.append((hit, mode))
            # the rules that finished meanwhile will not start again in this chain
    res = subprocess.run(_report(work), capture_output=True, text=True, timeout=1800)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    by_mode = {m: {r for r, mm in killed if mm == m} for m in ("group", "snakemake")}
    print(f"killed {len(killed)} times: group at {sorted(by_mode['group'])}; "
          f"snakemake alone at {sorted(by_mode['snakemake'])}")
    # every rule was killed at least once each way, but a few sub-second local jobs
    # (study_config, report_config) that start beside a killed one and finish before the
    # kill: they have no job left to start when their turn comes
    for mode, hit in by_mode.items():
        assert len(hit) >= len(rules) - (3 if rules is all_rules else 2), \
            (mode, sorted(set(rules) - hit))
    ref_rd, rd = tiny_run / "reports" / "tiny", work / "reports" / "tiny"
    for sub, pattern in (("tables", "*"), ("figures", "*.png")):
        ref = sorted(p.name for p in (ref_rd / sub).glob(pattern))
        got = sorted(p.name for p in (rd / sub).glob(pattern))
        assert ref and got == ref, (sub, set(ref) ^ set(got))
    for t in sorted((ref_rd / "tables").glob("*.csv")):
        assert (rd / "tables" / t.name).read_bytes() == t.read_bytes(), t.name
    assert "Not produced yet" not in (rd / "index.md").read_text()
    from gaitval.jobs.resume import marked_incomplete
    assert marked_incomplete(work) == {}, "marks left"


def test_a_live_snakemake_keeps_its_lock(tmp_path, monkeypatch):
    """run.py refuses to clear a lock while a Snakemake works in the folder."""
    import run

    (tmp_path / ".snakemake" / "locks").mkdir(parents=True)
    (tmp_path / ".snakemake" / "locks" / "0.input.lock").write_text("x")
    fake = {4242: (1, "/venv/bin/python /venv/bin/snakemake --profile p", str(tmp_path))}
    monkeypatch.setattr(run, "_processes", lambda: fake)
    assert run.clear_stale_lock(["snakemake"], {}, tmp_path) is False
    assert (tmp_path / ".snakemake" / "locks" / "0.input.lock").exists()


def _mark(work: Path, name: str, max_len: int = 255) -> Path:
    """A mark as Snakemake 9 writes it (snakemake/persistence/file.py, _record_path)."""
    b64 = base64.urlsafe_b64encode(name.encode()).decode()
    parts = [b64[i:i + max_len - 1] for i in range(0, len(b64), max_len - 1)]
    parts = ["@" + s for s in parts[:-1]] + [parts[-1]]
    mark = work / ".snakemake" / "incomplete" / Path(*parts)
    mark.parent.mkdir(parents=True, exist_ok=True)
    mark.write_text(json.dumps({"external_jobid": None}))
    return mark


def test_what_a_dead_run_left_unfinished_is_removed_before_the_next(tmp_path):
    from gaitval.jobs.resume import clear_interrupted, marked_incomplete

    (tmp_path / "reports" / "tiny" / "tables").mkdir(parents=True)
    t2 = tmp_path / "reports" / "tiny" / "tables" / "ultrasonic_table2.csv"
    t2.write_text("half")
    folder = tmp_path / "results" / "tiny" / "register" / "tug"
    folder.mkdir(parents=True)
    (folder / "t1.json").write_text("{}")
    done = tmp_path / "reports" / "tiny" / "tables" / "tug_table4.csv"
    done.write_text("finished")
    # the atomic writer's temporary files of the killed job, beside and above its outputs
    (tmp_path / "reports" / "tiny" / "provenance").mkdir()
    part = tmp_path / "reports" / "tiny" / "provenance" / ".ultrasonic_tables.json.ab_cd9xz.part"
    part.write_text("half")
    part2 = tmp_path / "reports" / "tiny" / "tables" / ".ultrasonic_table3.csv.a1b2c3d4.part"
    part2.write_text("half")
    long_name = "results/tiny/" + "x" * 300 + ".parquet"    # a mark split into folders
    _mark(tmp_path, str(t2.relative_to(tmp_path)))
    _mark(tmp_path, str(folder.relative_to(tmp_path)))
    _mark(tmp_path, long_name, max_len=100)
    _mark(tmp_path, "reports/tiny/figures/ultrasonic_fig5.png")   # never written
    assert set(marked_incomplete(tmp_path)) == {
        "reports/tiny/tables/ultrasonic_table2.csv", "results/tiny/register/tug",
        long_name, "reports/tiny/figures/ultrasonic_fig5.png"}
    # a Snakemake holds a lock here: its marks are its running jobs', left alone
    (tmp_path / ".snakemake" / "locks").mkdir()
    (tmp_path / ".snakemake" / "locks" / "0.output.lock").write_text("")
    assert clear_interrupted(tmp_path) == [] and t2.exists()
    (tmp_path / ".snakemake" / "locks" / "0.output.lock").unlink()
    removed = clear_interrupted(tmp_path)
    assert sorted(removed) == ["reports/tiny/tables/ultrasonic_table2.csv",
                               "results/tiny/register/tug"]
    assert not t2.exists() and not folder.exists() and done.read_text() == "finished"
    assert not part.exists() and not part2.exists()
    assert marked_incomplete(tmp_path) == {}


def test_the_report_refuses_to_finish_on_a_partial_report(tmp_path):
    from gaitval.errors import GaitvalError
    from gaitval.jobs.resume import refuse_unfinished, unfinished_report_items

    rd = tmp_path / "reports" / "tiny"
    (rd / "provenance").mkdir(parents=True)
    (rd / "tables").mkdir()
    for i in (2, 3):
        (rd / "tables" / f"ultrasonic_table{i}.csv").write_text("x")
    (rd / "provenance" / "ultrasonic_tables.json").write_text(json.dumps(
        {"step": "ultrasonic_tables", "items": [f"tables/ultrasonic_table{i}.csv"
                                                 for i in (2, 3, 4)]}))
    (rd / "provenance" / "report.json").write_text(json.dumps({"tables": "x"}))
    _mark(tmp_path, "reports/tiny/tables/ultrasonic_table3.csv")
    _mark(tmp_path, "reports/tiny/index.md")                # the report job's own
    (rd / "index.md").write_text("")
    probs = unfinished_report_items("reports/tiny", tmp_path,
                                    own_outputs=["reports/tiny/index.md"])
    assert len(probs) == 2, probs
    assert "ultrasonic_table4.csv: listed by ultrasonic_tables.json" in probs[0]
    assert probs[1].startswith("reports/tiny/tables/ultrasonic_table3.csv: left unfinished")
    cwd = os.getcwd()
    try:
        os.chdir(tmp_path)
        with pytest.raises(GaitvalError, match="incomplete .2 problems"):
            refuse_unfinished("reports/tiny", own_outputs=["reports/tiny/index.md"])
        (rd / "tables" / "ultrasonic_table4.csv").write_text("x")
        for m in (tmp_path / ".snakemake" / "incomplete").iterdir():
            m.unlink()
        refuse_unfinished("reports/tiny", own_outputs=["reports/tiny/index.md"])
    finally:
        os.chdir(cwd)


def test_a_pool_worker_dies_with_its_snakemake(tmp_path):
    """A process that watches a pid (gaitval.jobs.lifeline) ends within a second of it:
    the batch pool's workers watch the Snakemake that runs them."""
    parent = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    child = subprocess.Popen([sys.executable, "-c",
                              "import sys, time; from gaitval.jobs.lifeline import watch; "
                              f"watch({parent.pid}); time.sleep(60)"])
    time.sleep(1.0)
    assert child.poll() is None
    parent.kill()
    parent.wait()
    assert child.wait(timeout=10) == -signal.SIGKILL
