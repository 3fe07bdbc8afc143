"""Issue 33: a trial sheet's values reach no shell unquoted.

Trial sheets come from collaborators and a reviewer runs them.  Before issue 33, rule
``mtst_track`` put ``{input.sensor}`` (the sheet's ``sensor_file`` for a trial without
mocap) into its command unquoted, and a sheet naming ``lrs/y$(id>PWNED2).scan.parquet`` ran
``id`` in the job's shell.  Every rule's ``shell:`` command quotes each value it
interpolates, and a stage verb passes each trial's value as one argument of a gaitval verb
(gaitval.jobs.stages, gaitval.jobs.batch: no shell at all).  Here:

* every value interpolated into every rule's ``shell:`` command carries Snakemake's ``:q``
  (static check of the rule files), and no ``run:`` block starts a shell or a subprocess;
* a real run of an annotations-only MTST study whose file names hold spaces, quotes,
  ``$()``, backticks and ``;`` succeeds, runs none of the embedded commands, and its job
  log's command for the trial (``$ gaitval mtst-track ...``, quoted for a shell) splits
  into the intended arguments.
"""
from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pandas as pd
import pytest
import yaml

from test_workflow_annotations_only import STUDY, build_study, run_workflow

ROOT = Path(__file__).resolve().parents[1]
RULES = sorted((ROOT / "workflow" / "rules").glob("*.smk"))
HOSTILE = "it's a \"scan\" $(touch PWNED1) `touch PWNED2`; touch PWNED3 &"


def _shell_commands(text: str) -> list[str]:
    """The string literals of every ``shell:`` directive of a rule file, joined."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        if lines[i].strip() == "shell:":
            parts, i = [], i + 1
            while i < len(lines) and lines[i].strip().startswith(('"', "f\"")):
                parts.append(lines[i].strip())
                i += 1
            out.append(" ".join(parts))
        else:
            i += 1
    return out


def test_every_interpolated_value_of_every_rule_is_quoted():
    directives = commands = 0
    for path in RULES:
        text = path.read_text()
        directives += sum(ln.strip() == "shell:" for ln in text.splitlines())
        for cmd in _shell_commands(text):
            fields = re.findall(r"\{([^{}]+)\}", cmd)
            commands += bool(fields)
            for field in fields:
                assert field.endswith(":q"), \
                    f"{path.name}: {{{field}}} reaches the shell unquoted in {cmd[:80]}..."
    assert directives >= 1 and commands == directives    # every command was read


def test_no_run_block_starts_a_shell_or_a_process():
    for path in RULES:
        text = path.read_text()
        for word in ("shell(", "subprocess", "os.system", "os.popen", "shell=True"):
            assert word not in text, f"{path.name}: {word}"


def _hostile_study(work: Path) -> tuple[Path, str, str]:
    """The annotations-only MTST study, its first trial's scan log and annotation file
    renamed to hostile names; returns (config file, trial, new sensor_file)."""
    sheet = build_study(work / "data" / STUDY)
    df = pd.read_csv(sheet, dtype=str, keep_default_na=False)
    trial = df["trial"].iloc[0]
    renamed = {}
    for col, suffix in (("sensor_file", ".scan.parquet"), ("annotation_file",
                                                          ".annotations.csv")):
        old = df.loc[0, col]
        new = f"{Path(old).parent}/{HOSTILE} {col}{suffix}"
        shutil.move(sheet.parent / old, sheet.parent / new)
        df.loc[0, col] = renamed[col] = new
    df = df.iloc[:1]                                  # one trial: the run stays short
    df.to_csv(sheet, index=False)
    cf = work / "hostile.yaml"
    cf.write_text(yaml.safe_dump({
        "studies": {STUDY: {"trial_sheet": str(sheet),
                            "subjects": str(sheet.parent / "subjects.csv")}},
        "run": [STUDY], "peer_results": "",
        "mtst": {"methods": ["mtst_proposed"]}}))
    return cf, trial, renamed["sensor_file"]


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    work = tmp_path_factory.mktemp("hostile")
    cf, trial, sensor = _hostile_study(work)
    return work, cf, trial, sensor


def _no_pwned(work: Path) -> None:
    hits = [p for p in work.rglob("PWNED*")] + [p for p in ROOT.glob("PWNED*")]
    assert not hits, f"a command embedded in a file name ran: {hits}"


@pytest.mark.slow
def test_a_real_run_of_a_hostile_sheet_runs_no_embedded_command(hostile):
    work, cf, trial, sensor = hostile
    res = run_workflow(work, cf)
    assert res.returncode == 0, res.stderr[-4000:]
    track = work / "results" / STUDY / "mtst_track" / "mtst_proposed" / f"{trial}.parquet"
    assert len(pd.read_parquet(track)) > 0
    _no_pwned(work)
    log = (work / "logs" / "mtst_track" / STUDY / "mtst_proposed.log").read_text()
    printed = [ln[2:] for ln in log.splitlines() if ln.startswith("$ gaitval mtst-track ")]
    assert len(printed) == 1, log[-3000:]
    argv = shlex.split(printed[0])
    sheet_dir = work / "data" / STUDY
    # the raw file, one argument, relative to the workflow's folder (common.smk in_workdir)
    assert (work / argv[argv.index("--sensor") + 1]).resolve() == (sheet_dir / sensor).resolve()
    assert argv[argv.index("--trial") + 1] == trial
