"""Verbs of the workflow's jobs: each stage's trials in a process pool
(:mod:`gaitval.jobs.stages`), and the papers' example figures."""
from __future__ import annotations

import sys


def run_verbs(argvs: list[list[str]]) -> None:
    """A batch task (gaitval.jobs.batch): gaitval verbs one after the other, each as
    ``gaitval ARGV`` on the command line would run it (this parser and its exit codes);
    the first that fails stops the task.  Each verb's command line goes to the log first
    (``$ gaitval ...``, quoted as a shell would need it): the same step, by hand."""
    import copy
    import shlex

    from gaitval.cli import parser
    from gaitval.cli_exit import run_verb
    from gaitval.jobs.batch import VerbFailed

    saved = sys.argv
    try:
        for argv in argvs:
            sys.argv = ["gaitval", *argv]        # what a table's provenance records
            print(f"$ {shlex.join(sys.argv)}", flush=True)   # the same step by hand
            args = copy.deepcopy(parser().parse_args(list(argv)))
            rc = run_verb(args.func, args)
            if rc:
                raise VerbFailed(f"gaitval {argv[0]} exited with status {rc}")
    finally:
        sys.argv = saved


def cmd_stage(a) -> int:
    """``gaitval <stage>-trials``: make the job's output folders, then run every trial's
    verbs (:data:`gaitval.jobs.stages.STAGES`) in a pool of ``--threads`` processes forked
    from this one, largest first by ``--sizes`` (the log: gaitval.jobs.batch.run_batch)."""
    from pathlib import Path

    from gaitval.jobs.batch import Task, by_size, run_batch
    from gaitval.jobs.stages import STAGES, aligned, preload

    for d in a.out:
        Path(d).mkdir(parents=True, exist_ok=True)   # a batch of no trial leaves its folder
    tasks = [Task(label, run_verbs, {"argvs": argvs}) for label, argvs in STAGES[a.verb][0](a)]
    if a.sizes:
        tasks = by_size(tasks, [float(s) for s in aligned(a, "sizes")])
    if tasks:
        preload(a.verb)
    run_batch(tasks, a.threads, a.log)
    return 0
