"""One job, many trials: a rule's per-trial steps in a process pool (issue 38).

The workflow runs one Snakemake job per (study, stage) or (study, stage, method) instead
of one per trial.  The job's stage verb (:mod:`gaitval.jobs.stages`) imports what its
trials need (and loads the trackers' compiled kernels) once, then hands its trials to
:func:`run_batch`, which runs each trial's task in a
:class:`concurrent.futures.ProcessPoolExecutor` of the rule's ``threads`` processes forked
from that process (so a worker pays no import) and writes every trial's output files (one
file, or folder, per trial).  Each batch has its own workers; they exit when the batch
ends, and nothing a worker holds outlives its batch.  Why, and what it costs:
docs/speed.md.

Determinism: a trial's files depend on its inputs only, not on which worker ran it or
in which order; the job's log lists the trials in the order given, whatever the order they
finished in.
"""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import io
import logging
import multiprocessing
import os
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from gaitval.errors import GaitvalError

@dataclass
class Task:
    """One trial's call: ``func(**kwargs)``; ``label`` names it in the log and errors."""

    label: str
    func: Callable[..., Any]
    kwargs: dict = field(default_factory=dict)


class BatchError(GaitvalError):
    """A task of a batch failed; the message is the task's own error, its label first."""


def _call(func, kwargs) -> tuple[bool, str, str, float]:
    """Run one task in a worker: (ok, its printed output and log messages, the error, its
    CPU seconds)."""
    cpu0 = time.process_time()
    ok, text, err = _call_captured(func, kwargs)
    return ok, text, err, time.process_time() - cpu0


def _call_captured(func, kwargs) -> tuple[bool, str, str]:
    out = io.StringIO()
    handler = logging.StreamHandler(out)
    handler.setFormatter(logging.Formatter("gaitval: %(message)s"))
    log = logging.getLogger("gaitval")
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            try:
                func(**kwargs)
            except GaitvalError as exc:
                return False, out.getvalue(), _message(out.getvalue(), exc)
            except (Exception, SystemExit) as exc:          # a bug or a usage error
                if not isinstance(exc, (SystemExit, VerbFailed)):
                    traceback.print_exc(file=out)
                return False, out.getvalue(), _message(out.getvalue(), exc)
        return True, out.getvalue(), ""
    finally:
        log.removeHandler(handler)


def _message(text: str, exc: BaseException) -> str:
    """The task's error: the last ``gaitval[ VERB]: error: ...`` line it printed (the CLI's
    one message naming file, trial and problem, or argparse's usage error), else the
    exception's own message."""
    import re

    lines = [m.group(1) for m in re.finditer(r"^gaitval(?: \S+)?: error: (.*)$", text, re.M)]
    if lines:
        return lines[-1]
    if isinstance(exc, GaitvalError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


class VerbFailed(GaitvalError):
    """A verb of :func:`run_verbs` exited with a non-zero status (its message printed)."""


def run_batch(tasks: list[Task], processes: int, log: str | Path | None = None) -> None:
    """Run every task, ``processes`` at a time, each in a worker process forked from this
    one (a stage verb, :mod:`gaitval.jobs.stages`, imports what its trials need first).

    The log (``log``) starts with the task count, the wall time and the tasks' CPU, then
    gives each task's output under a ``== <label>`` line, by label, ending with its CPU
    seconds (``-- 0.123 s cpu``).  The first task that
    fails stops the batch: the tasks not started are cancelled, the log is written, and
    :class:`BatchError` is raised with that task's label and error (the data problem
    named as the step named it: file, trial, problem).  Give the longest tasks first: the
    pool starts them in this order.
    """
    if not tasks:
        if log is not None:
            Path(log).parent.mkdir(parents=True, exist_ok=True)
            Path(log).write_text("0 task(s) in 0 process(es), 0.00 s wall, 0.00 s cpu\n",
                                 encoding="utf-8")
        return
    processes = max(1, min(int(processes), len(tasks)))
    results: list[tuple[bool, str, str, float] | None] = [None] * len(tasks)
    failed: int | None = None
    t0 = time.perf_counter()
    # each worker dies with this process (a Snakemake killed alone): gaitval/jobs/lifeline.py
    from gaitval.jobs.lifeline import pool_worker

    ctx = multiprocessing.get_context("fork")
    with cf.ProcessPoolExecutor(max_workers=processes, mp_context=ctx,
                                initializer=pool_worker, initargs=(os.getpid(),)) as pool:
        futures = {pool.submit(_call, t.func, t.kwargs): i for i, t in enumerate(tasks)}
        for fut in cf.as_completed(futures):
            i = futures[fut]
            try:
                results[i] = fut.result()
            except cf.CancelledError:
                continue
            except Exception as exc:                      # the worker died (killed, OOM)
                results[i] = (False, "", f"worker process failed: {exc!r}", 0.0)
            if not results[i][0] and failed is None:
                failed = i
                for f in futures:
                    f.cancel()
    wall = time.perf_counter() - t0
    if log is not None:
        _write_log(log, tasks, results, processes, wall)
    if failed is not None:
        label, message = tasks[failed].label, results[failed][2]
        print(f"gaitval: error: [{label}] {message}", file=sys.stderr)
        raise BatchError(f"[{label}] {message}")


def _write_log(log, tasks, results, processes, wall) -> None:
    cpu = sum(r[3] for r in results if r is not None)
    lines = [f"{len(tasks)} task(s) in {processes} process(es), {wall:.2f} s wall, "
             f"{cpu:.2f} s cpu"]
    for t, r in sorted(zip(tasks, results), key=lambda tr: tr[0].label):
        if r is None:
            lines.append(f"== {t.label}: not run (an earlier task failed)")
            continue
        ok, text, err, task_cpu = r
        lines.append(f"== {t.label}" + ("" if ok else f": FAILED: {err}"))
        if text:
            lines.append(text.rstrip("\n"))
        lines.append(f"-- {task_cpu:.3f} s cpu")
    Path(log).parent.mkdir(parents=True, exist_ok=True)
    Path(log).write_text("\n".join(lines) + "\n", encoding="utf-8")


def by_size(tasks: list[Task], sizes: list[float]) -> list[Task]:
    """``tasks`` largest first (``sizes``: e.g. the bytes of each task's main input), the
    original order among equals: the longest trials start first, so the batch does not
    end with one process busy and the others idle."""
    order = sorted(range(len(tasks)), key=lambda i: -sizes[i])
    return [tasks[i] for i in order]


def file_size(path) -> int:
    try:
        return Path(path).stat().st_size
    except OSError:
        return 0
