"""The ultrasonic twin's range noise and the pendulum's per-axis error (seed 003 §4.3, Table 1).

The range noise per anchor is the paper's V whatever share of it is common to the four
anchors (:func:`gaitval.simulate.us_sensor.range_noise`); the board's geometry sends the
independent part mostly into the board's plane (X, Y) and the common part into its normal
(Z).  The ``pendulum_error_sd`` physics rows are the pipeline's Table 1 SDs of the study.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.config import deep_merge
from gaitval.errors import ConfigError
from gaitval.evaluate.pendulum import pendulum_alignment, pendulum_errors
from gaitval.evaluate.ultrasonic_config import resolve_cfg
from gaitval.simulate import ultrasonic as S
from gaitval.simulate.us_sensor import PAPER_ANCHORS, PAPER_V_M2, range_noise
from gaitval.types import MocapTrial


@pytest.mark.parametrize("f", [0.0, 0.5, 1.0])
def test_range_noise_keeps_V_per_anchor_and_shares_the_common_part(f):
    e = range_noise(np.random.default_rng(5), 200_000, PAPER_V_M2, f)
    cov = np.cov(e, rowvar=False)
    # eq. (23) sees only the per-anchor variance: the paper's V whatever the split
    assert np.diag(cov) == pytest.approx(PAPER_V_M2, rel=0.02)
    off = cov[~np.eye(4, dtype=bool)]
    assert off == pytest.approx(np.full(12, f * PAPER_V_M2.min()), abs=0.02 * PAPER_V_M2.min())


def test_range_noise_without_a_common_part_draws_as_before():
    # the default (no common part) makes exactly the draws of the earlier independent model,
    # so studies generated before the split stay byte-identical
    got = range_noise(np.random.default_rng(9), 50, PAPER_V_M2, 0.0)
    want = np.random.default_rng(9).standard_normal((50, 4)) * np.sqrt(PAPER_V_M2)[None]
    assert np.array_equal(got, want)
    with pytest.raises(ConfigError, match="noise_common_fraction is 1.5"):
        range_noise(np.random.default_rng(9), 5, PAPER_V_M2, 1.5)


def _still_pendulum_errors(f: float) -> np.ndarray:
    """UKF minus camera (m) on a pendulum hanging still 0.3 m in front of the board, with
    only the range noise (split ``f``) as error source."""
    R, o = S.board_pose(np.random.default_rng(11))
    cfg = {**S.DEFAULTS, "pendulum_duration_s": 12.0, "pendulum_release_deg": [0.0, 0.0],
           "pendulum_marker_offset_m": 0.0, "mocap_noise_m": 0.0, "multipath_prob": 0.0,
           "dropout_prob": 0.0, "noise_common_fraction": f}
    labels, xyz, log, _, _ = S.simulate_pendulum_trial(np.random.default_rng(41), cfg, R, o)
    mo = MocapTrial(path="still.c3d", rate_hz=200.0, first_frame=1, labels=labels, xyz=xyz)
    ucfg = deep_merge(resolve_cfg(None), {"ukf": {"W_sigma_mps2": [1.0, 1.0, 1.0],
                                                  "V_m2": PAPER_V_M2.tolist()}})
    a = pendulum_alignment(log, mo, ucfg, trial="still")
    err = pendulum_errors([(log, mo)], ucfg, names=["still"], aligned=[a])
    return err[["ex_m", "ey_m", "ez_m"]].to_numpy(), a["ref"]


def test_common_mode_range_noise_moves_z_not_x_or_y():
    e0, ref = _still_pendulum_errors(0.0)
    e1, _ = _still_pendulum_errors(1.0)
    sd0, sd1 = e0.std(axis=0), e1.std(axis=0)
    # first-order geometry at the transmitter: per-axis SD of the least-squares position per
    # unit range error, independent per anchor vs common to all four
    p = np.nanmean(ref, axis=0)
    H = (p[None] - PAPER_ANCHORS) / np.linalg.norm(p[None] - PAPER_ANCHORS, axis=1)[:, None]
    Hp = np.linalg.pinv(H)
    indep = np.sqrt(np.diag(Hp @ Hp.T))
    common = np.abs(Hp @ np.ones(4))
    assert indep[1] > indep[0] > indep[2]          # the short (vertical) side resolves worst
    assert common[2] > 1.0 and common[0] < 0.1 and common[1] < 0.1   # all into the normal
    # the filter (same W on every axis) scales each axis alike: with all the noise common
    # Z grows by about common_z / indep_z, X and Y keep only the anchors' independent rest
    # (V above the smallest anchor's)
    assert sd1[2] / sd0[2] == pytest.approx(common[2] / indep[2], rel=0.25)
    assert sd1[0] < 0.5 * sd0[0] and sd1[1] < 0.5 * sd0[1]


def test_pendulum_physics_rows(tmp_path):
    from gaitval.simulate.physics_ultrasonic import (PENDULUM_SD_FACTOR, PENDULUM_SD_M,
                                                     _pendulum_rows, pendulum_errors_of_study)

    cfg = {"n_subjects": 1, "speeds": {"normal": 0.99}, "duration_s": 5.0,
           "n_pendulum_trials": 2, "pendulum_duration_s": 8.0}
    trials, _ = S.generate_ultrasonic(tmp_path, cfg, seed=3)
    trials.to_csv(tmp_path / "trials.csv", index=False)
    rows = pd.DataFrame(_pendulum_rows(tmp_path))
    err = pendulum_errors_of_study(tmp_path)
    assert list(rows["phase"]) == ["X", "Y", "Z"]
    for r, col in zip(rows.itertuples(), ("ex_m", "ey_m", "ez_m")):
        ref = PENDULUM_SD_M[r.phase]
        assert (r.reference, r.lower, r.upper) == pytest.approx(
            (ref, ref / PENDULUM_SD_FACTOR, ref * PENDULUM_SD_FACTOR))
        assert r.value == pytest.approx(err[col].std(ddof=1))
        assert 0.0005 < r.value < 0.01               # mm-scale, as the ranging noise gives
        assert r.passed == (r.lower <= r.value <= r.upper)


def test_a_study_releases_one_pendulum(tmp_path):
    # seed 003 §4.3: one pendulum with one marker, released M times; only the release varies
    plan = S.plan_ultrasonic({"n_subjects": 1, "speeds": {"normal": 0.99},
                              "n_pendulum_trials": 2, "pendulum_duration_s": 6.0}, seed=4)
    metas = []
    for task in [t for t in plan.tasks if t[0] == "pendulum"]:
        rng = np.random.default_rng(task[2])
        *_, meta = S.simulate_pendulum_trial(rng, plan.cfg, plan.R, plan.o, plan.pendulum)
        metas.append(meta)
    assert metas[0]["pendulum_length_m"] == metas[1]["pendulum_length_m"]
    assert metas[0]["marker_offset_m"] == metas[1]["marker_offset_m"]
    assert np.max(np.abs(metas[0]["marker_offset_m"])) <= plan.cfg["pendulum_marker_offset_m"]
    assert metas[0]["theta0_rad"] != metas[1]["theta0_rad"]
    lo, hi = np.deg2rad(plan.cfg["pendulum_release_deg"])
    assert all(lo <= abs(m["theta0_rad"]) <= hi for m in metas)


def test_pendulum_errors_compare_the_low_passed_trajectories():
    # seed 003 §4.1: all data low-passed (2nd-order Butterworth, 10 Hz) before comparison.
    # An estimate off the camera by a 20 Hz ripple plus a 1 Hz sway keeps the sway and
    # loses most of the ripple; without the filter both stay.
    from gaitval.evaluate.pendulum import pendulum_track_errors

    t = np.arange(0.0, 10.0, 0.02)                                  # 50 Hz, as the log
    ref = np.column_stack([0.1 * np.sin(2 * np.pi * 0.7 * t), 0.05 + 0 * t, -0.3 + 0 * t])
    sway = 0.002 * np.sin(2 * np.pi * 1.0 * t)
    ripple = 0.003 * np.sin(2 * np.pi * 20.0 * t)

    class Offset:                              # a tracker role returning camera + error
        def track(self, log, *, trial=None):
            est = ref + np.column_stack([sway + ripple, ripple, 0 * t])
            return pd.DataFrame(est, columns=["x_m", "y_m", "z_m"])

    a = {"t": t, "ref": ref}
    raw, keep = pendulum_track_errors(Offset(), None, a, 0.5)
    lp, _ = pendulum_track_errors(Offset(), None, a, 0.5,
                                  lowpass_cfg=resolve_cfg(None)["lowpass"])
    mid = keep & (t < 9.5)                                       # away from the ends
    assert np.std(raw[mid, 1]) == pytest.approx(0.003 / np.sqrt(2), rel=0.05)
    assert np.std(lp[mid, 1]) < 0.2 * np.std(raw[mid, 1])      # 20 Hz: |H|^2 = 1/17 at 2 fc
    assert np.std(lp[mid, 0]) == pytest.approx(0.002 / np.sqrt(2), rel=0.1)   # 1 Hz kept
    assert keep.sum() == int(np.sum(t >= 0.5))


def test_the_boards_distance_from_the_heel_path_is_a_preset_choice():
    # ultrasonic.board_distance_m (the robustness ensemble varies it): the board plane
    # moves sideways by the change, the same draws otherwise; absent, the default pose
    from gaitval.simulate.us_sensor import BOARD_DISTANCE_M, board_pose

    R0, o0 = board_pose(np.random.default_rng(3))
    R1, o1 = board_pose(np.random.default_rng(3), BOARD_DISTANCE_M + 0.15)
    assert np.array_equal(R0, R1) and o1[0] == o0[0] and o1[2] == o0[2]
    assert o1[1] == pytest.approx(o0[1] - 0.15)                   # further to the left
    p0 = S.plan_ultrasonic({"n_subjects": 1, "speeds": {"normal": 0.99}}, seed=4)
    p1 = S.plan_ultrasonic({"n_subjects": 1, "speeds": {"normal": 0.99},
                            "board_distance_m": 0.45}, seed=4)
    assert p1.o[1] == pytest.approx(p0.o[1] - (0.45 - BOARD_DISTANCE_M))
