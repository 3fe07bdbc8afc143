"""``gaitval <verb>``: the pipeline's steps by hand, one verb per step.

Run ``gaitval --help`` or ``gaitval <verb> --help``.  Every verb reads files and writes
files; a data error prints one line ``gaitval: error: ...`` naming the file, the trial and
the problem, and exits with status 1; a usage error exits with 2
(:mod:`gaitval.cli_exit`).  ``-v``/``-q`` before or after the verb: more or less progress.

The verbs are one table, ``gaitval/cli/verbs/*.toml`` (name, handler, help, arguments;
read by :mod:`gaitval.cli.table`); their handlers live in the modules of this package by
concern: a study's inputs and the report (:mod:`.study`), the laser range sensor studies
(:mod:`.lrs`), the ultrasonic study (:mod:`.feet`), the MTST and rollator studies
(:mod:`.mtst_rollator`) and the workflow's jobs (:mod:`.jobs`).  Every verb is dispatched
the same way: ``handler(args)`` returns the exit code.
"""
from __future__ import annotations

import argparse
import functools
import sys

from gaitval.cli.jobs import run_verbs  # noqa: F401  (a batch task: gaitval.cli.run_verbs)
from gaitval.cli.table import add_verbs, read_table


def build_parser() -> argparse.ArgumentParser:
    """The ``gaitval`` argument parser: one sub-command per verb of the verb table
    (``gaitval/cli/verbs/*.toml``)."""
    from gaitval import __version__
    from gaitval.cli_exit import add_verbosity

    p = argparse.ArgumentParser(
        prog="gaitval", description=__doc__.splitlines()[0].replace("``", ""),
        epilog="'gaitval VERB --help': what the verb reads and writes (the paths the "
               "workflow uses, formats, units, defaults). Exit codes: 0 done, 1 a data "
               "error, 2 a usage error (README, 'When something goes wrong').")
    p.add_argument("--version", action="version", version=f"gaitval {__version__}")
    sub = p.add_subparsers(dest="verb", required=True, metavar="VERB",
                           title="verbs (in pipeline order)")
    add_verbs(sub, read_table())
    add_verbosity(p, sub)
    return p


@functools.cache
def parser() -> argparse.ArgumentParser:
    """:func:`build_parser`, built once per process (~12 ms; a batch job's worker runs
    the verbs of many trials, gaitval.jobs.batch)."""
    return build_parser()


def main(argv: list[str] | None = None) -> int:
    """Run one verb; exit codes 0 ok, 1 data/analysis error, 2 usage (gaitval.cli_exit)."""
    import copy

    from gaitval.cli_exit import configure_logging, run_verb
    from gaitval.jobs.lifeline import verb_process
    verb_process()      # started by a workflow's job: end with its Snakemake (jobs/lifeline.py)
    # a copy: a verb that changes a default list (--methods ...) leaves the next job's alone
    args = copy.deepcopy(parser().parse_args(argv))
    configure_logging(args.verbose, args.quiet)
    return run_verb(args.func, args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
