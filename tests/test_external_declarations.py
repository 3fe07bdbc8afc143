"""Issue 37: a study declares its external methods in its own study.yaml
(``external_methods:``), validated like the rest of it before any job runs: the schema
(name, path with {trial}, protocols, topic, legs), a name not already a method nor also in
the workflow config, the same names in every study of run, and every trial's file there,
inside the study's folder; and an edited entry (``legs``, ``topic``) reruns that
method's jobs and only those (dry runs on a copy of the session's tiny run)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

from gaitval.configcheck import check_study_file
from gaitval.errors import ConfigError
from gaitval.pipeline.steps.declarations import external_declarations, missing_external_files

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = Path(sys.executable).parent / "snakemake"


def study(tmp_path: Path, name: str, external: dict | None, trials=("tug_a", "tug_b")):
    folder = tmp_path / name
    folder.mkdir()
    sheet = folder / "trials.csv"
    sheet.write_text("study,protocol,subject,trial\n" + "".join(
        f"{name},{t.split('_')[0]},S1,{t}\n" for t in trials))
    if external is not None:
        (folder / "study.yaml").write_text(yaml.safe_dump({"external_methods": external}))
    return sheet


ENTRY = {"path": "ext/{trial}.tracks.csv", "protocols": ["tug"]}


def test_study_methods_join_the_configs_per_study(tmp_path):
    a = study(tmp_path, "a", {"mine": ENTRY})
    got = external_declarations({"cfg": {"path": "c/{trial}.csv"}}, {"a": a}, {"tug_m1"})
    assert got == {"a": {"cfg": {"path": "c/{trial}.csv"}, "mine": ENTRY}}


@pytest.mark.parametrize("external, config, words", [
    ({"tug_m1": ENTRY}, {}, ["external_methods.tug_m1", "already a tracking method"]),
    ({"mine": ENTRY}, {"mine": ENTRY}, ["external_methods.mine", "also declared in the "
                                        "workflow config"]),
])
def test_a_taken_name_is_refused_naming_the_study_yaml(tmp_path, external, config, words):
    a = study(tmp_path, "a", external)
    with pytest.raises(ConfigError) as exc:
        external_declarations(config, {"a": a}, {"tug_m1"})
    msg = str(exc.value)
    for w in [str(a.parent / "study.yaml")] + words:
        assert w in msg, (w, msg)


def test_every_study_of_run_declares_the_same_methods(tmp_path):
    a = study(tmp_path, "a", {"mine": ENTRY})
    b = study(tmp_path, "b", None)
    with pytest.raises(ConfigError, match="study 'b' of run \\['a', 'b'\\] does not declare "
                                          "it"):
        external_declarations({}, {"a": a, "b": b}, set())
    (b.parent / "study.yaml").write_text(yaml.safe_dump({"external_methods": {
        "mine": {"path": "x/{trial}.csv", "protocols": ["tug", "mtst"]}}}))
    with pytest.raises(ConfigError, match="external_methods.mine.protocols"):
        external_declarations({}, {"a": a, "b": b}, set())
    (b.parent / "study.yaml").write_text(yaml.safe_dump({"external_methods": {
        "mine": {"path": "x/{trial}.csv", "protocols": ["tug"]}}}))
    got = external_declarations({}, {"a": a, "b": b}, set())
    assert got["b"]["mine"]["path"] == "x/{trial}.csv"      # each study its own files


def test_missing_and_outside_files_are_named_before_any_job(tmp_path):
    a = study(tmp_path, "a", {"mine": ENTRY}, trials=("tug_a", "tug_b", "mtst_c"))
    with pytest.raises(ConfigError) as exc:
        missing_external_files(a, {"mine": ENTRY}, "study a: external_methods")
    msg = str(exc.value)
    for w in ("study a: external_methods mine", "2 of 2 trials' track files are missing",
              "tug_a.tracks.csv", "relative to the trial sheet's folder"):
        assert w in msg, (w, msg)
    for t in ("tug_a", "tug_b"):                 # the MTST trial is not the entry's
        (a.parent / "ext").mkdir(exist_ok=True)
        (a.parent / "ext" / f"{t}.tracks.csv").write_text("")
    missing_external_files(a, {"mine": ENTRY})
    with pytest.raises(ConfigError, match="leads outside the trial sheet's folder"):
        missing_external_files(a, {"mine": {"path": "../{trial}.csv"}})
    missing_external_files(tmp_path / "not_yet" / "trials.csv", {"mine": ENTRY})  # skipped


@pytest.mark.parametrize("entry, words", [
    ({"mine": {"path": "ext/tracks.csv"}}, ["external_methods.mine.path", "{trial}"]),
    ({"my tracker": ENTRY}, ["external_methods", "my tracker"]),
    ({"mine": {"path": "ext/{trial}.csv", "legs": {"L": "1"}}}, ["legs", "R"]),
    ({"mine": {"path": "ext/{trial}.csv", "protocols": ["ultrasonic"]}},
     ["protocols", "ultrasonic"]),
    ({"mine": {"path": "ext/{trial}.csv", "topc": "/x"}},
     ["topc", "did you mean external_methods.mine.topic"]),
])
def test_study_yaml_schema_refuses_what_cannot_be_checked(tmp_path, entry, words):
    with pytest.raises(ConfigError) as exc:
        check_study_file({"external_methods": entry}, tmp_path / "study.yaml")
    msg = str(exc.value)
    for w in words:
        assert w in msg, (w, msg)


@pytest.mark.slow
def test_the_workflow_stops_at_start_naming_the_missing_files(tmp_path):
    """The declaration reaches the workflow: a dry run stops before any job, naming the
    study.yaml key and the missing files."""
    sheet = study(tmp_path, "mine", {"my_tracker": ENTRY})
    cf = tmp_path / "c.yaml"
    cf.write_text(yaml.safe_dump({"run": ["mine"], "peer_results": "", "studies": {"mine": {
        "trial_sheet": str(sheet), "subjects": str(sheet.parent / "subjects.csv")}}}))
    res = subprocess.run([str(SNAKEMAKE), "-n", "--snakefile", str(ROOT / "Snakefile"),
                          "--directory", str(tmp_path), "--cores", "1",
                          "--force-use-threads", "--configfile", str(cf)],
                         capture_output=True, text=True, timeout=300)
    out = res.stdout + res.stderr
    assert res.returncode != 0
    for w in ("ConfigError", "study mine", "study.yaml] external_methods my_tracker",
              "2 of 2 trials' track files are missing"):
        assert w in out, (w, out[-2000:])


def test_validate_reports_the_studys_external_files(tmp_path):
    """``gaitval validate`` (the helper it calls) names a study.yaml entry's missing files,
    and with --deep each file that does not read (here: units in cm)."""
    from gaitval.pipeline.steps.checks import external_problems

    a = study(tmp_path, "a", {"mine": ENTRY})
    probs = external_problems(a)
    assert len(probs) == 1 and "2 of 2 trials' track files are missing" in probs[0]
    (a.parent / "ext").mkdir()
    good = ("# gaitval-tracks v1\n# units: m\n# frame: sensor\n# clock: sensor\n"
            "t_s,side,x,y\n0.0,L,1.0,0.1\n0.0,R,1.0,-0.1\n")
    (a.parent / "ext" / "tug_a.tracks.csv").write_text(good)
    (a.parent / "ext" / "tug_b.tracks.csv").write_text(good.replace("units: m", "units: cm"))
    assert external_problems(a) == []
    probs = external_problems(a, deep=True)
    assert len(probs) == 1
    for w in ("external_methods.mine", "tug_b.tracks.csv", "trial tug_b", "'units' is 'cm'",
              "(line 2)"):
        assert w in probs[0], (w, probs[0])
    assert external_problems(study(tmp_path, "b", None), deep=True) == []


# -- an edited study.yaml entry reruns that method's jobs, and only those ------------------
EXT_TARGETS = ["results/tiny/evaluate/ext_bag", "results/tiny/evaluate/ext_csv",
               "results/tiny/evaluate/tug_m1"]


def dry_run_jobs(work: Path) -> dict[str, set[str]]:
    """The jobs a dry run of EXT_TARGETS would run: rule -> the ``method``/``view``
    wildcard of each of its jobs (the study's own jobs by rule name alone)."""
    from conftest import planned_jobs

    return planned_jobs(work, EXT_TARGETS, ("method", "view"))


@pytest.fixture(scope="module")
def study_ext_run(tiny_run, tmp_path_factory):
    """A copy of the session's tiny data (tiny_run itself is only read) with two external
    methods in its study.yaml, made from tiny_run's own TUG tracks: ``ext_bag`` (tug_m2's
    legs as leg_tracker's /people_tracked in a ROS 1 bag per trial, each leg a person) and
    ``ext_csv`` (tug_m1's track as an exchange CSV); then the EXT_TARGETS run for real once
    (the ingest, the TUG registration, tug_m1 and the two external methods)."""
    from conftest import copy_run, tiny_workflow
    from gaitval.io.tracks.write import track_to_exchange, write_tracks
    from test_workflow_external import people_bag

    work = tmp_path_factory.mktemp("study_ext")
    copy_run(tiny_run, work)
    study, done = work / "data" / "tiny", tiny_run / "results" / "tiny"
    trials = sorted(p.stem for p in (done / "track" / "tug_m2").glob("*.parquet"))
    assert trials
    for t in trials:
        people_bag(study / "bags" / f"{t}.bag", done / "ingest" / t / "sensor.parquet",
                   pd.read_parquet(done / "track" / "tug_m2" / f"{t}.parquet"))
        write_tracks(track_to_exchange(pd.read_parquet(done / "track" / "tug_m1" /
                                                       f"{t}.parquet")),
                     study / "ext" / f"{t}.tracks.csv")
    cal = study / "study.yaml"
    doc = yaml.safe_load(cal.read_text()) or {}
    doc["external_methods"] = {
        "ext_bag": {"path": "bags/{trial}.bag", "topic": "/people_tracked",
                    "legs": {"L": "1", "R": "2"}, "protocols": ["tug"]},
        "ext_csv": {"path": "ext/{trial}.tracks.csv", "protocols": ["tug"]}}
    cal.write_text(yaml.safe_dump(doc))
    res = tiny_workflow(work, targets=EXT_TARGETS)
    assert res.returncode == 0, res.stderr[-4000:]
    assert dry_run_jobs(work) == {}, "not up to date after its own run"
    return work


@pytest.mark.slow
@pytest.mark.parametrize("key, value", [("legs", {"L": "2", "R": "1"}),
                                        ("topic", "/people_tracked_2")])
def test_editing_a_study_yaml_entry_reruns_that_methods_jobs_only(study_ext_run, key,
                                                                   value):
    """A changed ``legs`` or ``topic`` of ext_bag (read by its jobs from the study.yaml)
    reruns ext_bag's config view and its import-and-evaluate job -- not ext_csv's, not
    tug_m1's, not the study's ingest or registration -- and the original entry back is
    up to date again (dry runs: Snakemake's params trigger, common.smk
    analysis_sections_json)."""
    cal = study_ext_run / "data" / "tiny" / "study.yaml"
    text = cal.read_text()
    doc = yaml.safe_load(text)
    doc["external_methods"]["ext_bag"][key] = value
    try:
        cal.write_text(yaml.safe_dump(doc))
        jobs = dry_run_jobs(study_ext_run)
    finally:
        cal.write_text(text)
    assert jobs == {"config_view": {"ext_bag"}, "track_external": {"ext_bag"}}, jobs
    assert dry_run_jobs(study_ext_run) == {}
