"""The shape of a verb: name, handler, help and arguments (one entry of a ``VERBS`` table),
and the help texts several verbs share (the paths are those the workflow passes,
workflow/rules/)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Arg:
    """One argument: ``add_argument(*flags, **options)``."""

    flags: tuple[str, ...]
    options: dict


def A(*flags: str, **options) -> Arg:
    return Arg(flags, options)


@dataclass(frozen=True)
class Verb:
    """``gaitval NAME``: ``handler(args)`` returns the exit code; ``help`` opens its
    ``--help`` and is its line in ``gaitval --help``."""

    name: str
    handler: Callable[..., int]
    help: str
    args: tuple[Arg, ...]

    def __init__(self, name, handler, help, *args):
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "handler", handler)
        object.__setattr__(self, "help", help)
        object.__setattr__(self, "args", args)


SHEET = ("the study's trial sheet, trials.csv (data/<study>/trials.csv for a simulated "
         "study; docs/formats.md, Trial sheet)")
SUBJECTS = "the study's subject table, subjects.csv (leg width, height; docs/formats.md)"
TRIAL = "trial id: a row of the trial sheet (named in errors and outputs)"
REPORTS = ("the report folder (reports/<run> in the workflow): the step's provenance record "
           "goes to its provenance/ (default: reports)")
HASH = "the run's config hash, written into the provenance record (default: empty)"
TABLES = "folder the tables go to, each as .csv, .md, .tex (reports/<run>/tables)"
FIGURES = "folder the figures go to, PNG (reports/<run>/figures)"

#: the arguments several verbs share
SHEET_ARG = A("--sheet", required=True, help=SHEET)
SUBJECTS_ARG = A("--subjects", required=True, help=SUBJECTS)
TRIAL_ARG = A("--trial", required=True, help=TRIAL)
REPORTS_ARG = A("--reports-dir", default="reports", help=REPORTS)
HASH_ARG = A("--config-hash", default="", help=HASH)
TABLES_ARG = A("--tables-dir", required=True, help=TABLES)
FIGURES_ARG = A("--figures-dir", required=True, help=FIGURES)
#: one LRS trial's ingested scan log, the input of its per-trial steps
SCAN_LOG_ARG = A("--sensor", required=True,
                 help="the trial's ingested scan log "
                      "(results/<study>/ingest/<trial>/sensor.parquet)")
#: a method's name where it only labels the rows of the tables
LABEL_METHOD_ARG = A("--method", required=True,
                     help="the method's name (its label in the tables)")
#: the arguments closing a table verb: provenance, config hash, where tables and figures go
TABLE_OUTPUT_ARGS = (REPORTS_ARG, HASH_ARG, TABLES_ARG, FIGURES_ARG)


def view_arg(family: str, contents: str) -> Arg:
    """``--config``: the method's config view of a per-trial step of ``family``."""
    return A("--config", required=True,
             help=f"the method's config view (results/<study>/config_views/{family}/"
                  f"<method>.json): {contents}")


def eval_dirs_arg(help: str) -> Arg:
    """The positional evaluation folders a table verb reads."""
    return A("inputs", nargs="+", metavar="EVAL_DIR", help=help)


def labelled_eval_args(family: str, contents: str, out: str) -> tuple[Arg, ...]:
    """The closing arguments of an evaluation verb: subjects, trial, the method's label,
    its config view and the output folder."""
    return (SUBJECTS_ARG, TRIAL_ARG, LABEL_METHOD_ARG, view_arg(family, contents),
            A("--out", required=True, help=out))
