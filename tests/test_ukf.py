"""The TOA unscented Kalman filter (seed 003 eq. 3-13) and its multipath gate."""
from __future__ import annotations

import numpy as np
import pytest

from gaitval.track.ukf import cv_matrices, run_toa_ukf, toa_ranges, trilaterate, ukf_weights

ANCHORS = np.array([[0.0, 0.0, 0.0], [0.324, 0.0, 0.0], [0.324, 0.230, 0.0],
                    [0.0, 0.230, 0.0]])          # seed 003 §4.1, p1..p4
SIG = np.sqrt([11.0, 9.3, 9.0, 9.0]) * 1e-3        # seed 003 §4.3.2, V in mm^2
W = np.array([30.0, 25.0, 10.0])
GUESS = np.array([0.16, 0.10, -0.30])


def _path(n=1500, fs=50.0):
    t = np.arange(n) / fs
    pos = np.column_stack([0.16 + 0.3 * np.sin(2 * np.pi * t / 1.2),
                           0.10 + 0.08 * np.cos(2 * np.pi * t / 1.2),
                           -0.30 + 0.01 * np.sin(t)])
    return t, pos


def test_weights_by_hand():
    # eq. (13): lambda = alpha^2 (n + kappa) - n = 1e-6 * 6 - 6
    Wm, Wc, lam = ukf_weights(6, 1e-3, 2.0, 0.0)
    assert lam == pytest.approx(6e-6 - 6.0)
    assert Wm.sum() == pytest.approx(1.0, abs=1e-6)
    assert Wm[1] == pytest.approx(1.0 / (2 * 6e-6))            # eq. (12)
    assert Wc[0] - Wm[0] == pytest.approx(1.0 - 1e-6 + 2.0)      # + 1 - alpha^2 + beta


def test_cv_matrices_eq5():
    A, G = cv_matrices(0.02)
    x = np.array([1.0, 2.0, 3.0, 0.5, -1.0, 2.0])
    assert A @ x == pytest.approx([1.01, 1.98, 3.04, 0.5, -1.0, 2.0])
    assert G[0, 0] == pytest.approx(0.0002) and G[3, 0] == pytest.approx(0.02)


def test_trilaterate_exact_ranges():
    p = np.array([0.05, 0.12, -0.25])
    d = np.linalg.norm(ANCHORS - p, axis=1)
    assert trilaterate(d, ANCHORS, GUESS) == pytest.approx(p, abs=1e-9)
    # the mirror solution of the planar array is found from the other side
    assert trilaterate(d, ANCHORS, GUESS * [1, 1, -1])[2] == pytest.approx(0.25, abs=1e-9)


def test_noiseless_constant_velocity_is_recovered():
    t = np.arange(400) / 50.0
    pos = np.column_stack([-0.2 + 0.5 * t / 8, 0.05 + 0.02 * t / 8, -0.3 + 0 * t])
    d = toa_ranges(pos, ANCHORS)
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=[0.01] * 3, V=np.full(4, 1e-10),
                    init_guess=GUESS)
    assert np.abs(r.x[50:, :3] - pos[50:]).max() < 1e-4
    assert r.x[-1, 3] == pytest.approx(0.5 / 8, abs=1e-3)     # velocity 0.0625 m/s


def test_noisy_ranges_track_within_millimetres():
    rng = np.random.default_rng(3)
    t, pos = _path()
    d = toa_ranges(pos, ANCHORS) + rng.standard_normal((len(t), 4)) * SIG
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS)
    rmse = np.sqrt(np.mean((r.x[25:, :3] - pos[25:]) ** 2, axis=0))
    assert np.all(rmse < 0.006), rmse
    assert not r.rejected[25:].any() or r.rejected[25:].mean() < 0.002


def test_multipath_outlier_is_rejected_per_anchor():
    rng = np.random.default_rng(4)
    t, pos = _path(600)
    d = toa_ranges(pos, ANCHORS) + rng.standard_normal((len(t), 4)) * SIG
    k = 300
    d[k, 2] += 0.30                                    # a late echo on receiver 3
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS)
    assert r.rejected[k, 2] and not r.rejected[k, [0, 1, 3]].any()
    assert r.used[k].tolist() == [True, True, False, True]
    err_gated = np.linalg.norm(r.x[k, :3] - pos[k])
    raw = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS,
                      gate_sigma=np.inf)
    err_raw = np.linalg.norm(raw.x[k, :3] - pos[k])
    assert err_gated < 0.01 and err_raw > 3 * err_gated


def test_missing_echo_drops_that_anchor():
    t, pos = _path(200)
    d = toa_ranges(pos, ANCHORS)
    d[100, 1] = np.nan
    d[101] = np.nan                                   # no echo at all: predict only
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS)
    assert r.used[100].tolist() == [True, False, True, True]
    assert not r.used[101].any()
    assert np.all(np.isfinite(r.x[100:]))


def test_matches_filterpy_unscented_kalman_filter():
    """Same model and data through filterpy's UKF (outside reference implementation)."""
    fp = pytest.importorskip("filterpy.kalman")
    rng = np.random.default_rng(5)
    t, pos = _path(300)
    d = toa_ranges(pos, ANCHORS) + rng.standard_normal((len(t), 4)) * SIG
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS,
                    gate_sigma=np.inf)
    pts = fp.MerweScaledSigmaPoints(6, alpha=1e-3, beta=2.0, kappa=0.0)
    f = fp.UnscentedKalmanFilter(6, 4, 0.02, lambda x: toa_ranges(x[:3], ANCHORS),
                                 lambda x, dt: cv_matrices(dt)[0] @ x, pts)
    f.x = r.x[0].copy()
    f.P = np.diag([0.05 ** 2] * 3 + [1.0] * 3)
    f.R = np.diag(SIG ** 2)
    A, G = cv_matrices(0.02)
    f.Q = G @ np.diag(W ** 2) @ G.T
    out = [r.x[0]]
    for k in range(1, len(t)):
        f.predict()
        f.update(d[k])
        out.append(f.x.copy())
    assert np.abs(np.array(out) - r.x).max() < 1e-6


def test_two_simultaneous_late_echoes_are_both_rejected():
    rng = np.random.default_rng(6)
    t, pos = _path(600)
    d = toa_ranges(pos, ANCHORS) + rng.standard_normal((len(t), 4)) * SIG
    k = 300
    d[k, 0] += 0.25
    d[k, 2] += 0.14
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS)
    assert r.used[k].tolist() == [False, True, False, True]
    assert np.linalg.norm(r.x[k, :3] - pos[k]) < 0.01


def test_state_behind_a_planar_array_is_reflected_to_the_guess_side():
    # transmitter passing close to the receiver plane (z -> -0.01 m): the linearised update
    # pushes the state through z = 0, where the mirror image fits the ranges equally well;
    # the filter must stay on the physical side (that of init_guess).  (Near the plane z is
    # barely observable, dr/dz = z/r -> 0, so no accuracy is claimed there.)
    t = np.arange(300) / 50.0
    pos = np.column_stack([0.16 + 0.2 * np.sin(t), 0.1 + 0 * t,
                           -0.01 - 0.2 * (1 + np.cos(2 * t)) / 2])
    d = toa_ranges(pos, ANCHORS)
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=[50.0] * 3, V=SIG ** 2, init_guess=GUESS)
    assert r.reflected.any()
    assert np.all(r.x[:, 2] <= 1e-9)                    # never on the mirror side


def test_lost_filter_reinitialises_by_trilateration():
    t = np.arange(400) / 50.0
    pos = np.tile([0.10, 0.10, -0.30], (400, 1))
    pos[200:] = [0.30, 0.05, -0.45]                     # an instantaneous 0.25 m jump
    d = toa_ranges(pos, ANCHORS)
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=[0.01] * 3, V=SIG ** 2, init_guess=GUESS,
                    reinit_after=10)
    assert r.reinit[0] and r.reinit[200:215].any()
    assert np.abs(r.x[-1, :3] - pos[-1]).max() < 0.005


# -- the filter as a tracker role (registry UKF_TRACKERS, built from config) ---------------
def _log(n=300, seed=6):
    import pandas as pd

    from gaitval.types import UltrasonicLog

    rng = np.random.default_rng(seed)
    t, pos = _path(n)
    d = toa_ranges(pos, ANCHORS) + rng.standard_normal((n, 4)) * SIG
    d[40, 1] = np.nan                                    # a missing echo
    anchors = pd.DataFrame({"anchor": ["ANC1", "ANC2", "ANC3", "ANC4"], "x_m": ANCHORS[:, 0],
                            "y_m": ANCHORS[:, 1], "z_m": ANCHORS[:, 2]})
    return UltrasonicLog(t=t, temperature_c=np.full(n, 20.0), anchors=anchors,
                         distance_m=d), d


def test_toa_ukf_role_is_built_from_config_and_runs_the_filter():
    from gaitval.errors import ConfigError
    from gaitval.track.ukf import TRACK_COLUMNS, UKF_TRACKERS, ToaUkf

    assert "toa_ukf" in UKF_TRACKERS.names()
    default = UKF_TRACKERS.build("toa_ukf")
    assert isinstance(default, ToaUkf) and default.W_sigma_mps2 == [30.0, 25.0, 10.0]
    tracker = UKF_TRACKERS.build({"name": "toa_ukf", "W_sigma_mps2": list(W),
                                  "V_m2": list(SIG ** 2), "gate_sigma": 3.0})
    log, d = _log()
    tr = tracker.track(log, trial="t1")
    assert list(tr.columns) == TRACK_COLUMNS
    r = run_toa_ukf(log.t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS,
                    gate_sigma=3.0)
    assert np.array_equal(tr[["x_m", "y_m", "z_m"]].to_numpy(), r.x[:, :3], equal_nan=True)
    assert tr["used_anchors"].iloc[40] == 3
    with pytest.raises(ConfigError, match="toa_ukf"):
        UKF_TRACKERS.build({"name": "toa_ukf", "W_sigma": [1, 1, 1]})   # not a config name
    with pytest.raises(ConfigError, match="V_m2 has 3 entries"):
        UKF_TRACKERS.build({"name": "toa_ukf", "V_m2": [1e-5] * 3}).track(log)


def test_ultrasonic_config_defaults_are_the_roles():
    from dataclasses import asdict

    from gaitval.evaluate.ultrasonic_config import DEFAULT_CFG, build_tracker
    from gaitval.track.ukf import ToaUkf

    assert DEFAULT_CFG["ukf"] == {k: v for k, v in asdict(ToaUkf()).items()
                                  if k != "mirror_guard"}
    assert build_tracker({"ultrasonic": {"ukf": {"alpha": 0.5}}}).alpha == 0.5


@pytest.mark.slow
def test_warm_up_compiles_what_a_track_then_uses(tmp_path):
    """gaitval.track.ukf.warm_up (the fork server's and run.py's) gives the UKF kernel the
    specialisation a track needs: a track of a 4-anchor log afterwards compiles nothing
    new.  In a fresh process, so that no other test's track has compiled it first."""
    from fresh_process import run_fresh

    code = (
        "from gaitval.track import ukf_kernel as K\n"
        "from gaitval.track.ukf import ToaUkf, warm_up\n"
        "from test_ukf import SIG, W, _log, _path\n"
        "warm_up()\n"
        "before = list(K.ukf_steps.signatures)\n"
        "assert len(before) == 1, before\n"
        "log, _ = _log()\n"
        "tr = ToaUkf(W_sigma_mps2=list(W), V_m2=list(SIG ** 2)).track(log)\n"
        "e = (tr[['x_m', 'y_m', 'z_m']].to_numpy() - _path(300)[1])[25:]\n"
        "assert (e ** 2).mean(axis=0).max() ** 0.5 < 0.006, e\n"
        "assert list(K.ukf_steps.signatures) == before, K.ukf_steps.signatures\n")
    run_fresh(code, tmp_path)


# -- the compiled kernel against the numpy formulation it replaced ---------------------------
def _eventful_ranges(near_plane=True):
    """Ranges with every branch of the per-sample cycle: noise, irregular sample times,
    single and double late echoes, a missing echo, a stretch with no echo at all (the
    filter starves and re-initialises), and (``near_plane``) passes within 1 cm of the
    receiver plane (the mirror state is reflected; there depth is barely observable and
    the track chaotic)."""
    rng = np.random.default_rng(11)
    n = 900
    t = np.cumsum(rng.choice([0.019, 0.020, 0.021], n))     # three distinct time steps
    depth = 0.01 if near_plane else 0.25
    pos = np.column_stack([0.16 + 0.2 * np.sin(t), 0.1 + 0.05 * np.cos(t),
                           -depth - 0.2 * (1 + np.cos(2 * t)) / 2])
    d = toa_ranges(pos, ANCHORS) + rng.standard_normal((n, 4)) * SIG
    d[rng.choice(n, 20, replace=False), 2] += 0.3            # late echoes on receiver 3
    both = rng.choice(n, 8, replace=False)
    d[both, 0] += 0.25                                       # two at once
    d[both, 1] += 0.15
    d[rng.choice(n, 15, replace=False), 3] = np.nan          # missing echoes
    d[500:520] = np.nan                                      # no echo: starve, re-initialise
    return t, d


@pytest.mark.parametrize("gate", [4.0, np.inf])
def test_kernel_agrees_with_the_numpy_formulation(gate):
    """The compiled cycle against the numpy formulation it came from
    (tests/ukf_numpy_reference.py), away from the receiver plane: the same decisions
    (gate, re-initialisation, reflection) and states equal within round-off, amplified by
    W_0 ≈ -1e6 (docs/numerics.md: the kernel makes no attempt to repeat numpy's order of
    operations)."""
    import ukf_numpy_reference as ref

    t, d = _eventful_ranges(near_plane=False)
    kw = dict(W_sigma=[50.0] * 3, V=SIG ** 2, init_guess=GUESS, gate_sigma=gate)
    new, old = run_toa_ukf(t, d, ANCHORS, **kw), ref.run_toa_ukf(t, d, ANCHORS, **kw)
    assert new.reinit.sum() >= 2
    assert new.rejected.any() == np.isfinite(gate)
    for name in ("used", "rejected", "reinit", "reflected"):
        assert np.array_equal(getattr(new, name), getattr(old, name)), name
    assert np.array_equal(np.isnan(new.x), np.isnan(old.x))
    assert np.nanmax(np.abs(new.x[:, :3] - old.x[:, :3])) < 1e-6      # metres
    assert np.nanmax(np.abs(new.P_diag - old.P_diag) / old.P_diag) < 1e-4


def test_kernel_near_the_receiver_plane_reflects_like_the_numpy_formulation():
    """Within 1 cm of the plane a round-off decides on which side an update lands, so the
    tracks part there (here from sample 80 on); before, they agree within round-off, and
    both reflect and re-initialise; the kernel's state stays on the physical side."""
    import ukf_numpy_reference as ref

    t, d = _eventful_ranges(near_plane=True)
    kw = dict(W_sigma=[50.0] * 3, V=SIG ** 2, init_guess=GUESS)
    new, old = run_toa_ukf(t, d, ANCHORS, **kw), ref.run_toa_ukf(t, d, ANCHORS, **kw)
    for r in (new, old):
        assert r.reflected.any() and r.reinit.sum() >= 2
    assert np.nanmax(new.x[:, 2]) <= 1e-9                   # never on the mirror side
    assert np.nanmax(np.abs(new.x[:75, :3] - old.x[:75, :3])) < 1e-6


# -- checked (re-)initialisation (issue 34) ---------------------------------------------
def _late_echo_ranges():
    """The issue's case: at sample 0 anchor 3's echo arrives late (about 0.46 m of extra
    path), from sample 1 on every range is direct."""
    t, pos = _path(200)
    d = toa_ranges(pos, ANCHORS)
    d[0, 2] += 0.46
    return t, pos, d


#: Sample 0 and 1 of the default study's us_US04_slow (issue 34): anchor 3's time of
#: flight 2.333 ms at sample 0 against 1.003 ms at sample 1 (ranges in m).
US04_SLOW_D = np.array([[0.4054554, 0.30581542, 0.80436007, 0.43614037],
                        [0.40446506, 0.30826237, 0.34584694, 0.44204963]])


def test_unchecked_trilateration_of_a_late_echo_runs_away():
    # the bug the check guards against: Gauss-Newton on inconsistent ranges lands far off
    p = trilaterate(US04_SLOW_D[0], ANCHORS, GUESS)
    assert not np.all(np.isfinite(p)) or np.linalg.norm(p - ANCHORS.mean(axis=0)) > 1e3
    _, pos, d = _late_echo_ranges()
    assert np.linalg.norm(trilaterate(d[0], ANCHORS, GUESS) - pos[0]) > 0.2


def test_checked_trilateration_of_the_issue_sample():
    from gaitval.track.ukf import trilaterate_checked

    fix0 = trilaterate_checked(US04_SLOW_D[0], ANCHORS, GUESS)
    fix1 = trilaterate_checked(US04_SLOW_D[1], ANCHORS, GUESS)
    assert fix0.used.tolist() == [True, True, False, True] and fix1.used.all()
    # 20 ms apart: the heel moved millimetres, not kilometres
    assert np.linalg.norm(fix0.p - fix1.p) < 0.01


def test_checked_trilateration_drops_the_late_anchor():
    from gaitval.track.ukf import trilaterate_checked

    _, pos, d = _late_echo_ranges()
    fix = trilaterate_checked(d[0], ANCHORS, GUESS)
    assert fix.reason == ""
    assert fix.used.tolist() == [True, True, False, True]
    assert fix.p == pytest.approx(pos[0], abs=1e-6)
    # consistent ranges: all anchors, the unchecked result bit for bit
    full = trilaterate_checked(d[1], ANCHORS, GUESS)
    assert full.used.all() and np.array_equal(full.p, trilaterate(d[1], ANCHORS, GUESS))


def test_checked_trilateration_refuses_what_no_anchor_set_supports():
    from gaitval.track.ukf import trilaterate_checked

    _, pos, d = _late_echo_ranges()
    two_late = d[1].copy()
    two_late[[1, 2]] += [0.4, 0.7]                    # two late echoes: no 3 ranges agree
    fix = trilaterate_checked(two_late, ANCHORS, GUESS)
    assert fix.reason != "" and np.isnan(fix.p).all() and not fix.used.any()
    three = d[1].copy()
    three[3] = np.nan
    three[2] += 0.5                                   # 3 ranges, inconsistent: no subset
    assert np.isnan(trilaterate_checked(three, ANCHORS, GUESS).p).all()
    far = toa_ranges(np.array([30.0, 0.1, -0.3]), ANCHORS)   # beyond the 20 m range
    assert trilaterate_checked(far, ANCHORS, GUESS).reason == "fewer than 3 ranges"
    assert np.isfinite(trilaterate_checked(far, ANCHORS, GUESS,
                                           max_range_m=50.0).p).all()


def test_filter_starts_at_the_heel_despite_a_late_echo_at_sample_0():
    t, pos, d = _late_echo_ranges()
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS)
    assert r.reinit[0] and r.used[0].tolist() == [True, True, False, True]
    assert np.linalg.norm(r.x[0, :3] - pos[0]) < 1e-6
    assert np.linalg.norm(r.x[:, :3] - pos, axis=1).max() < 0.02


def test_filter_waits_for_a_sample_with_a_fix():
    t, pos, d = _late_echo_ranges()
    d[0, 1] += 0.4                                    # sample 0: two late echoes
    r = run_toa_ukf(t, d, ANCHORS, W_sigma=W, V=SIG ** 2, init_guess=GUESS)
    assert r.refused[0] and not r.reinit[0] and np.isnan(r.x[0]).all()
    assert r.reinit[1] and np.linalg.norm(r.x[1, :3] - pos[1]) < 1e-6
