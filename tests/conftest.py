"""Shared fixtures: where the real data lives, and skipping cleanly when it does not; the
tiny study's workflow run, built once per test run and shared read-only (by every
pytest-xdist worker too: :func:`built_once`)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REALDATA = (ROOT / ".." / "shared" / "realdata").resolve()
SEEDS = (ROOT / ".." / "shared" / "seeds").resolve()
#: the peer's published results (tables/peer_agreement): made when ../shared is there
PEER = REALDATA / "peer-results" / "gailo_results.parquet"
#: the Snakemake of this venv (the 9.x requirements.lock installs)
SNAKEMAKE = Path(sys.executable).parent / "snakemake"
#: the README's report command's profile (threads for the `run:` jobs, the greedy scheduler)
PROFILE = ROOT / "workflow" / "profiles" / "default"


@pytest.fixture(scope="session")
def realdata() -> Path:
    """``../shared/realdata`` beside the checkout; skip with a reason when absent."""
    if not REALDATA.is_dir():
        pytest.skip(f"real data folder {REALDATA} is absent (a user's clone has no "
                    "../shared/realdata; CI always has it)")
    return REALDATA


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT


def built_once(tmp_path_factory, name: str, build) -> Path:
    """Folder ``name``, made by ``build(folder)`` once per test run and only read after.

    Under pytest-xdist each worker has its own session, so a session fixture would build
    once per worker: the workers share the run's temporary folder (the parent of each
    one's own), the first to ask builds there while the others wait on a file lock, and
    all of them read the same folder.  A build that failed is tried again by the next
    worker that asks (and fails its tests the same way)."""
    from filelock import FileLock

    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    out, done = root / name, root / f"{name}.built"
    with FileLock(str(root / f"{name}.lock")):
        if not done.exists():
            if out.exists():
                shutil.rmtree(out)                      # a failed build's leftovers
            out.mkdir()
            build(out)
            done.touch()
    return out


@pytest.fixture(scope="session")
def tiny_simulated(tmp_path_factory) -> Path:
    """``generate_study(folder, "tiny")`` once per test run: the tiny preset's files, read
    only by the tests (tests/test_simulate.py, test_physics.py, test_registration.py,
    test_mtst_steps.py); a test that changes files copies them."""
    from gaitval.simulate import generate_study

    return built_once(tmp_path_factory, "tiny_simulated",
                      lambda out: generate_study(out, "tiny"))


def tiny_workflow(work: Path, *extra: str, snakemake: Path = SNAKEMAKE, targets=(),
                  profile: bool = True, timeout: int = 900) -> subprocess.CompletedProcess:
    """The README's report command on the tiny study in folder ``work`` (its data in
    ``work/data``, the config's default ``data_dir``): ``extra`` goes after the
    ``--config`` items, so it may add more of them, then options (``-n``,
    ``--configfile ...``); ``targets`` come first.  ``profile=False``: without the
    README's profile, so each `run:` job runs in a Snakemake process of its own (as a
    cluster job does) under Snakemake's default scheduler."""
    cmd = [str(snakemake), *map(str, targets), "--snakefile", str(ROOT / "Snakefile"),
           *(["--profile", str(PROFILE)] if profile else []),
           "--directory", str(work), "--cores", "2",
           "--config", 'run=["tiny"]', f"peer_results={PEER}", *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="session")
def replay_simulated(realdata, tmp_path_factory) -> Path:
    """The replay preset (real walks replayed into a simulated study,
    ``tests/own_study.py``) generated once per test run; tests build their own studies
    from it and only read it."""
    from own_study import replay_study

    return built_once(tmp_path_factory, "replay_simulated", replay_study)


def _report_tiny(work: Path, snakemake: Path = SNAKEMAKE) -> None:
    res = tiny_workflow(work, snakemake=snakemake)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-4000:]


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory) -> Path:
    """The tiny study simulated and reported once per test run, with this venv's
    Snakemake, in a scratch folder that tests only read (dry runs included).  A test that
    runs the workflow for real builds its own folder from a copy of this one
    (:func:`copy_run`: its ``data`` to run from the simulation on, or the whole folder to
    run only what the test adds).  It is the suite's most
    expensive fixture (a whole report): a test that needs a workflow's outputs reads
    these rather than running Snakemake again."""
    return built_once(tmp_path_factory, "tiny_run", _report_tiny)


@pytest.fixture(scope="session")
def tiny_run_snakemake8(tmp_path_factory) -> Path:
    """The same tiny report in another folder, simulated there again with the same seed, on
    the newest Snakemake 8.x (tests/test_snakemake_releases.py, ``.venv-snakemake8``)."""
    from test_snakemake_releases import snakemake_8

    return built_once(tmp_path_factory, "tiny_run_snakemake8",
                      lambda work: _report_tiny(work, snakemake_8()))


def copy_run(run: Path, dst: Path) -> Path:
    """A copy of a run's folder (its ``data``: the simulated study; or the whole run, with
    ``results``, ``reports`` and Snakemake's ``.snakemake`` records), times kept, so that a
    run there finds what was copied up to date (the raw files are the jobs' inputs by paths
    relative to the workflow's folder: workflow/rules/common.smk, ``in_workdir``) and runs
    only what the test adds."""
    shutil.copytree(run, dst, symlinks=True, dirs_exist_ok=True)
    return dst


def planned_jobs(work, targets, wildcards=("method", "view")) -> dict[str, set[str]]:
    """The jobs a dry run of ``targets`` in the tiny workflow at ``work`` would run: rule ->
    the first of ``wildcards`` each job has ("" for a job with none of them)."""
    res = tiny_workflow(work, "-n", targets=targets)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    jobs: dict[str, set[str]] = {}
    for block in ("\n" + out).split("\nrule ")[1:] + ("\n" + out).split("\nlocalrule ")[1:]:
        rule = block.split(":", 1)[0].strip()
        wc = next((ln for ln in block.splitlines() if ln.strip().startswith("wildcards:")),
                  "")
        ws = dict(kv.strip().split("=", 1) for kv in wc.split(":", 1)[-1].split(",")
                  if "=" in kv)
        jobs.setdefault(rule, set()).add(next((ws[w] for w in wildcards if ws.get(w)), ""))
    return jobs


#: The test files that run whole workflows, in the order ``run.py test`` hands them to
#: pytest-xdist's workers (``--dist loadfile --no-loadscope-reorder``): the builder of the
#: shared tiny run on one worker and the longest independent runs on the other first, then
#: the other long files, longest first; every other file follows in collection order.
#: pytest-xdist's own order (the files with most tests first) started the longest runs
#: last, leaving one worker idle at the end.  Only the order matters: it changes how long
#: the suite takes, never what it checks.  Seconds: ``--durations`` on the 2-core machine.
LONG_FIRST = [
    "test_workflow.py",                  # tiny_run (~100 s) + the Snakemake 8 run (~100 s)
    "test_robustness_ensemble.py",       # two tiny twins, 225 s
    "test_workflow_external_default.py",  # the default study, 180 s + the second run
    "test_resume.py",                    # killed at each rule, 186 s
    "test_initstudy.py",                 # the tiny folder through init-study, 150 + 70 s
    "test_external_declarations.py",     # 90 s
    "test_workflow_external.py",         # 65 s
    "test_manual_pose.py",               # 50 s
    "test_workflow_refusals.py",         # 45 s
    "test_crowd.py",                     # 35 s
    "test_people.py",                    # 55 s
    "test_workflow_annotations_only.py",  # 25 s
    "test_legbench.py",                  # 20 s
    "test_paper_figures.py",             # 16 s
]


def pytest_collection_modifyitems(session, config, items):
    rank = {name: i for i, name in enumerate(LONG_FIRST)}
    items.sort(key=lambda it: rank.get(Path(str(it.fspath)).name, len(LONG_FIRST)))
