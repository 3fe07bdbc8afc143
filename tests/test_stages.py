"""The stage verbs (gaitval.jobs.stages): each trial's per-trial commands, built from the
arguments a workflow rule passes, and per-trial lists that do not match the trials refused
with one message."""
from __future__ import annotations

import pytest

from gaitval.cli import parser
from gaitval.jobs.stages import STAGES, StageError


def _tasks(argv):
    a = parser().parse_args(argv)
    return STAGES[a.verb][0](a)


def test_track_trials_gives_each_trial_its_track_and_evaluation():
    tasks = _tasks(["track-trials", "--trials", "T1", "T2", "--ingest", "r/ingest",
                    "--register", "r/register/tug", "--sheet", "s.csv", "--subjects",
                    "p.csv", "--config", "v.json", "--method", "m", "--detections", "",
                    "--out", "r/track/m", "r/evaluate/m"])
    assert [label for label, _ in tasks] == ["T1", "T2"]
    track, evaluate = tasks[1][1]
    assert track == ["track", "--sensor", "r/ingest/T2/sensor.parquet", "--sheet", "s.csv",
                     "--subjects", "p.csv", "--trial", "T2", "--method", "m", "--config",
                     "v.json", "--out", "r/track/m/T2.parquet"]
    assert evaluate[:3] == ["evaluate-tug", "--track", "r/track/m/T2.parquet"]
    assert evaluate[-2:] == ["--out", "r/evaluate/m/T2"]


def test_shared_detections_and_mocap_trials_reach_only_their_trials():
    tasks = _tasks(["mtst-trials", "--trials", "A", "B", "--sensors", "a.parquet",
                    "raw b.parquet", "--mocap-trials", "A", "--register", "r/register/mtst",
                    "--sheet", "s", "--subjects", "p", "--config", "v", "--method", "m",
                    "--detections", "r/detect/mtst/d", "--out", "t", "e"])
    (_, (track_a, eval_a)), (_, (track_b, eval_b)) = tasks
    assert "r/register/mtst/A/registration.json" in track_a
    assert "--registration" not in track_b and "--groundtruth" not in eval_b
    assert "r/register/mtst/A/groundtruth.parquet" in eval_a
    assert track_b[track_b.index("--sensor") + 1] == "raw b.parquet"   # one argument
    assert track_b[track_b.index("--detections") + 1] == "r/detect/mtst/d/B.parquet"


def test_a_per_trial_list_of_another_length_is_refused():
    with pytest.raises(StageError, match="--files: 1 value"):
        _tasks(["import-tracks-trials", "--trials", "T1", "T2", "--files", "x.csv",
                "--ingest", "i", "--register", "r", "--config", "v", "--method", "m",
                "--out", "t", "e"])


def test_every_stage_verb_is_a_verb_of_the_cli():
    sub = next(a for a in parser()._actions if a.dest == "verb")
    assert set(STAGES) <= set(sub.choices)


def test_legbench_trials_read_topics_set_sector_and_leg_width_from_the_sheet(tmp_path):
    for bag in ("a b.bag", "b.bag"):
        (tmp_path / bag).write_bytes(b"")
    (tmp_path / "ann.csv").write_text("t_s,x,y\n")
    (tmp_path / "trials.csv").write_text(
        "study,protocol,subject,trial,sensor_kind,sensor_file,sensor_topic,annotation_file,"
        "annotation_topic,scenario\n"
        "lb,legbench,P1,out,lrs,a b.bag,/scan_base2,,/gt,following_outdoor\n"
        "lb,legbench,P2,gen,lrs,b.bag,/scan,ann.csv,,\n")
    (tmp_path / "subjects.csv").write_text("subject,group,leg_width_m\nP1,adult,0.1\n"
                                           "P2,adult,0.12\n")
    tasks = _tasks(["legbench-trials", "--trials", "out", "gen",
                    "--sheet", str(tmp_path / "trials.csv"),
                    "--subjects", str(tmp_path / "subjects.csv"), "--config", "v.json",
                    "--method", "people", "--init", "annotation", "--match-m", "0.5",
                    "--out", "r/legbench/people/annotation", "r/legbench_eval/people/annotation"])
    (_, (track, score)), (_, (track2, score2)) = tasks
    bag = str(tmp_path / "a b.bag")
    assert track == ["legbench-track", "--sensor", bag, "--annotations", bag,
                     "--scan-topic", "/scan_base2", "--annotation-topic", "/gt",
                     "--method", "people", "--init", "annotation", "--leg-width-m", "0.1",
                     "--config", "v.json", "--trial", "out",
                     "--out", "r/legbench/people/annotation/out/track.parquet"]
    assert score[score.index("--benchmark-set") + 1] == "following_outdoor"
    assert "--sector-deg" not in score                     # the following sets: none
    assert score[score.index("--match-m") + 1] == "0.5"
    assert score[-2:] == ["--out", "r/legbench_eval/people/annotation/out"]
    # the second recording: its annotation file (no topic), its subject's leg width
    assert track2[track2.index("--annotations") + 1] == str(tmp_path / "ann.csv")
    assert "--annotation-topic" not in track2 and "--benchmark-set" not in score2
    assert track2[track2.index("--leg-width-m") + 1] == "0.12"
