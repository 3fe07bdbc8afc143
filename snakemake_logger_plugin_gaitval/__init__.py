"""gaitval's console for Snakemake: one line per finished step, errors and refusals loud.

A Snakemake 9 logger plugin (``snakemake-interface-logger-plugins``): ``snakemake --logger
gaitval`` (what ``python3 run.py report`` passes) hands every log record of the run to
:class:`LogHandler` instead of Snakemake's own console.  Snakemake finds logger plugins by
the name of their top-level package (``snakemake_logger_plugin_<name>``, by
:mod:`pkgutil`), so this package sits beside ``gaitval/`` and is installed with it
(pyproject.toml); ``run.py`` also puts the checkout on ``PYTHONPATH``, because an editable
install hides a top-level package from :mod:`pkgutil`.

What it prints (stdout, one line each, never longer than :data:`WIDTH` characters):

* at the start, how many steps the run has and where Snakemake's full log is (its own log
  file, ``.snakemake/log/<time>.snakemake.log``, which Snakemake writes as always, with
  every rule's inputs, outputs and reasons);
* per finished step ``[12/62] track tug_m3 default  28 trials  4.1 s``: the running count
  of finished steps out of the run's total, the rule and its wildcards, the trials its
  batch ran (the first line of the job's log, :func:`gaitval.jobs.batch.run_batch`'s
  summary) and its wall time;
* a registration step's refused trials, highlighted, each with its reason (its
  ``registration.json`` files, ``status: refused``);
* a failed step, highlighted, with the trial and message of the batch's first failure and
  the job's log; Snakemake's error message (a few lines, each clipped);
* Snakemake's warnings and errors, each line clipped; everything else (the DAG, job
  stats, reasons, shell commands) only in the log file;
* at the end, the steps done, the time, and the log file again.

The raw Snakemake console comes back with ``python3 run.py report -v`` (or
``GAITVAL_CONSOLE=raw``).  Cluster runs (``--profile workflow/profiles/slurm``) use it
the same way: the plugin runs in the Snakemake that submits the jobs; Snakemake gives no
logger plugin to the jobs themselves (their own logs are SLURM's and the rules' logs).
"""
from __future__ import annotations

import json
import logging
import os
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from snakemake_interface_logger_plugins.base import LogHandlerBase
from snakemake_interface_logger_plugins.common import LogEvent
from snakemake_interface_logger_plugins.settings import LogHandlerSettingsBase

#: the longest line the console prints (a longer one is clipped with "…")
WIDTH = 200
#: at most this many lines of one error message
ERROR_LINES = 8
#: the first line of a batch job's log (gaitval.jobs.batch._write_log)
_BATCH_HEAD = re.compile(r"^(\d+) task\(s\) in (\d+) process\(es\)")
_FAILED = re.compile(r"^== (.+?): FAILED: (.*)$")
try:                         # Snakemake's own words when every output is up to date
    from snakemake.common import NOTHING_TO_BE_DONE_MSG as _NOTHING_TO_DO
except ImportError:           # pragma: no cover - another Snakemake
    _NOTHING_TO_DO = None
#: wildcards shown after the rule, in this order (the study last)
_WILDCARD_ORDER = ("method", "family", "detector", "scope", "view", "system", "name", "study")


@dataclass
class LogHandlerSettings(LogHandlerSettingsBase):
    """No settings: the console is the same for every run."""


@dataclass
class _Job:
    rule: str
    wildcards: dict
    log: list
    output: list
    start: float = field(default_factory=time.monotonic)


def clip(text: str, width: int = WIDTH) -> str:
    """One line of at most ``width`` characters."""
    text = " ".join(str(text).split()) if "\n" in str(text) else str(text).rstrip()
    return text if len(text) <= width else text[:width - 1] + "…"


def _wildcard_text(wildcards: dict) -> str:
    items = dict(wildcards or {})
    order = [k for k in _WILDCARD_ORDER if k in items] + sorted(
        k for k in items if k not in _WILDCARD_ORDER)
    return " ".join(str(items[k]) for k in order)


def batch_summary(log_path) -> tuple[Optional[int], list[tuple[str, str]]]:
    """(trials, [(trial, error)]) from a batch job's log, or (None, []) when the log is no
    batch's, or (None, ...) for a job of one verb (a table, the report: no trial count)."""
    try:
        text = Path(log_path).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None, []
    lines = text.splitlines()
    m = _BATCH_HEAD.match(lines[0]) if lines else None
    if not m:
        return None, []
    failed = [(f.group(1), f.group(2)) for f in map(_FAILED.match, lines) if f]
    labels = [ln[3:].split(":", 1)[0] for ln in lines if ln.startswith("== ")]
    verbs = {ln.split()[2] for ln in lines if ln.startswith("$ gaitval ") and len(ln.split()) > 2}
    n = int(m.group(1))
    if n == 1 and labels and labels[0] in verbs:            # one verb: a table, the report
        return None, failed
    return n, failed


def refused_trials(outputs) -> list[tuple[str, str]]:
    """(trial, reason) of every refused registration in a job's output folders."""
    out = []
    for o in outputs:
        d = Path(o)
        if not d.is_dir():
            continue
        for rec in sorted(d.glob("*/registration.json")):
            try:
                r = json.loads(rec.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                continue
            if r.get("status", "ok") != "ok":
                out.append((str(r.get("trial") or rec.parent.name),
                            str(r.get("reason") or "no reason given")))
    return out


class LogHandler(LogHandlerBase):
    """Snakemake's log records as gaitval's console (module docstring)."""

    def __post_init__(self) -> None:
        self.stream = sys.stdout
        color = os.environ.get("NO_COLOR") is None and not getattr(
            self.common_settings, "nocolor", False)
        self.color = color and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.jobs: dict[int, _Job] = {}
        self.finished: list[tuple[int, str]] = []      # (jobid, line) waiting for PROGRESS
        self.done = 0
        self.total: Optional[int] = None
        self.shown_total: Optional[int] = None      # the total the last lines showed
        self.failed = 0
        self.refused = 0
        self.t0 = time.monotonic()
        self.logfile: Optional[str] = None
        self.started = False
        self.closed = False
        self.errors = 0
        self.nothing_to_do = False

    # -- what Snakemake asks of a plugin --------------------------------------------------
    @property
    def writes_to_stream(self) -> bool:
        return True

    @property
    def writes_to_file(self) -> bool:
        return False

    @property
    def has_filter(self) -> bool:
        return True

    @property
    def has_formatter(self) -> bool:
        return True

    @property
    def needs_rulegraph(self) -> bool:
        return False

    # -- output ---------------------------------------------------------------------------
    def _paint(self, text: str, colour: str) -> str:
        codes = {"red": "31;1", "yellow": "33;1", "green": "32", "dim": "2"}
        return f"\x1b[{codes[colour]}m{text}\x1b[0m" if self.color else text

    def _print(self, text: str, colour: Optional[str] = None) -> None:
        for line in str(text).splitlines() or [""]:
            line = clip(line)
            self.stream.write((self._paint(line, colour) if colour else line) + "\n")
        self.stream.flush()

    def _find_logfile(self) -> None:
        """Snakemake's own log file (its DefaultLogFileHandler on its logger)."""
        if self.logfile:
            return
        for h in logging.getLogger("snakemake.logging").handlers:
            name = getattr(h, "baseFilename", None)
            if name:
                self.logfile = os.path.relpath(name) if not os.path.relpath(
                    name).startswith("..") else name
                return

    # -- records --------------------------------------------------------------------------
    def emit(self, record: logging.LogRecord) -> None:
        try:
            self._emit(record)
        except Exception:                          # a console must never stop the run
            self.handleError(record)

    def _emit(self, record: logging.LogRecord) -> None:
        event = getattr(record, "event", None)
        if event == LogEvent.RUN_INFO:
            self._run_info(getattr(record, "stats", {}) or {})
        elif event == LogEvent.JOB_INFO:
            self.jobs[int(record.jobid)] = _Job(
                record.rule_name, dict(getattr(record, "wildcards", {}) or {}),
                list(getattr(record, "log", []) or []),
                list(getattr(record, "output", []) or []))
        elif event == LogEvent.JOB_FINISHED:
            self._job_finished(int(record.job_id))
        elif event == LogEvent.PROGRESS:
            self.total = int(record.total)
            self._flush_finished(int(record.done))
        elif event == LogEvent.JOB_ERROR:
            self._job_error(record)
        elif event == LogEvent.GROUP_ERROR:
            self._print(f"FAILED: a group of jobs ({record.getMessage()})", "red")
        elif event == LogEvent.ERROR or (event is None and record.levelno >= logging.ERROR):
            self._error(record)
        elif event is None and record.levelno >= logging.WARNING:
            self._print(f"warning: {record.getMessage()}", "yellow")
        elif event is None and record.msg == _NOTHING_TO_DO:
            self.nothing_to_do = True
        # everything else (DAG, shell commands, reasons, resources): the log file only

    def _run_info(self, stats: dict) -> None:
        self._find_logfile()
        total = stats.get("total")
        if self.started or total is None:
            return
        self.started = True
        self.total = self.shown_total = int(total)
        where = f"; Snakemake's full log: {self.logfile}" if self.logfile else ""
        self._print(f"[gaitval] {self.total} steps to run{where}")

    def _label(self, job: _Job) -> str:
        return f"{job.rule} {_wildcard_text(job.wildcards)}".strip()

    def _job_finished(self, jobid: int) -> None:
        job = self.jobs.pop(jobid, None)
        if job is None:
            self.finished.append((jobid, f"job {jobid}"))
            return
        secs = time.monotonic() - job.start
        parts = [self._label(job)]
        trials = None
        for log in job.log:
            trials, _ = batch_summary(log)
            if trials is not None:
                break
        if trials is not None:
            parts.append(f"{trials} trial{'s' if trials != 1 else ''}")
        parts.append(f"{secs:.1f} s")
        line = "  ".join(parts)
        refused = refused_trials(job.output)
        if refused:
            self.refused += len(refused)
            line += "  " + self._paint(f"{len(refused)} refused", "yellow")
            line += "".join(f"\n    refused {t}: {r}" for t, r in refused)
        self.finished.append((jobid, line))

    def _flush_finished(self, done: int) -> None:
        first = done - len(self.finished) + 1
        for i, (_, line) in enumerate(self.finished):
            head, *rest = line.split("\n")
            self._print(f"[{first + i}/{self.shown_total or self.total}] {head}")
            for r in rest:
                self._print(r, "yellow")
        if self.shown_total is not None and self.total != self.shown_total:
            # a checkpoint (the simulation) wrote the trial sheet: its trials' steps
            self._print(f"[gaitval] the run now has {self.total} steps (the trials the "
                        "finished step made known)")
        self.shown_total = self.total
        self.done = done
        self.finished = []

    def _job_error(self, record: logging.LogRecord) -> None:
        self.failed += 1
        wildcards = {}
        job = self.jobs.get(int(getattr(record, "jobid", -1)))
        if job is not None:
            wildcards = job.wildcards
        label = f"{record.rule_name} {_wildcard_text(wildcards)}".strip()
        logs = list(getattr(record, "log", []) or [])
        self._print(f"FAILED {label}" + (f"  (log: {', '.join(logs)})" if logs else ""),
                    "red")
        for log in logs:
            _, failed = batch_summary(log)
            for trial, err in failed:
                self._print(f"    {trial}: {err}", "red")

    def _error(self, record: logging.LogRecord) -> None:
        msg = record.getMessage() if record.msg is not None else ""
        lines = [ln for ln in str(msg).splitlines() if ln.strip()]
        if not lines:
            return
        self.errors += 1
        for ln in lines[:ERROR_LINES]:
            self._print(ln, "red")
        if len(lines) > ERROR_LINES:
            self._print(f"    ... ({len(lines) - ERROR_LINES} more lines in the log file)",
                        "red")

    def close(self) -> None:
        if self.closed:
            return super().close()
        self.closed = True
        if not self.started:
            if self.nothing_to_do:
                self._print("[gaitval] nothing to run: every output is up to date")
        elif getattr(self.common_settings, "dryrun", False):
            self._print(f"[gaitval] dry run: {self.total} steps would run")
        else:
            if self.finished:
                self._flush_finished(self.done + len(self.finished))
            self._find_logfile()
            secs = time.monotonic() - self.t0
            failed = self.failed or self.errors
            state = self._paint("FAILED", "red") if failed else "done"
            extra = (f", {self._paint(f'{self.refused} trial(s) refused', 'yellow')}"
                     if self.refused else "")
            where = f"; Snakemake's full log: {self.logfile}" if self.logfile else ""
            self._print(f"[gaitval] {state}: {self.done} of {self.total} steps in "
                        f"{secs:.0f} s{extra}{where}")
        super().close()
