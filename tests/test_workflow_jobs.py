"""How the workflow runs its jobs: one job per (study, stage[, method]) whose stage verb
(gaitval.jobs.stages) runs each trial's gaitval verbs in a process pool of the rule's
threads (gaitval.jobs.batch).  Here, on the tiny study's ingest (one job for its trials), one
trial with its C3D file overwritten by junk: the job fails with one message naming the
file, the trial and the problem, its log holds every trial's messages and the command
that reruns each by hand, and its outputs are removed."""
from __future__ import annotations

import os
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from gaitval.errors import GaitvalError
from gaitval.cli import run_verbs
from gaitval.jobs.batch import BatchError, Task, by_size, run_batch

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"
BAD = "tug_Y01_t2"


@pytest.fixture(scope="module")
def tiny_data(tiny_run):
    """The session's simulated tiny study (tests/conftest.py), read only: each test here
    copies it."""
    data = tiny_run / "data"
    sheet = pd.read_csv(data / "tiny" / "trials.csv")
    return data, sheet


@pytest.fixture(scope="module")
def bad_ingest(tiny_data, tmp_path_factory):
    data, sheet = tiny_data
    work = tmp_path_factory.mktemp("bad")
    shutil.copytree(data, work / "data")
    row = sheet.set_index("trial").loc[BAD]
    (work / "data" / "tiny" / row["mocap_file"]).write_bytes(b"not a C3D file" * 100)
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(work),
           "--cores", "2", "--force-use-threads", "results/tiny/ingest",
           "--config", 'run=["tiny"]', f"data_dir={work / 'data'}"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    return work, res


@pytest.mark.slow
def test_a_failing_trial_names_file_trial_and_problem(bad_ingest):
    work, res = bad_ingest
    out = res.stdout + res.stderr
    assert res.returncode != 0
    message = [ln for ln in out.splitlines() if ln.startswith("gaitval: error: ")]
    assert message and f"[{BAD}]" in message[0] and f"{BAD}.c3d" in message[0], out[-3000:]
    log = (work / "logs" / "ingest" / "tiny.log").read_text()
    assert f"== {BAD}: FAILED: " in log and f"{BAD}.c3d" in log, log
    assert not (work / "results" / "tiny" / "ingest").exists()   # the job's output removed


@pytest.mark.slow
def test_the_log_gives_each_trials_command(tiny_data, tmp_path):
    """A batch's log holds, per trial, the command that runs the same step by hand; run
    by hand, it writes the same bytes."""
    data, sheet = tiny_data
    shutil.copytree(data, tmp_path / "data")
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory",
           str(tmp_path), "--cores", "2", "--force-use-threads", "results/tiny/ingest",
           "--config", 'run=["tiny"]', f"data_dir={tmp_path / 'data'}"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-3000:]
    log = (tmp_path / "logs" / "ingest" / "tiny.log").read_text()
    trials = sorted(sheet.loc[sheet["mocap_file"].notna(), "trial"])
    commands = [ln[2:] for ln in log.splitlines() if ln.startswith("$ gaitval ingest ")]
    assert len(commands) == len(trials)
    argv = shlex.split(commands[0])
    trial = argv[argv.index("--trial") + 1]
    out = tmp_path / "by_hand"
    argv[argv.index("--out") + 1] = str(out)
    subprocess.run([sys.executable, "-m", *argv], cwd=tmp_path, check=True,
                   capture_output=True, timeout=300)
    for f in sorted(out.iterdir()):
        if f.name != "mocap.parquet":             # it names the C3D as the command gave it
            assert f.read_bytes() == (tmp_path / "results" / "tiny" / "ingest" / trial
                                      / f.name).read_bytes(), f


def _fails(label):
    raise GaitvalError(f"[file x.csv] trial {label}: broken")


def _writes(path, text):
    Path(path).write_text(text)


@pytest.mark.slow
def test_run_batch_stops_at_the_first_failure_and_says_which(tmp_path):
    tasks = [Task("a", _writes, {"path": tmp_path / "a.txt", "text": "a"}),
             Task("b", _fails, {"label": "b"})]
    with pytest.raises(BatchError, match=r"\[b\] \[file x.csv\] trial b: broken"):
        run_batch(tasks, 2, tmp_path / "batch.log")
    log = (tmp_path / "batch.log").read_text()
    assert "== b: FAILED: [file x.csv] trial b: broken" in log


@pytest.mark.slow
def test_run_batch_runs_every_task_and_logs_by_label(tmp_path):
    tasks = by_size([Task(f"t{i}", _writes, {"path": tmp_path / f"{i}.txt", "text": str(i)})
                     for i in range(5)], sizes=[1, 5, 3, 2, 4])
    assert [t.label for t in tasks] == ["t1", "t4", "t2", "t3", "t0"]   # largest first
    run_batch(tasks, 2, tmp_path / "batch.log")
    assert sorted(p.read_text() for p in tmp_path.glob("*.txt")) == list("01234")
    labels = [ln for ln in (tmp_path / "batch.log").read_text().splitlines()
              if ln.startswith("== ")]
    assert labels == [f"== t{i}" for i in range(5)]


def test_a_usage_error_of_a_verb_fails_its_task(tmp_path):
    with pytest.raises(BatchError, match=r"\[x\] unrecognized arguments: --no-such-option"):
        argv = ["ingest", "--sheet", "s.csv", "--trial", "t", "--out", "o", "--no-such-option"]
        run_batch([Task("x", run_verbs, {"argvs": [argv]})], 1, tmp_path / "batch.log")


@pytest.mark.slow
def test_ctrl_c_stops_a_batch_job(tiny_data, tmp_path):
    """Ctrl-C (SIGINT to Snakemake's process group, as a terminal sends it) stops a batch
    job's workers too: nothing keeps running once Snakemake has exited."""
    data, _ = tiny_data
    shutil.copytree(data, tmp_path / "data")
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(tmp_path),
           "--profile", str(ROOT / "workflow" / "profiles" / "default"),
           "--cores", "2", "--force-use-threads", "--config", 'run=["tiny"]', f"data_dir={tmp_path / 'data'}"]

    def as_from_a_terminal():
        # Snakemake as a terminal starts it: SIGINT at its default.  A test suite run in
        # the background of a non-interactive shell (`... &`, as CI scripts may) inherits
        # SIGINT *ignored* (POSIX: asynchronous commands ignore SIGINT without job
        # control); Python then installs no KeyboardInterrupt handler, and Snakemake runs
        # on to the end whatever Ctrl-C -- the failure seen in a fresh-clone CI run.
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True, preexec_fn=as_from_a_terminal)
    deadline = time.time() + 300
    try:
        # a registration batch whose workers are at work (a trial's first file in its
        # family's folder), so that the Ctrl-C reaches running workers
        reg = tmp_path / "results" / "tiny" / "register"

        def working() -> bool:
            for d in reg.glob("*"):
                try:
                    if d.is_dir() and any(d.iterdir()):
                        return True
                except FileNotFoundError:
                    continue
            return False

        while not working():
            assert proc.poll() is None and time.time() < deadline, "no registration started"
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        rc = proc.wait(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert rc != 0
    # the pool's workers and forkserver end when they see Snakemake gone (their pipes to
    # it closed): give them a moment on a loaded machine
    left = "?"
    for _ in range(60):
        left = subprocess.run(["pgrep", "-a", "-s", str(proc.pid)], capture_output=True,
                              text=True).stdout.strip()
        if not left:
            break
        time.sleep(0.5)
    assert left == "", f"processes left running: {left}"
