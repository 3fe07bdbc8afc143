"""Ultrasonic pipeline (seed 003): ranging, registration, alignment, noise identification,
gait parameters against the simulator's truth, Table 1 and the simulator itself."""
from __future__ import annotations

import hashlib

import numpy as np
import pandas as pd
import pytest

from gaitval import ultrasonic as U
from gaitval.simulate import ultrasonic as S
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
    assert U.speed_of_sound(20.0) == pytest.approx(343.5)
    assert U.speed_of_sound(0.0) == pytest.approx(331.5)
    d = U.tof_to_distance(np.array([[1e-3, np.nan], [2e-3, 5e-4]]), np.array([20.0, 30.0]))
    assert d[0, 0] == pytest.approx(0.3435)
    assert np.isnan(d[0, 1])
    assert d[1] == pytest.approx([2e-3 * 349.5, 5e-4 * 349.5])


def test_register_anchors_recovers_a_known_pose():
    anchors = pd.DataFrame({"anchor": ["A", "B", "C", "D"], "x_m": S.PAPER_ANCHORS[:, 0],
                            "y_m": S.PAPER_ANCHORS[:, 1], "z_m": S.PAPER_ANCHORS[:, 2]})
    R, o = _board(5)
    xyz = np.repeat((S.PAPER_ANCHORS @ R.T + o)[None], 10, axis=0)
    mocap = MocapTrial(path="x.c3d", rate_hz=100.0, first_frame=1,
                       labels=["ANC1", "ANC2", "ANC3", "ANC4"], xyz=xyz)
    R2, o2, rms = U.register_anchors(mocap, anchors)
    assert R2 == pytest.approx(R, abs=1e-9) and o2 == pytest.approx(o, abs=1e-9)
    assert rms < 1e-9


def test_missing_receiver_marker_is_a_marker_error(treadmill):
    from gaitval.errors import MarkerError
    mo = treadmill["mocap"]
    bad = MocapTrial(path="bad.c3d", rate_hz=200.0, first_frame=1,
                     labels=["TX", "ANC1", "ANC2", "XXX", "ANC4"], xyz=mo.xyz[:, :5])
    with pytest.raises(MarkerError, match="ANC3"):
        U.register_anchors(bad, treadmill["log"].anchors, trial="t1")


def test_align_xcorr_finds_a_fractional_lag_on_a_gait_like_signal():
    fs = 50.0
    rng = np.random.default_rng(2)
    T = 1.2 * (1 + 0.02 * rng.standard_normal(40))
    phase = np.concatenate([[0], np.cumsum(T)])
    t = np.arange(int(phase[-1] * fs)) / fs
    x = np.sin(2 * np.pi * np.interp(t, phase, np.arange(len(phase))))
    ref = x[100:1800]
    sys = x[100 + 37:1200]                    # sys[i] = ref[i + 37]  ->  lag = +37
    assert U.align_xcorr(ref, sys, fs) == pytest.approx(37.0, abs=0.1)


def test_track_of_a_treadmill_trial_is_within_millimetres(treadmill):
    tr = U.track_ultrasonic_trial(treadmill["log"], {})
    assert list(tr.columns) == U.TRACK_COLUMNS
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
    tr = U.track_ultrasonic_trial(treadmill["log"], {})
    row = {"study": "s", "trial": "t1", "subject": "US01", "speed": "normal",
           "clock_offset_s": np.nan}
    g = U.gait_parameters(tr, treadmill["mocap"], row, SUBJECT, {})
    assert list(g.columns) == U.GAIT_COLUMNS
    assert set(g["parameter"]) == set(U.PARAMETERS)
    assert g.attrs["clock_offset_s"] == pytest.approx(treadmill["meta"]["clock_offset_s"],
                                                      abs=0.005)
    n_true = len(treadmill["strides"])
    assert g.attrs["n_matched"] >= n_true - 4
    by = g.set_index("parameter")
    rmse = {p: float(np.sqrt(np.mean((by.loc[p, "system"] - by.loc[p, "reference"]) ** 2)))
            for p in U.PARAMETERS}
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
    tr = U.track_ultrasonic_trial(treadmill["log"], {})
    off = treadmill["meta"]["clock_offset_s"]
    g = U.gait_parameters(tr, treadmill["mocap"], {"trial": "t1", "clock_offset_s": off},
                          SUBJECT, {})
    assert g.attrs["clock_offset_s"] == off


def test_noise_identification_recovers_simulated_V(pendulums, tmp_path):
    trials = [(lg, mo) for lg, mo, _ in pendulums]
    cfg = {"noise_id": {"W_grid_mps2": [1.0, 5.0, 30.0]}}
    res = U.identify_noise(trials, cfg)
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
    off = U.identify_noise([(lg, mo) for lg, mo, _ in _pendulums(0.002)],
                           {"noise_id": {"W_grid_mps2": [5.0]}})
    assert np.sqrt(off["V_m2"]) == pytest.approx(true_sd, rel=0.25)
    assert np.mean(off["V_m2"]) > np.mean(res["V_m2"])
    assert res["rmse_m"] == pytest.approx(res["search"]["rmse_m"].min())
    # Table 1 from the errors at the identified noise
    from gaitval.tables.ultrasonic_table1 import table1, write_ultrasonic_table1
    ucfg = {**cfg, "ukf": {"W_sigma_mps2": res["W_sigma_mps2"], "V_m2": res["V_m2"]}}
    err = U.pendulum_errors(trials, ucfg, aligned=res["_aligned"])
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
           "n_pendulum_trials": 1, "pendulum_duration_s": 4.0}
    tr1, su1 = S.generate_ultrasonic(tmp_path / "a", cfg, seed=7)
    tr2, su2 = S.generate_ultrasonic(tmp_path / "b", cfg, seed=7)
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    assert list(tr1["protocol"]) == ["treadmill", "pendulum"]
    assert set(tr1["sensor_kind"]) == {"ultrasonic"}
    assert set(tr1["subject"]) <= set(su1["subject"])
    for f in list(tr1["mocap_file"]) + list(tr1["sensor_file"]):
        assert (tmp_path / "a" / f).is_file()
    assert (tmp_path / "a" / "truth" / tr1["trial"][0] / "strides.csv").is_file()


def test_end_to_end_through_files(tmp_path):
    from gaitval.io.c3d import read_c3d
    from gaitval.io.ultrasonic import read_ultrasonic
    cfg = {"n_subjects": 1, "speeds": {"fast": 1.40}, "duration_s": 25.0,
           "n_pendulum_trials": 0}
    trials, _ = S.generate_ultrasonic(tmp_path, cfg, seed=3)
    row = trials.iloc[0].to_dict()
    log = read_ultrasonic(tmp_path / row["sensor_file"], trial=row["trial"])
    mocap = read_c3d(tmp_path / row["mocap_file"], trial=row["trial"])
    tr = U.track_ultrasonic_trial(log, {}, trial=row["trial"])
    g = U.gait_parameters(tr, mocap, row, {"subject": row["subject"]}, {},
                          anchors=log.anchors)
    sl = g[g["parameter"] == "stride_duration"]
    assert len(sl) >= 15
    assert np.sqrt(np.mean((sl["system"] - sl["reference"]) ** 2)) < 0.05


def test_track_that_never_finds_a_stride_is_an_error_not_an_empty_table(treadmill):
    from gaitval.errors import GaitvalError
    tr = U.track_ultrasonic_trial(treadmill["log"], {})
    tr[["x_m", "y_m", "z_m"]] = 0.1                      # a track that never moves
    with pytest.raises(GaitvalError, match="no stride"):
        U.gait_parameters(tr, treadmill["mocap"], {"trial": "t1"}, SUBJECT, {})
