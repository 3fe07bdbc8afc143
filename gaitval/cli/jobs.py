"""Verbs of the workflow's jobs: each stage's trials in a process pool
(:mod:`gaitval.jobs.stages`), and the papers' example figures."""
from __future__ import annotations

import sys

from gaitval.cli.table import A, Verb
from gaitval.jobs.stages import OPTIONS, STAGES


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


def cmd_paper_figures(a) -> int:
    from gaitval.pipeline.paper_figures import paper_figures_step
    paper_figures_step(a.protocol, a.results, a.figures_dir, a.reports_dir, a.config_hash,
                       a.config, a.sheet, a.subjects)
    return 0


#: the stage verbs, every one with the options of :data:`gaitval.jobs.stages.OPTIONS`
STAGE_VERBS = tuple(
    Verb(name, cmd_stage, f"{text} (a workflow job: the per-trial verbs in a pool of "
         "--threads processes)",
         *(A(f"--{opt.replace('_', '-')}", **kw) for opt, kw in OPTIONS.items()))
    for name, (_, text) in STAGES.items())

FIGURES = (
    Verb("paper-figures", cmd_paper_figures,
         "the papers' example figures of one protocol (Yorozu et al. 2015a Figs. "
         "12-13, Yorozu et al. 2015b Figs. 6a, 8, 9, Chalvatzaki et al. 2017 Fig. 5, "
         "Qi et al. 2014 Figs. 2-4) from a run's results",
         A("protocol", choices=["tug", "mtst", "rollator", "ultrasonic"],
           help="which paper's figures: tug, mtst, rollator, ultrasonic"),
         A("--results", nargs="+", required=True, metavar="DIR",
           help="results/<study> folders; the first with the protocol's results is "
                "drawn"),
         A("--config",
           help="a study config view (mtst: the mtst section; ultrasonic: its strides "
                "and symmetry window)"),
         A("--sheet",
           help="the study's trial sheet (with --subjects: the leg widths of the TUG "
                "and MTST snapshots' observations)"),
         A("--subjects", help="the study's subject table"),
         A("--figures-dir", required=True, help="where the PNGs go"),
         A("--reports-dir", default="reports", help="the report folder (provenance)"),
         A("--config-hash", default="", help="recorded in the provenance")),
)
