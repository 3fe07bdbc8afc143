"""Reports are namespaced by the studies they pool: reports/<run-name>/ (issue 14, scope 3).

A Snakemake dry run (a few seconds, nothing is generated) shows where the `report` rule
would write for a given `run` and which studies its command names, so switching `run`
asks for another folder instead of serving the previous run's stale report.  The full
tiny workflow (tests/test_workflow.py) checks the same on real outputs.
"""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"


def dry_run(workdir: Path, run: str, *extra: str) -> str:
    cmd = [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory",
           str(workdir), "-n", "-p", "--config", f"run={run}",
           f"data_dir={workdir / 'data'}", *extra]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    return res.stdout + res.stderr


def report_job(out: str) -> tuple[str, str]:
    """(output line, log line) of the `report` job of a dry run's printout (a `run:` job:
    its verb's arguments are not printed; a real run's report names its studies,
    tests/test_workflow.py)."""
    m = re.search(r"rule report:\n(.*?)\n\n", out + "\n\n", re.S)
    assert m, "the dry run has no report job:\n" + out[-2000:]
    block = m.group(1)
    output = re.search(r"^\s*output: (.*)$", block, re.M).group(1)
    log = re.search(r"^\s*log: (.*)$", block, re.M).group(1)
    return output, log


@pytest.mark.parametrize("run, name", [
    ('["tiny"]', "tiny"),
    ('["default"]', "default"),
    ('["tiny","default"]', "tiny+default"),
])
@pytest.mark.slow
def test_report_rule_writes_into_the_run_folder(tmp_path, run, name):
    output, log = report_job(dry_run(tmp_path, run))
    outs = [o.strip() for o in output.split(",")]
    assert f"reports/{name}/index.md" in outs and f"reports/{name}/index.html" in outs
    assert all(o.startswith(f"reports/{name}/") for o in outs), outs
    assert log.strip() == f"logs/report/{name}.log"


@pytest.mark.slow
def test_switching_run_asks_for_another_report_not_the_stale_one(tmp_path):
    """A finished tiny report in the folder does not satisfy a default run."""
    done = tmp_path / "reports" / "tiny"
    done.mkdir(parents=True)
    for f in ("index.md", "index.html"):
        (done / f).write_text("Studies: tiny\n")
    output, _ = report_job(dry_run(tmp_path, '["default"]'))
    assert "reports/default/index.md" in output and "reports/tiny/" not in output


@pytest.mark.slow
def test_reports_dir_is_the_root_of_the_run_folders(tmp_path):
    output, _ = report_job(dry_run(tmp_path, '["tiny"]', f"reports_dir={tmp_path}/out"))
    assert f"{tmp_path}/out/tiny/index.md" in output
