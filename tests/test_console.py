"""gaitval's console for Snakemake (snakemake_logger_plugin_gaitval, run.py report).

The handler is fed the log records Snakemake 9 emits (the same ``extra`` fields as
``snakemake.jobs.Job.log_info``, ``JobScheduler.progress`` ...), so these tests need no
workflow run; a run of the tiny study through it is ``python3 run.py report --config
'run=["tiny"]'`` (docs/report.md, "The console").
"""
from __future__ import annotations

import io
import json
import logging
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

pytest.importorskip("snakemake_interface_logger_plugins")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import run as run_py  # noqa: E402
from snakemake_interface_logger_plugins.common import LogEvent  # noqa: E402

import snakemake_logger_plugin_gaitval as plugin  # noqa: E402


def _handler():
    settings = SimpleNamespace(printshellcmds=True, nocolor=True, quiet=None,
                               debug_dag=False, verbose=False, show_failed_logs=False,
                               stdout=False, dryrun=False)
    h = plugin.LogHandler(settings, None)
    h.stream = io.StringIO()
    return h


def _rec(msg="", level=logging.INFO, **extra):
    r = logging.LogRecord("snakemake.logging", level, __file__, 1, msg, None, None)
    for k, v in extra.items():
        setattr(r, k, v)
    return r


def _batch_log(path: Path, labels, failed=None, verb="register"):
    lines = [f"{len(labels)} task(s) in 2 process(es), 1.00 s wall, 1.50 s cpu"]
    for lab in labels:
        lines.append(f"== {lab}" + (f": FAILED: {failed}" if lab == labels[-1] and failed
                                    else ""))
        lines.append(f"$ gaitval {verb} --trial {lab}")
        lines.append("-- 0.100 s cpu")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def test_one_line_per_step_with_trials_refusals_and_total(tmp_path):
    log = tmp_path / "logs/register/s1/tug.log"
    _batch_log(log, ["T01", "T02", "T03"])
    out = tmp_path / "results/s1/register/tug"
    for t, status in (("T01", "ok"), ("T02", "refused"), ("T03", "ok")):
        (out / t).mkdir(parents=True)
        (out / t / "registration.json").write_text(json.dumps(
            {"trial": t, "status": status,
             "reason": "" if status == "ok" else "[trial T02] clock synchronisation failed "
             + "x" * 300}))
    tlog = tmp_path / "logs/tug_tables.log"
    _batch_log(tlog, ["tug-tables"], verb="tug-tables")
    h = _handler()
    h.emit(_rec("Job stats", event=LogEvent.RUN_INFO, stats={"register": 1, "total": 2}))
    h.emit(_rec(event=LogEvent.JOB_INFO, jobid=3, rule_name="register",
                wildcards={"study": "s1", "family": "tug"}, log=[str(log)], output=[str(out)]))
    h.emit(_rec(event=LogEvent.JOB_FINISHED, job_id=3))
    h.emit(_rec(event=LogEvent.PROGRESS, done=1, total=2))
    h.emit(_rec(event=LogEvent.JOB_INFO, jobid=4, rule_name="tug_tables", wildcards={},
                log=[str(tlog)], output=[]))
    h.emit(_rec(event=LogEvent.SHELLCMD, shellcmd=None))          # not on the console
    h.emit(_rec(event=LogEvent.JOB_FINISHED, job_id=4))
    h.emit(_rec(event=LogEvent.PROGRESS, done=2, total=2))
    h.close()
    lines = h.stream.getvalue().splitlines()
    assert lines[0] == "[gaitval] 2 steps to run"
    assert lines[1].startswith("[1/2] register tug s1  3 trials  ")
    assert lines[1].endswith("1 refused")
    assert lines[2].startswith("    refused T02: [trial T02] clock synchronisation failed")
    assert lines[3].startswith("[2/2] tug_tables  ") and "trial" not in lines[3]
    assert lines[4].startswith("[gaitval] done: 2 of 2 steps in ")
    assert "1 trial(s) refused" in lines[4]
    assert not any("Shell command" in ln for ln in lines)
    assert max(len(ln) for ln in lines) <= plugin.WIDTH


def test_failed_step_names_trial_and_log(tmp_path):
    log = tmp_path / "logs/track/s1/tug_m3.log"
    _batch_log(log, ["T01", "T02"], failed="[file a.c3d, trial T02] marker LHEE missing",
               verb="track")
    h = _handler()
    h.emit(_rec("Job stats", event=LogEvent.RUN_INFO, stats={"total": 1}))
    h.emit(_rec(event=LogEvent.JOB_INFO, jobid=7, rule_name="track",
                wildcards={"study": "s1", "method": "tug_m3"}, log=[str(log)], output=[]))
    h.emit(_rec("Error in rule track", logging.ERROR, event=LogEvent.JOB_ERROR, jobid=7,
                rule_name="track", log=[str(log)]))
    h.emit(_rec("RuleException:\n" + "\n".join(f"line {i} " + "y" * 400 for i in range(20)),
                logging.ERROR, event=LogEvent.ERROR))
    h.close()
    text = h.stream.getvalue()
    lines = text.splitlines()
    assert lines[1] == f"FAILED track tug_m3 s1  (log: {log})"
    assert lines[2] == "    T02: [file a.c3d, trial T02] marker LHEE missing"
    assert "more lines in the log file" in text
    assert lines[-1].startswith("[gaitval] FAILED: 0 of 1 steps")
    assert max(len(ln) for ln in lines) <= plugin.WIDTH


def test_nothing_to_do_is_said_and_a_parse_error_is_not_called_that():
    h = _handler()
    h.close()
    assert h.stream.getvalue() == ""                   # e.g. a ConfigError at parse time
    h = _handler()
    h.emit(_rec(plugin._NOTHING_TO_DO))
    h.close()
    assert "nothing to run" in h.stream.getvalue()


def test_run_py_adds_the_logger_and_verbose_gives_raw_snakemake(monkeypatch):
    monkeypatch.delenv("GAITVAL_CONSOLE", raising=False)
    env = {"PATH": "/bin"}
    rest, logger = run_py.console_args(["--config", "run=[\"tiny\"]"], env)
    assert logger == ["--logger", "gaitval"] and rest == ["--config", "run=[\"tiny\"]"]
    assert env["PYTHONPATH"].split(os.pathsep)[0] == str(run_py.ROOT)
    for flag in ("-v", "--verbose"):
        rest, logger = run_py.console_args([flag, "-n"], {})
        assert (rest, logger) == (["-n"], [])
    monkeypatch.setenv("GAITVAL_CONSOLE", "raw")
    assert run_py.console_args(["-n"], {}) == (["-n"], [])


def test_snakemake_finds_the_plugin_by_its_package_name():
    """Snakemake's registry discovers logger plugins by top-level package name
    (pkgutil); with the checkout on PYTHONPATH, as run.py sets it, it finds gaitval's."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    code = ("from snakemake_interface_logger_plugins.registry import LoggerPluginRegistry;"
            "print(LoggerPluginRegistry().is_installed('gaitval'))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True, cwd="/")
    assert out.stdout.strip() == "True"


def test_a_checkpoint_that_adds_steps_is_said_once(tmp_path):
    h = _handler()
    h.emit(_rec("Job stats", event=LogEvent.RUN_INFO, stats={"total": 5}))
    h.emit(_rec(event=LogEvent.JOB_INFO, jobid=1, rule_name="simulate",
                wildcards={"study": "default"}, log=[], output=[]))
    h.emit(_rec(event=LogEvent.JOB_FINISHED, job_id=1))
    h.emit(_rec(event=LogEvent.PROGRESS, done=1, total=62))
    h.emit(_rec(event=LogEvent.JOB_INFO, jobid=2, rule_name="ingest",
                wildcards={"study": "default"}, log=[], output=[]))
    h.emit(_rec(event=LogEvent.JOB_FINISHED, job_id=2))
    h.emit(_rec(event=LogEvent.PROGRESS, done=2, total=62))
    lines = h.stream.getvalue().splitlines()
    assert lines[1].startswith("[1/5] simulate default")
    assert lines[2] == ("[gaitval] the run now has 62 steps (the trials the finished step "
                        "made known)")
    assert lines[3].startswith("[2/62] ingest default")


def test_snakemake_without_logger_plugins_keeps_its_own_console(monkeypatch):
    """Snakemake 8 (pyproject allows it) has no --logger: run.py then adds nothing."""
    monkeypatch.delenv("GAITVAL_CONSOLE", raising=False)
    monkeypatch.setattr(run_py, "_has_logger_plugins", lambda: False)
    assert run_py.console_args(["-n"], {}) == (["-n"], [])
