"""Shared detections (issue 38, gaitval/pipeline/detections.py): a method that tracks from
a detections file made by its detector gives the track it gives when it detects itself;
a file made by another detector, leg width or scan series is refused with the file named;
which methods share a detector."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import GaitvalError
from gaitval.methods import METHODS, track_trial, trial_detector
from gaitval.pipeline.detections import (detect_and_write, detector_key, method_detector,
                                         read_detections)
from tug_synth import tug_scans

W = 0.1


@pytest.fixture(scope="module")
def scans():
    return tug_scans(seed=3)[0]


@pytest.fixture(scope="module")
def detections(scans, tmp_path_factory):
    path = tmp_path_factory.mktemp("det") / "trial.parquet"
    detect_and_write(scans, trial_detector("tug_m1"), W, path, trial="T1")
    return path


@pytest.mark.parametrize("method", ["tug_m1", "tug_m3", "people", "mtst_proposed"])
def test_a_track_from_the_shared_detections_equals_the_track_that_detects(
        scans, detections, method):
    spec = trial_detector(method)
    if spec != trial_detector("tug_m1"):
        pytest.skip(f"{method} has a detector of its own")
    obs = read_detections(detections, spec, W, scans, trial="T1")
    assert len(obs) > 100
    own = track_trial(scans, method, W)
    shared = track_trial(scans, method, W, observations=obs)
    pd.testing.assert_frame_equal(own, shared, check_exact=True)


def test_the_shared_detectors_of_the_default_methods():
    tug = {m: json.dumps(trial_detector(m), sort_keys=True)
           for m in ("tug_m1", "tug_m2", "tug_m3", "people")}
    assert len(set(tug.values())) == 1          # seed 000's methods and the people tracker
    mtst = {m: json.dumps(trial_detector(m), sort_keys=True)
            for m in ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed")}
    assert mtst["mtst_m1"] != mtst["mtst_m2"] == mtst["mtst_m3"] == mtst["mtst_proposed"]
    assert trial_detector("rollator_pf") is None    # reads raw scans
    assert trial_detector("rollator_kf") is None    # a windowed detector, scan by scan
    # a detector parameter changes the spec and so the folder's name; another one does not
    m1 = trial_detector("tug_m1")
    assert trial_detector("tug_m1", {"gate__g": 9.21}) == m1
    moved = trial_detector("tug_m1", {"detector__max_occluder_m": 0.2})
    assert moved != m1 and detector_key(moved) != detector_key(m1)
    # from a config view: tracking.methods and tracking.overrides of the method
    cfg = {"tracking": {"methods": {"mine": METHODS["tug_m2"]},
                        "overrides": {"mine": {"detector__use_fs_u": False}}}}
    assert method_detector(cfg, "mine") == {**m1, "use_fs_u": False}


def test_detections_of_another_detector_leg_width_or_scans_are_refused(scans, detections):
    other = trial_detector("mtst_m1")
    with pytest.raises(GaitvalError, match="another detector") as e:
        read_detections(detections, other, W, scans, trial="T1")
    assert str(detections) in str(e.value) and "T1" in str(e.value)
    with pytest.raises(GaitvalError, match="another leg width"):
        read_detections(detections, trial_detector("tug_m1"), 0.12, scans, trial="T1")
    fewer = dataclasses.replace(scans, t=np.asarray(scans.t)[::2],
                                ranges=np.asarray(scans.ranges)[::2])
    with pytest.raises(GaitvalError, match="another scan series"):
        read_detections(detections, trial_detector("tug_m1"), W, fewer, trial="T1")


def test_the_track_verb_with_detections_writes_the_same_track(scans, detections, tmp_path):
    from gaitval.pipeline.steps.tracking import track_and_write

    a = track_and_write(scans, "tug_m2", W, None, trial="T1", method="tug_m2", source="s",
                        out_parquet=tmp_path / "a.parquet")
    b = track_and_write(scans, "tug_m2", W, None, trial="T1", method="tug_m2", source="s",
                        out_parquet=tmp_path / "b.parquet", detections=detections)
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    assert (tmp_path / "a.parquet").read_bytes() == (tmp_path / "b.parquet").read_bytes()
    with pytest.raises(GaitvalError, match="cannot track from detections"):
        track_and_write(scans, "rollator_pf", W, None, trial="T1", method="rollator_pf",
                        source="s", out_parquet=tmp_path / "c.parquet", detections=detections)
