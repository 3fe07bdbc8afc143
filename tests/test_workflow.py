"""The whole Snakemake DAG on the tiny simulated study: the session's run (tests/conftest.py).

This is the README's report command on the small study: simulate -> ingest -> register ->
... -> report.  It checks that the DAG runs end to end, that every report item carries
provenance, and that the same config and seed give byte-identical tables.
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import pandas as pd
import pytest

from conftest import SNAKEMAKE, tiny_workflow

ROOT = Path(__file__).resolve().parents[1]


def run_workflow(workdir: Path, *extra: str) -> subprocess.CompletedProcess:
    """The tiny study's report command in ``workdir`` as the session's ``tiny_run``
    (tests/conftest.py) was made, plus ``extra``."""
    return tiny_workflow(workdir, *extra)


@pytest.mark.slow
def test_dag_runs_end_to_end_and_index_has_provenance(tiny_run):
    index = (tiny_run / "reports" / "tiny" / "index.md").read_text()
    assert (tiny_run / "reports" / "tiny" / "index.html").is_file()
    assert "Studies: tiny." in index
    for item in ("study_ingest_tiny", "study_registration_tiny"):
        assert f"### {item}" in index
    # every table in the index is followed by its provenance line; the report's own
    # provenance (rebuild command, config, input checksums, versions) comes once
    assert index.count("_made by step `") >= index.count("\n### ") - index.count("![")
    assert index.count("python3 run.py report") == 1
    for f in ("config.yaml", "inputs.sha256", "environment.txt", "report.json"):
        assert (tiny_run / "reports" / "tiny" / "provenance" / f).is_file(), f
    reg = pd.read_csv(tiny_run / "results" / "tiny" / "registration.csv")
    sheet = pd.read_csv(tiny_run / "data" / "tiny" / "trials.csv")
    assert sorted(reg["trial"]) == sorted(sheet["trial"])
    assert set(reg.columns) >= {"trial", "x_m", "y_m", "yaw_rad", "clock_offset_s",
                                "clock_drift_ppm", "pole_residual_m", "sync_peak",
                                "joint_centre_source", "gt_frames_excluded"}


@pytest.mark.slow
def test_a_track_job_tracks_then_evaluates_every_trial(tiny_run):
    """Issue 38: one TUG, MTST, rollator or ultrasonic job per (study[, method]) runs, for
    each trial, two gaitval verbs (tracking, then its evaluation or the gait parameters) in
    its process pool; its log holds both commands and what both printed, per trial."""
    import re

    for log, track, evaluate, folder in (
            ("track/tiny/tug_m1.log", "track", "evaluate-tug", "track/tug_m1"),
            ("mtst_track/tiny/mtst_m1.log", "mtst-track", "mtst-evaluate",
             "mtst_track/mtst_m1"),
            ("rollator_track/tiny/rollator_kf.log", "rollator-track", "rollator-evaluate",
             "rollator/rollator_kf"),
            ("ultrasonic_track/tiny.log", "ultrasonic-track", "gait-parameters",
             "ultrasonic/track")):
        text = (tiny_run / "logs" / log).read_text()
        trials = re.findall(r"^== (\S+)$", text, re.M)
        assert trials, text[:2000]
        assert len(re.findall(rf"^\$ gaitval {track} ", text, re.M)) == len(trials)
        assert len(re.findall(rf"^\$ gaitval {evaluate} ", text, re.M)) == len(trials)
        written = list((tiny_run / "results" / "tiny" / folder).glob("*.parquet"))
        assert len(written) == len(trials), (log, written)
    assert "category" in (tiny_run / "logs" / "track" / "tiny" / "tug_m1.log").read_text()


@pytest.mark.slow
def test_same_config_and_seed_give_byte_identical_tables(tiny_run, tiny_run_snakemake8):
    """A second run of the same config and seed in another folder -- its own simulation,
    on Snakemake 8.x, the session's run the one tests/test_snakemake_releases.py also
    compares -- gives the same bytes in every table."""
    first = sorted((tiny_run / "reports" / "tiny" / "tables").glob("*.csv"))
    assert first
    for p in first:
        q = tiny_run_snakemake8 / "reports" / "tiny" / "tables" / p.name
        assert q.read_bytes() == p.read_bytes(), p.name


#: The tiny study's tables as the code made them last (docs/numerics.md); regenerate with
#: ``.venv/bin/python tests/data/regenerate_tiny_reference.py`` when a change is meant to
#: alter numbers.
REFERENCE = ROOT / "tests" / "data" / "tiny_reference"
#: The tolerance the tables keep across machines and BLAS builds (docs/numerics.md).
RTOL = 1e-9


@pytest.mark.slow
def test_tables_equal_the_stored_reference_within_the_tolerance(tiny_run):
    """Every number of the tiny report's tables within RTOL of tests/data/tiny_reference
    (or one unit in the 6th printed digit), counts, text and verdicts exactly."""
    from gaitval.report.compare import compare_folders, format_report

    ignore = []
    if not (ROOT / ".." / "shared" / "realdata" / "peer-results").is_dir():
        ignore.append("tables/peer_agreement.csv")          # made only with the peer's file
    diffs = compare_folders(tiny_run / "reports" / "tiny", REFERENCE, rtol=RTOL,
                            ignore=["tables/sensitivity.csv", *ignore])
    assert len(diffs) >= 10
    assert all(d.ok for d in diffs), format_report(diffs, RTOL)


@pytest.mark.slow
def test_switching_run_rebuilds_into_that_runs_folder(tiny_run):
    """After the tiny report, the tiny run is up to date and a default run asks for its
    own reports/default/ (issue 14: it used to say "Nothing to be done" and serve tiny) and
    its own pendulum noise file (a shared one made the other run's ultrasonic jobs rerun
    after every switch)."""
    same = run_workflow(tiny_run, "-n")
    assert same.returncode == 0 and "Nothing to be done" in same.stdout + same.stderr
    other = subprocess.run(
        [str(SNAKEMAKE), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(tiny_run),
         "-n", "--config", 'run=["default"]', f"data_dir={tiny_run / 'data'}"],
        capture_output=True, text=True, timeout=300)
    assert other.returncode == 0, other.stderr[-3000:]
    assert "reports/default/index.md" in other.stdout
    assert "reports/tiny/index.md" not in other.stdout
    # the pendulum noise identification is the run's own (results/runs/<run>/): the
    # default run (its jobs after the simulation are not listed yet) touches nothing of
    # tiny's, so switching back reruns no ultrasonic job of tiny's
    assert "results/runs/tiny/" not in other.stdout
    assert (tiny_run / "results" / "runs" / "tiny" / "ultrasonic_noise.json").is_file()
    assert not (tiny_run / "results" / "ultrasonic_noise.json").exists()


def _planned(res: subprocess.CompletedProcess) -> dict[str, int]:
    """Job counts of a dry run's first "Job stats" table."""
    text = res.stdout + res.stderr
    rows = text.split("Job stats:", 1)[1].split("total", 1)[0].splitlines()
    out = {}
    for row in rows:
        parts = row.split()
        if len(parts) == 2 and parts[1].isdigit():
            out[parts[0]] = int(parts[1])
    return out


@pytest.mark.slow
def test_one_methods_parameter_reruns_only_that_methods_trials(tiny_run):
    """Issue 13: after the tiny report, a new value of one TUG method's parameter plans
    that method's tracks with their evaluations (and its eq. (3)-(4) reading variant's, which
    inherits the override), the TUG tables and the report -- no registration, no
    other method's track, no ultrasonic noise identification or track, no other study
    section's tables or summaries."""
    res = run_workflow(tiny_run,                   # a --config item, then the dry run
                       'tracking={"overrides": {"tug_m1": {"gate__g": 9.21}}}', "-n")
    assert res.returncode == 0, res.stderr[-3000:]
    planned = _planned(res)
    n_tug = len(list((tiny_run / "results" / "tiny" / "track" / "tug_m1").glob("*.parquet")))
    assert n_tug > 0
    assert planned["track"] == 2          # tug_m1 + variant: one job each for the study's trials
    assert "evaluate_tug" not in planned          # no such rule since the track job evaluates
    assert planned["config_view"] == 2
    for rule in ("register", "ingest", "detect", "mtst_track", "rollator_track",
                 "ultrasonic_noise", "ultrasonic_track", "rollator_train", "mtst_tables",
                 "rollator_tables", "ultrasonic_tables", "ingest_summary",
                 "registration_summary"):
        assert rule not in planned, (rule, planned)
    assert planned.get("tug_tables") == 1
    out = res.stdout + res.stderr
    import re
    assert re.search(r"track/tug_m1\b", out) and not re.search(r"track/tug_m2\b", out)


@pytest.mark.slow
def test_a_detector_parameter_detects_once_more_for_its_methods_only(tiny_run):
    """Issue 38: the TUG methods share one detection job per detector spec
    (workflow/rules/detect.smk); a new detector parameter of tug_m1 plans one detection
    with the new spec (tug_m1 and its reading variant share it) and those two tracks, no
    other method's track and no other detection."""
    res = run_workflow(tiny_run,
                       'tracking={"overrides": {"tug_m1": {"detector__max_occluder_m": 0.2}}}',
                       "-n")
    assert res.returncode == 0, res.stderr[-3000:]
    planned = _planned(res)
    assert planned["detect"] == 1 and planned["track"] == 2, planned
    assert "mtst_track" not in planned and "register" not in planned, planned
    shared = list((tiny_run / "results" / "tiny" / "detect" / "tug").iterdir())
    assert len(shared) == 1                 # the tiny run: every TUG method, one detector
    out = res.stdout + res.stderr
    import re
    new = set(re.findall(r"detect/tug/(leg_patterns-[0-9a-f]+)", out))
    assert new and shared[0].name not in new


@pytest.mark.slow
def test_a_rollator_setting_reruns_only_the_rollator_trials(tiny_run, tmp_path):
    """Issues 13 and 38: a new rollator.pf_seed (a section of one protocol family) plans
    the rollator trials' registration (one job per study and family, reading the rollator
    view), the rollator jobs and tables only: the TUG, MTST and ultrasonic jobs, their
    registrations included, read views without the rollator: section
    (config_views/<scope>/)."""
    import pandas as pd

    overlay = tmp_path / "seed.yaml"
    overlay.write_text("rollator:\n  pf_seed: 2018\n")
    res = run_workflow(tiny_run, "--configfile",
                       str(ROOT / "config" / "config.yaml"), str(overlay), "-n")
    assert res.returncode == 0, res.stderr[-3000:]
    planned = _planned(res)
    # the same on the command line: the nested 2018 is a number there too
    cli = run_workflow(tiny_run, 'rollator={"pf_seed": 2018}', "-n")
    assert cli.returncode == 0, cli.stderr[-3000:]
    assert _planned(cli) == planned
    sheet = pd.read_csv(tiny_run / "data" / "tiny" / "trials.csv")
    n_rollator = int((sheet["protocol"] == "rollator").sum())
    assert n_rollator > 0
    import yaml
    extra = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["rollator"]["methods"]
    assert extra == ["people", "people_offline"]
    assert planned["rollator_track"] == 2 + len(extra)    # KF, PF and rollator.methods
    assert planned["rollator_tables"] == 1
    assert planned["register"] == 1                # the rollator family's job only
    import re
    blocks = re.findall(r"^rule register:\n((?:[ \t]+\S.*\n)+)", res.stdout + res.stderr, re.M)
    outputs = [re.search(r"output: (\S+)", b).group(1) for b in blocks]
    assert [o.rstrip(",").split("/")[-2:] for o in outputs] == [["register", "rollator"]], blocks
    for rule in ("track", "mtst_track", "ultrasonic_noise",
                 "ultrasonic_track", "tug_tables", "mtst_tables",
                 "ultrasonic_tables", "ingest"):
        assert rule not in planned, (rule, planned)


@pytest.mark.slow
def test_every_tex_of_the_tiny_report_compiles(tiny_run, tmp_path):
    """Issue 14, scope 4: each table's .tex and verdicts.tex, alone, with pdflatex."""
    import shutil

    from gaitval.tables.latex_compile import compile_tables
    if shutil.which("pdflatex") is None:
        pytest.skip("pdflatex not installed (Debian: texlive-latex-base "
                    "texlive-latex-recommended texlive-latex-extra)")
    rd = tiny_run / "reports" / "tiny"
    tex = sorted(rd.glob("tables/*.tex")) + [rd / "verdicts.tex"]
    assert len(tex) > 10
    res = compile_tables(tex, tmp_path)
    failed = {p: err for p, (ok, err, _) in res.items() if not ok}
    assert not failed, failed


@pytest.mark.slow
def test_the_pages_verdict_table_shows_the_robustness_share_beside_the_outcome(tiny_run):
    # the share sits right after the outcome, before the long "why" text, so that it is in
    # view without scrolling sideways; verdicts.csv keeps its own column order
    import re

    from gaitval.report.verdicts import VERDICT_COLUMNS

    html = (tiny_run / "reports" / "tiny" / "index.html").read_text()
    table = html.split('id="verdicts"', 1)[1].split("</table>", 1)[0]
    head = re.findall(r"<th>([^<]*)</th>", table.split("</tr>", 1)[0])
    assert head.index("robustness") == head.index("outcome") + 1 < head.index("why")
    first = table.split("</tr>", 2)[1]
    assert first.count("<td") == len(head) == len(VERDICT_COLUMNS) - 1      # no "table"
    csv_head = (tiny_run / "reports" / "tiny" / "verdicts.csv").read_text().splitlines()[0]
    assert csv_head.split(",") == list(VERDICT_COLUMNS)
