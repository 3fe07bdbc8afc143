"""Resuming after a kill: what an interrupted job left is never taken as done.

Snakemake marks every output of a job as *incomplete* (``.snakemake/incomplete/``) when
the job starts and unmarks them when it ends, and ``--rerun-incomplete`` (the profiles)
reruns a job whose outputs are still marked.  Snakemake 9 checks the marks only for the
jobs it knows when it first builds its graph, not for those it adds after a checkpoint
(a simulated study's trial sheet is one: every job downstream of it): a run killed while
``ultrasonic_tables`` wrote then resumed to "Nothing to be done" with 21 tables and 11
figures missing, their marks still there.  So before Snakemake plans the run, what a dead
run left marked is removed (:func:`clear_interrupted`): the files are missing, and the
jobs that make them run again, wherever they are in the graph.  That is Snakemake's own
record, read by gaitval; no second mechanism.

:func:`clear_interrupted` runs in the main Snakemake process when it reads the workflow
(``workflow/rules/common.smk``) and in ``run.py report`` before it starts Snakemake,
both only when no Snakemake holds a lock in the working folder (one that runs there
holds one: its marks are its own jobs', at work).  :func:`unfinished_report_items` is the
report rule's last check: it refuses to write the index while a table or figure a step's
provenance record lists is missing, or a file of the report is still marked.
"""
from __future__ import annotations

import base64
import json
import os
import re
import shutil
from pathlib import Path

from gaitval.errors import GaitvalError

#: Snakemake's own files in the working folder
INCOMPLETE = Path(".snakemake") / "incomplete"
LOCKS = Path(".snakemake") / "locks"


def marked_incomplete(workdir: str | Path = ".") -> dict[str, Path]:
    """Output path (as Snakemake names it, relative to ``workdir``) -> its mark file, for
    every output Snakemake marked incomplete in ``workdir``."""
    root = Path(workdir) / INCOMPLETE
    out: dict[str, Path] = {}
    if not root.is_dir():
        return out
    for dirpath, _, files in os.walk(root):
        for name in files:
            mark = Path(dirpath) / name
            parts = mark.relative_to(root).parts
            # a long name is split into folders, each but the last prefixed with "@"
            # (snakemake/persistence/file.py, _record_path)
            b64 = "".join(p[1:] if p.startswith("@") else p for p in parts)
            try:
                path = base64.urlsafe_b64decode(b64.encode()).decode()
            except (ValueError, UnicodeDecodeError):
                continue                  # not a mark (e.g. "migration_underway")
            out[path] = mark
    return out


def locked(workdir: str | Path = ".") -> bool:
    """Whether a Snakemake holds (or a dead one left) a lock in ``workdir``."""
    locks = Path(workdir) / LOCKS
    try:
        return any(locks.iterdir())
    except OSError:
        return False


def clear_interrupted(workdir: str | Path = ".") -> list[str]:
    """Remove every output a killed run left marked incomplete in ``workdir``, and its
    mark; return the paths removed (files and folders that existed).  Nothing when a lock
    is held there (a live Snakemake's marks are its running jobs'): call it only where no
    Snakemake can be at work, as ``run.py`` does after clearing a dead run's lock."""
    if locked(workdir):
        return []
    removed = []
    work = Path(workdir).resolve()
    marks = marked_incomplete(workdir)
    for name, mark in sorted(marks.items()):
        target = Path(name) if Path(name).is_absolute() else work / name
        try:
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
                removed.append(name)
            elif target.exists() or target.is_symlink():
                target.unlink()
                removed.append(name)
        except OSError:                   # a name too long for a file: none was written
            pass
        try:
            gone = not (target.exists() or target.is_symlink())
        except OSError:
            gone = True
        if gone:                          # a file that could not be removed keeps its mark
            try:
                mark.unlink()
            except OSError:
                pass
    _sweep_partial_files({(work / name).parent.parent for name in marks
                          if len(Path(name).parts) > 2 and ".." not in Path(name).parts})
    for dirpath, dirs, files in os.walk(Path(workdir) / INCOMPLETE, topdown=False):
        if not dirs and not files and Path(dirpath) != Path(workdir) / INCOMPLETE:
            try:
                os.rmdir(dirpath)
            except OSError:
                pass
    return removed


#: the temporary file of gaitval.io.atomic (``mkstemp(prefix=".<name>.", suffix=".part")``)
_PARTIAL = re.compile(r"\..+\.[A-Za-z0-9_]{8}\.part")


def _sweep_partial_files(folders) -> None:
    """Remove the atomic writer's temporary files a killed job left in ``folders`` and
    below (the folders above each output it had: a job also writes files it does not
    declare, a table's .md and .tex, its provenance record, beside them)."""
    for top in sorted(folders):
        for dirpath, _, files in os.walk(top):
            for name in files:
                if _PARTIAL.fullmatch(name):
                    try:
                        os.unlink(os.path.join(dirpath, name))
                    except OSError:
                        pass


def unfinished_report_items(reports_dir: str | Path, workdir: str | Path = ".",
                            own_outputs=()) -> list[str]:
    """What keeps a report from being complete: each table or figure a step's provenance
    record (``<reports_dir>/provenance/<step>.json``) lists that is missing, and each file
    under ``reports_dir`` still marked incomplete by an interrupted job (``own_outputs``:
    the calling job's own, marked while it runs).  One line per problem."""
    rd = Path(workdir) / reports_dir          # reports_dir as the workflow names it
    problems = []
    for rec_path in sorted((rd / "provenance").glob("*.json")):
        try:
            rec = json.loads(rec_path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        items = rec.get("items") if isinstance(rec, dict) else None
        if not isinstance(items, list) or "step" not in rec:
            continue                           # report.json, rebuild.json: no step's record
        for item in items:
            if isinstance(item, str) and not (rd / item).exists():
                problems.append(f"{Path(reports_dir) / item}: listed by {rec_path.name} (step "
                                f"{rec['step']}) but missing")
    own = {os.path.normpath(str(o)) for o in own_outputs}
    prefix = os.path.normpath(str(reports_dir)) + os.sep
    for name in sorted(marked_incomplete(workdir)):
        norm = os.path.normpath(name)
        if norm.startswith(prefix) and norm not in own and (Path(workdir) / norm).exists():
            problems.append(f"{norm}: left unfinished by an interrupted job (marked in "
                            f"{INCOMPLETE})")
    return problems


class UnfinishedReport(GaitvalError):
    """The report's tables or figures are not all there."""


def refuse_unfinished(reports_dir: str | Path, own_outputs=(), workdir: str | Path = "."
                      ) -> None:
    """Raise :class:`UnfinishedReport` naming every problem of
    :func:`unfinished_report_items`: the report rule does not finish on a partial report."""
    problems = unfinished_report_items(reports_dir, workdir, own_outputs)
    if problems:
        shown = "; ".join(problems[:8]) + (f"; and {len(problems) - 8} more"
                                           if len(problems) > 8 else "")
        raise UnfinishedReport(
            f"the report {reports_dir} is incomplete ({len(problems)} problem"
            f"{'s' * (len(problems) > 1)}): {shown}",
            hint="a job was interrupted; run the same command again (python3 run.py "
                 "report redoes what a killed run left unfinished)")
