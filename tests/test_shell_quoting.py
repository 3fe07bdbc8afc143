"""Issue 33: a trial sheet's values reach the shell only quoted.

Trial sheets come from collaborators and a reviewer runs them.  Before this test, rule
``mtst_track`` put ``{input.sensor}`` (the sheet's ``sensor_file`` for a trial without
mocap) into its command unquoted, and a sheet naming ``lrs/y$(id>PWNED2).scan.parquet`` ran
``id`` in the job's shell.  Here:

* every value interpolated into every rule's ``shell:`` command carries Snakemake's ``:q``
  (static check of the rule files; ``{params.gv}`` is the command itself, quoted where it
  is built);
* a dry run (``-n -p``) of an annotations-only MTST study whose file names hold spaces,
  quotes, ``$()``, backticks and ``;`` prints commands that ``shlex`` splits into the
  intended arguments;
* a real run of one such trial with ``fork_server: false`` (every job through the shell,
  as on a cluster) succeeds and runs none of the embedded commands.
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
                assert field == "params.gv" or field.endswith(":q"), \
                    f"{path.name}: {{{field}}} reaches the shell unquoted in {cmd[:80]}..."
    assert directives >= 15 and commands == directives   # every command was read


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
        "run": [STUDY], "peer_results": "", "fork_server": False,
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
def test_dry_run_commands_split_into_the_intended_arguments(hostile):
    work, cf, trial, sensor = hostile
    res = run_workflow(work, cf, "-n", "-p")
    assert res.returncode == 0, res.stderr[-3000:]
    printed = [ln for ln in (res.stdout + res.stderr).splitlines() if " mtst-track " in ln]
    assert printed, res.stdout[-3000:]
    sheet_dir = work / "data" / STUDY
    for line in printed:
        argv = shlex.split(line)
        assert argv[argv.index("--sensor") + 1] == str((sheet_dir / sensor).resolve())
        assert argv[argv.index("--trial") + 1] == trial
        i = argv.index("mtst-evaluate")
        assert argv[i:].count(trial) == 1
    _no_pwned(work)


@pytest.mark.slow
def test_a_real_run_of_a_hostile_sheet_runs_no_embedded_command(hostile):
    work, cf, trial, _ = hostile
    res = run_workflow(work, cf)
    assert res.returncode == 0, res.stderr[-4000:]
    track = work / "results" / STUDY / "mtst_track" / "mtst_proposed" / f"{trial}.parquet"
    assert len(pd.read_parquet(track)) > 0
    _no_pwned(work)
