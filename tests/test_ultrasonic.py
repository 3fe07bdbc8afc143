"""Ultrasonic pipeline (seed 003) stage by stage: ranging (io), anchor registration
(registration), camera reference and its gap rule (groundtruth), the UKF tracker role
(track), alignment and gait parameters (evaluate), noise identification (stats), against the
simulator's truth; Table 1 and the simulator itself."""
from __future__ import annotations

import hashlib

import numpy as np
import pandas as pd
import pytest

from gaitval.evaluate.alignment import align_xcorr
from gaitval.evaluate.pendulum import pendulum_errors
from gaitval.evaluate.ultrasonic import GAIT_COLUMNS, PARAMETERS, gait_parameters
from gaitval.evaluate.ultrasonic_config import build_tracker
from gaitval.io.ultrasonic import distance_to_tof, speed_of_sound, tof_to_distance
from gaitval.registration.anchors import fit_anchor_frame
from gaitval.simulate import ultrasonic as S
from gaitval.stats.noise import identify_noise
from gaitval.track.ukf import TRACK_COLUMNS
from gaitval.types import MocapTrial

CFG = {**S.DEFAULTS, "duration_s": 30.0, "pendulum_duration_s": 12.0}
SUBJECT = {"subject": "US01", "leg_length_m": 0.91, "_t_factor": 1.0}


def _board(seed=11):
    return S.board_pose(np.random.default_rng(seed))


@pytest.fixture(scope="module")
def treadmill():
    R, o = _board()
    labels, xyz, log, truth, meta, strides = S.simulate_treadmill_trial(
        np.random.default_rng(21), CFG, SUBJECT, 0.99, R, o)
    mocap = MocapTrial(path="sim.c3d", rate_hz=CFG["mocap_rate_hz"], first_frame=1,
                       labels=labels, xyz=xyz)
    return {"log": log, "mocap": mocap, "truth": truth, "meta": meta, "strides": strides}


def _pendulums(marker_offset_m):
    R, o = _board()
    cfg = {**CFG, "pendulum_marker_offset_m": marker_offset_m}
    out = []
    for seed in (31, 32, 33):
        labels, xyz, log, truth, meta = S.simulate_pendulum_trial(
            np.random.default_rng(seed), cfg, R, o)
        out.append((log, MocapTrial(path=f"p{seed}.c3d", rate_hz=200.0, first_frame=1,
                                    labels=labels, xyz=xyz), meta))
    return out


@pytest.fixture(scope="module")
def pendulums():
    """Pendulum trials whose camera marker sits exactly on the transducer head."""
    return _pendulums(0.0)


def test_tof_to_distance_by_hand():
    # eq. (2): v_s = 331.5 + 0.6 * 20 = 343.5 m/s;  eq. (1): d = 1 ms * 343.5 m/s
    assert speed_of_sound(20.0) == pytest.approx(343.5)
    assert speed_of_sound(0.0) == pytest.approx(331.5)
    tof = np.array([[1e-3, np.nan], [2e-3, 5e-4]])
    d = tof_to_distance(tof, np.array([20.0, 30.0]))
    assert d[0, 0] == pytest.approx(0.3435)
    assert np.isnan(d[0, 1])
    assert d[1] == pytest.approx([2e-3 * 349.5, 5e-4 * 349.5])
    # the inverse, and the simulator's physical law through the same eq. (1)
    back = distance_to_tof(d, np.array([20.0, 30.0]))
    assert np.allclose(back, tof, equal_nan=True, rtol=1e-15, atol=0)
    t_phys = distance_to_tof(0.3435, 20.0, speed=S.speed_of_sound_true)
    assert t_phys == pytest.approx(0.3435 / (331.3 * np.sqrt(1 + 20.0 / 273.15)))


def _anchor_mocap(labels, seed=5, n=10):
    R, o = _board(seed)
    xyz = np.repeat((S.PAPER_ANCHORS @ R.T + o)[None], n, axis=0)
    return R, o, MocapTrial(path="x.c3d", rate_hz=100.0, first_frame=1, labels=labels,
                            xyz=xyz[:, :len(labels)])


def test_anchor_fit_recovers_a_known_pose_with_either_centre():
    anchors = pd.DataFrame({"anchor": ["A", "B", "C", "D"], "x_m": S.PAPER_ANCHORS[:, 0],
                            "y_m": S.PAPER_ANCHORS[:, 1], "z_m": S.PAPER_ANCHORS[:, 2]})
    R, o, mocap = _anchor_mocap(["ANC1", "ANC2", "ANC3", "ANC4"])
    for centre in ("median", "mean"):
        fit = fit_anchor_frame(mocap, anchors, centre=centre)
        assert fit.R == pytest.approx(R, abs=1e-9) and fit.t == pytest.approx(o, abs=1e-9)
        assert fit.rms_m < 1e-9 and fit.markers == ["ANC1", "ANC2", "ANC3", "ANC4"]
        p_us = np.array([[0.1, 0.2, -0.3]])
        assert fit.to_ultrasonic(p_us @ R.T + o) == pytest.approx(p_us, abs=1e-12)


def test_anchor_fit_uses_three_markers_and_refuses_two(treadmill):
    from gaitval.errors import RegistrationError
    anchors = treadmill["log"].anchors
    R, o, mocap = _anchor_mocap(["ANC1", "ANC2", "XXX", "ANC4"])
    fit = fit_anchor_frame(mocap, anchors, trial="t1")          # three are enough
    assert fit.markers == ["ANC1", "ANC2", "ANC4"]
    assert fit.R == pytest.approx(R, abs=1e-9)
    _, _, two = _anchor_mocap(["ANC1", "XXX", "YYY", "ANC4"])
    with pytest.raises(RegistrationError, match="2 usable anchor marker"):
        fit_anchor_frame(two, anchors, trial="t1")


def test_reference_bridges_gaps_linearly_and_flags_long_ones(treadmill):
    from gaitval.groundtruth.gaps import fill_short_gaps
    from gaitval.groundtruth.reference import reference_trajectory
    mo = treadmill["mocap"]
    i = mo.labels.index("TX")
    xyz = mo.xyz.copy()
    xyz[:, i] = np.linspace(0, 1, len(xyz))[:, None] * [1.0, 2.0, 3.0]    # a straight line
    xyz[100:110, i] = np.nan                   # 10 frames = 0.05 s: short
    xyz[500:560, i] = np.nan                   # 60 frames = 0.30 s: long
    xyz[:3, i] = np.nan                        # at the start: never trusted
    gapped = MocapTrial(path="g.c3d", rate_hz=mo.rate_hz, first_frame=1, labels=mo.labels,
                        xyz=xyz)
    ref = reference_trajectory(gapped, treadmill["log"].anchors, max_gap_s=0.2)
    assert list(np.flatnonzero(ref["gap"])) == [0, 1, 2] + list(range(500, 560))
    assert ref[["x_m", "y_m", "z_m"]].notna().all().all()          # every frame bridged
    # linear bridging of a straight line is exact (the fit only rotates and shifts it)
    p = ref[["x_m", "y_m", "z_m"]].to_numpy()
    step = np.diff(p[3:], axis=0)
    assert np.allclose(step, step[0], atol=1e-12)
    # the same filler's default method leaves the long gap and the start missing
    f, short = fill_short_gaps(xyz[:, i], mo.rate_hz, 0.2)
    assert np.isnan(f[500:560]).all() and np.isnan(f[:3]).all()
    assert short[100:110].all() and not short[500:560].any()


def test_align_xcorr_finds_a_fractional_lag_on_a_gait_like_signal():
    fs = 50.0
    rng = np.random.default_rng(2)
    T = 1.2 * (1 + 0.02 * rng.standard_normal(40))
    phase = np.concatenate([[0], np.cumsum(T)])
    t = np.arange(int(phase[-1] * fs)) / fs
    x = np.sin(2 * np.pi * np.interp(t, phase, np.arange(len(phase))))
    ref = x[100:1800]
    sys = x[100 + 37:1200]                    # sys[i] = ref[i + 37]  ->  lag = +37
    assert align_xcorr(ref, sys, fs) == pytest.approx(37.0, abs=0.1)


def test_track_of_a_treadmill_trial_is_within_millimetres(treadmill):
    tr = build_tracker({}).track(treadmill["log"])
    assert list(tr.columns) == TRACK_COLUMNS
    meta, truth = treadmill["meta"], treadmill["truth"]
    tm = (tr["t_s"] - meta["clock_offset_s"]) / (1 + meta["clock_drift_ppm"] * 1e-6)
    err = np.column_stack([tr[c] - np.interp(tm, truth["t_s"], truth[u])
                           for c, u in (("x_m", "xu_m"), ("y_m", "yu_m"), ("z_m", "zu_m"))])
    inside = (tm >= truth["t_s"].iloc[0]) & (tm <= truth["t_s"].iloc[-1])  # truth = capture
    rmse = np.sqrt(np.mean(err[25:][inside[25:]] ** 2, axis=0))
    assert np.all(rmse < 0.010), rmse
    # the simulated late echoes are caught by the per-anchor gate
    assert tr["rejected_anchors"].sum() >= 0.5 * meta["n_multipath"]


def test_gait_parameters_agree_with_reference_and_truth(treadmill):
    tr = build_tracker({}).track(treadmill["log"])
    row = {"study": "s", "trial": "t1", "subject": "US01", "speed": "normal",
           "clock_offset_s": np.nan}
    g = gait_parameters(tr, treadmill["mocap"], row, SUBJECT, {})
    assert list(g.columns) == GAIT_COLUMNS
    assert set(g["parameter"]) == set(PARAMETERS)
    assert g.attrs["clock_offset_s"] == pytest.approx(treadmill["meta"]["clock_offset_s"],
                                                      abs=0.005)
    n_true = len(treadmill["strides"])
    assert g.attrs["n_matched"] >= n_true - 4
    by = g.set_index("parameter")
    rmse = {p: float(np.sqrt(np.mean((by.loc[p, "system"] - by.loc[p, "reference"]) ** 2)))
            for p in PARAMETERS}
    # the paper's RMSEs (Tables 2-6): 0.027 m, 0.035 s, 0.036 m/s, 0.013, 0.034
    assert rmse["stride_length"] < 0.04
    assert rmse["stride_duration"] < 0.05
    assert rmse["stride_velocity"] < 0.05
    assert rmse["h_symmetry"] < 0.05 and rmse["v_symmetry"] < 0.08
    # the reference's stride duration is the true one (to a 20 ms sample)
    T_ref = by.loc["stride_duration", "reference"].mean()
    assert T_ref == pytest.approx(treadmill["strides"]["duration_s"].mean(), abs=0.02)
    # eq. (17) (S = 2 (max - min) of the heel) vs the belt-relative truth: documented bias
    S_ref = by.loc["stride_length", "reference"].mean()
    ratio = S_ref / treadmill["strides"]["length_m"].mean()
    assert 1.0 < ratio < 1.25


def test_manual_clock_offset_overrides_the_estimate(treadmill):
    tr = build_tracker({}).track(treadmill["log"])
    off = treadmill["meta"]["clock_offset_s"]
    g = gait_parameters(tr, treadmill["mocap"], {"trial": "t1", "clock_offset_s": off},
                          SUBJECT, {})
    assert g.attrs["clock_offset_s"] == off


def test_noise_identification_recovers_simulated_V(pendulums, tmp_path):
    trials = [(lg, mo) for lg, mo, _ in pendulums]
    cfg = {"noise_id": {"W_grid_mps2": [1.0, 5.0, 30.0]}}
    res = identify_noise(trials, cfg)
    true_sd = np.sqrt(CFG["noise_V_m2"])
    got_sd = np.sqrt(res["V_m2"])
    assert got_sd == pytest.approx(true_sd, rel=0.1)           # eq. (23)
    assert all(abs(b) < 0.002 for b in res["bias_m"])
    assert res["noise"]["n_outliers"].sum() > 0               # late echoes excluded
    for (_, _, meta), off in zip(pendulums, res["clock"]["clock_offset_s"]):
        assert off == pytest.approx(meta["clock_offset_s"], abs=0.002)
    assert set(res["W_sigma_mps2"]) <= {1.0, 5.0, 30.0}
    # a marker up to 2 mm off the transducer head (the default) adds its own scatter:
    # eq. (23) pools trials with different marker offsets, so V comes out larger
    off = identify_noise([(lg, mo) for lg, mo, _ in _pendulums(0.002)],
                           {"noise_id": {"W_grid_mps2": [5.0]}})
    assert np.sqrt(off["V_m2"]) == pytest.approx(true_sd, rel=0.25)
    assert np.mean(off["V_m2"]) > np.mean(res["V_m2"])
    assert res["rmse_m"] == pytest.approx(res["search"]["rmse_m"].min())
    # Table 1 from the errors at the identified noise
    from gaitval.tables.ultrasonic_table1 import table1, write_ultrasonic_table1
    ucfg = {**cfg, "ukf": {"W_sigma_mps2": res["W_sigma_mps2"], "V_m2": res["V_m2"]}}
    err = pendulum_errors(trials, ucfg, aligned=res["_aligned"])
    t1 = table1(err)
    assert list(t1["axis"]) == ["X", "Y", "Z"]
    assert t1["net_rmse_mm"].iloc[-1] == pytest.approx(
        np.sqrt((t1["rmse_mm"] ** 2).sum()))
    assert t1["rmse_mm"].max() < 8.0
    assert t1["rmse_mm_published"].tolist() == [4.08, 0.72, 1.08]
    paths = write_ultrasonic_table1(err, tmp_path / "ultrasonic_table1", res)
    assert [p.suffix for p in paths] == [".csv", ".md", ".tex"]
    assert "net_rmse_mm_published" in paths[0].read_text()


def _digest(folder):
    h = hashlib.sha256()
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            h.update(p.relative_to(folder).as_posix().encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def test_generator_is_deterministic_and_writes_sheet_rows(tmp_path):
    cfg = {"n_subjects": 1, "speeds": {"normal": 0.99}, "duration_s": 6.0,
           "n_pendulum_trials": 1, "pendulum_duration_s": 5.0}
    tr1, su1 = S.generate_ultrasonic(tmp_path / "a", cfg, seed=7)
    tr2, su2 = S.generate_ultrasonic(tmp_path / "b", cfg, seed=7)
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    assert list(tr1["protocol"]) == ["treadmill", "pendulum"]
    assert set(tr1["sensor_kind"]) == {"ultrasonic"}
    assert set(tr1["subject"]) <= set(su1["subject"])
    for f in list(tr1["mocap_file"]) + list(tr1["sensor_file"]):
        assert (tmp_path / "a" / f).is_file()
    assert (tmp_path / "a" / "truth" / tr1["trial"][0] / "strides.csv").is_file()


def test_trials_simulated_out_of_order_give_the_same_files(tmp_path):
    # generate_study runs each trial as its own task in a process pool: the order the
    # tasks run in must not change a byte (every trial draws from its own seed)
    cfg = {"n_subjects": 2, "speeds": {"slow": 0.54, "fast": 1.40}, "duration_s": 6.0,
           "n_pendulum_trials": 1, "pendulum_duration_s": 5.0}
    tr1, su1 = S.generate_ultrasonic(tmp_path / "a", cfg, seed=11)
    plan = S.plan_ultrasonic(cfg, seed=11)
    assert len(plan.tasks) == 5
    backwards = {t[1]: S.simulate_ultrasonic_trial(tmp_path / "b", plan, t)
                 for t in reversed(plan.tasks)}
    tr2, su2 = S.finish_ultrasonic(tmp_path / "b", plan,
                                   [backwards[t[1]] for t in plan.tasks])
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    pd.testing.assert_frame_equal(tr1, tr2)
    pd.testing.assert_frame_equal(su1, su2)


def test_end_to_end_through_files(tmp_path):
    from gaitval.io.c3d import read_c3d
    from gaitval.io.ultrasonic import read_ultrasonic
    cfg = {"n_subjects": 1, "speeds": {"fast": 1.40}, "duration_s": 25.0,
           "n_pendulum_trials": 0}
    trials, _ = S.generate_ultrasonic(tmp_path, cfg, seed=3)
    row = trials.iloc[0].to_dict()
    log = read_ultrasonic(tmp_path / row["sensor_file"], trial=row["trial"])
    mocap = read_c3d(tmp_path / row["mocap_file"], trial=row["trial"])
    tr = build_tracker({}).track(log, trial=row["trial"])
    g = gait_parameters(tr, mocap, row, {"subject": row["subject"]}, {},
                          anchors=log.anchors)
    sl = g[g["parameter"] == "stride_duration"]
    assert len(sl) >= 15
    assert np.sqrt(np.mean((sl["system"] - sl["reference"]) ** 2)) < 0.05


def test_track_that_never_finds_a_stride_is_an_error_not_an_empty_table(treadmill):
    from gaitval.errors import GaitvalError
    tr = build_tracker({}).track(treadmill["log"])
    tr[["x_m", "y_m", "z_m"]] = 0.1                      # a track that never moves
    with pytest.raises(GaitvalError, match="no stride"):
        gait_parameters(tr, treadmill["mocap"], {"trial": "t1"}, SUBJECT, {})


def test_a_trial_too_short_for_any_ultrasonic_sample_is_a_config_error(tmp_path):
    from gaitval.errors import ConfigError
    with pytest.raises(ConfigError, match="pendulum_duration_s is 3.0 s"):
        S.generate_ultrasonic(tmp_path, {"n_subjects": 1, "duration_s": 6.0,
                                         "pendulum_duration_s": 3.0}, seed=1)
