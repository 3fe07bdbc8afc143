"""How the workflow runs its jobs: locally in the warm fork server, sent from Snakemake's own
job thread (workflow/rules/common.smk), or as the plain shell command -- with the same
outputs, logs and error messages either way.

One Snakemake run per mode on the tiny study's ingest step, one core: every trial's ingest,
one trial with its C3D file overwritten by junk, that one last (``--prioritize`` the
others, so by then the server that the run starts is listening).
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"
BAD = "tug_Y01_t2"


@pytest.fixture(scope="module")
def tiny_data(tmp_path_factory):
    data = tmp_path_factory.mktemp("jobs") / "data"
    subprocess.run([sys.executable, "-m", "gaitval", "simulate", "--preset",
                    str(ROOT / "config" / "studies" / "tiny.yaml"), "--seed", "0",
                    "--out", str(data / "tiny")], check=True, capture_output=True, timeout=300)
    sheet = pd.read_csv(data / "tiny" / "trials.csv")
    row = sheet.set_index("trial").loc[BAD]
    (data / "tiny" / row["mocap_file"]).write_bytes(b"not a C3D file" * 100)
    return data, sorted(sheet.loc[sheet["mocap_file"].notna(), "trial"])


def _run(tiny_data, tmp_path_factory, fork_server: bool):
    data, trials = tiny_data
    work = tmp_path_factory.mktemp(f"fork{int(fork_server)}")
    shutil.copytree(data, work / "data")
    good = [f"results/tiny/ingest/{t}/sensor.parquet" for t in trials if t != BAD]
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(work),
           "--cores", "1", "--keep-going", "-p",
           *good, f"results/tiny/ingest/{BAD}/sensor.parquet", "--prioritize", *good,
           "--config", 'run=["tiny"]', f"data_dir={work / 'data'}", f"fork_server={fork_server}"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    return work, trials, res


@pytest.fixture(scope="module")
def with_server(tiny_data, tmp_path_factory):
    return _run(tiny_data, tmp_path_factory, True)


@pytest.fixture(scope="module")
def without_server(tiny_data, tmp_path_factory):
    return _run(tiny_data, tmp_path_factory, False)


def test_jobs_go_to_the_server_from_snakemakes_thread(with_server):
    work, trials, res = with_server
    log = (work / "logs" / "forkserver.log").read_text()
    ends = re.findall(r"^job \S+: exit (-?\d+), .*, via (\S+)$", log, re.M)
    # the first jobs may run before the server has imported everything (the plain way);
    # every job it ran came from Snakemake's thread, none through a shell and the client
    assert ends, log
    assert {via for _, via in ends} == {"snakemake"}, log
    # the bad trial went last, to the server, and failed there
    assert f"--trial {BAD} " in log.strip().splitlines()[-2] and ends[-1][0] == "1", log
    # a dry run and the log show the rules' commands as before
    assert re.search(r"forkclient\.py \S+ -- ingest --sheet", res.stdout + res.stderr)


@pytest.mark.parametrize("mode", ["with_server", "without_server"])
def test_a_failing_job_names_file_trial_and_problem(mode, request):
    work, trials, res = request.getfixturevalue(mode)
    out = res.stdout + res.stderr
    assert res.returncode != 0
    job_log = (work / "logs" / "ingest" / "tiny" / f"{BAD}.log").read_text()
    message = [line for line in job_log.splitlines() if "error" in line.lower()]
    assert message and BAD in message[-1] and f"{BAD}.c3d" in message[-1], job_log
    assert message[-1] in out                         # the log reaches Snakemake's output
    assert "returned non-zero exit status 1" in out
    assert not (work / "results" / "tiny" / "ingest" / BAD / "sensor.parquet").exists()

def test_same_outputs_and_logs_with_and_without_the_server(with_server, without_server):
    a, trials, _ = with_server
    b, _, _ = without_server
    for t in trials:
        if t == BAD:
            continue
        for f in sorted((a / "results" / "tiny" / "ingest" / t).iterdir()):
            assert f.read_bytes() == (b / f.relative_to(a)).read_bytes(), f
        log = Path("logs") / "ingest" / "tiny" / f"{t}.log"
        assert (a / log).read_text() == (b / log).read_text(), t
    bad = Path("logs") / "ingest" / "tiny" / f"{BAD}.log"         # names the file: its folder
    assert (a / bad).read_text().replace(str(a), "<run>") == \
        (b / bad).read_text().replace(str(b), "<run>")


def test_ctrl_c_stops_a_job_running_in_the_server(tmp_path):
    """Ctrl-C (SIGINT to Snakemake) stops the jobs the server is running for it -- they are
    in process groups of their own, which the terminal's signal does not reach -- instead of
    letting them run to their end while Snakemake waits."""
    import os
    import signal
    import time

    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(tmp_path),
           "--cores", "2", "--config", 'run=["tiny"]', f"data_dir={tmp_path / 'data'}"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    log = tmp_path / "logs" / "forkserver.log"
    job = None
    deadline = time.time() + 300
    try:
        # the ultrasonic tables: the tiny study's longest job (~3 s)
        while job is None and proc.poll() is None and time.time() < deadline:
            time.sleep(0.05)
            text = log.read_text() if log.is_file() else ""
            m = re.search(r"^job (\S+): gaitval ultrasonic-tables ", text, re.M)
            if m and f"job {m.group(1)}: exit" not in text:
                job = m.group(1)
        assert job is not None, "the run ended before its ultrasonic tables started"
        os.kill(proc.pid, signal.SIGINT)
        rc = proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert rc != 0
    end = re.search(rf"^job {re.escape(job)}: exit (-?\d+),", log.read_text(), re.M)
    assert end and end.group(1) != "0", "the running job was stopped, not finished"
