"""Role contracts of the tracker, parametrised over every registry, and the roles that the
MTST (seed 001) and rollator (seed 002) methods plug in without touching the loop."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from gaitval.detect import DETECTORS
from gaitval.detect.base import WindowedDetector
from gaitval.errors import ConfigError
from gaitval.methods import METHODS, build_method, build_tracker, track_trial
from gaitval.track import ROLE_REGISTRIES, TRACKER_KINDS, Tracker
from gaitval.track.gate import GateContext, VariableValidationRegion
from gaitval.track.kalman import FILTERS
from gaitval.track.kinds import RawScanTracker
from gaitval.track.leg import empty_result
from gaitval.types import ScanSeries

DT = 0.025


def _walk(n=200, hide=(80, 85), cycle_s=1.0, swing_s=0.4, step_m=0.5):
    """Alternating gait along +x, legs 0.2 m apart: each leg swings ``step_m`` in
    ``swing_s`` with a smooth (sin²) speed profile while the other stands, the right leg
    half a cycle after the left; the right leg is hidden over scans ``hide`` (in stance).
    Returns t, per-scan observations, patterns and the truth (2, n, 2)."""
    t = np.arange(n) * DT
    truth = np.zeros((2, n, 2))
    for f, (offset, y, x0) in enumerate(((0.0, 0.1, 0.0), (0.5, -0.1, 0.25))):
        tau = (t - offset * cycle_s) % cycle_s / swing_s           # position in the swing
        done = np.floor((t - offset * cycle_s) / cycle_s)          # completed swings
        frac = np.where(tau < 1.0, tau - np.sin(2 * np.pi * tau) / (2 * np.pi), 1.0)
        truth[f, :, 0] = x0 + step_m * (np.maximum(done, -1) + 1 + frac)
        truth[f, :, 1] = y
    xy, pats = [], []
    for k in range(n):
        obs = [truth[0, k]] + ([] if hide[0] <= k < hide[1] else [truth[1, k]])
        xy.append(np.array(obs))
        pats.append(["SL"] * len(obs))
    return t, xy, pats, truth


ALL_PARTS = [(role, name) for role, reg in ROLE_REGISTRIES.items() for name in reg.names()]

#: parameters a part gets for the shared walk where its paper defaults are for another
#: sensor set-up: seed 002's σ_a = (1.63, 5.24) m/s² suits legs seen from a rollator that
#: moves with the walker, not a 20 m/s² swing seen from a fixed sensor at 40 Hz
CONTRACT_PARAMS = {("filter", "kf_aniso"): {"q_accel_sd_mps2": (15.0, 10.0),
                                            "r_sd_m": (0.04, 0.03)},
                   # seed 002's laser faces the user (left leg at the smaller bearing); the
                   # shared walk is seen from behind
                   ("init", "facing_pair"): {"sensor_faces_user": False}}


@pytest.mark.parametrize("role, name", ALL_PARTS, ids=[f"{r}-{n}" for r, n in ALL_PARTS])
def test_every_registered_part_drives_the_tracker(role, name):
    """The shared contract: swap one registered part into the default tracker and it still
    follows two walking legs through a short occlusion of a standing leg (within 5 cm),
    reports the hidden scans as UO and returns a full-length result."""
    t, xy, pats, truth = _walk()
    spec = {"name": name, **CONTRACT_PARAMS.get((role, name), {})}
    if (role, name) == ("init", "annotated_pair"):
        # the rater's annotation: the person (midpoint of the legs) at the first scan
        mid = (truth[0, 0] + truth[1, 0]) / 2
        spec.update(k=0, x_m=float(mid[0]), y_m=float(mid[1]))
    tr = Tracker(**{role: spec}, dt_s=DT, sides="as_initialised")
    res = tr.run(t, xy, pats, 0.1)
    assert res.k_init == 0 and res.x.shape == (2, len(t))
    err = np.hypot(res.x - truth[:, :, 0], res.y - truth[:, :, 1])
    assert np.nanmax(err) < 0.05, f"{role}={name}: max error {np.nanmax(err):.3f} m"
    assert (res.pattern[1, 80:85] == "UO").all() and res.observed[0].all()
    assert set(np.unique(res.phase)) <= set(range(6))


@pytest.mark.parametrize("name", ROLE_REGISTRIES["init"].names())
def test_initialiser_contract(name):
    from gaitval.track.observations import DetectionSeries
    # annotated_pair starts where the rater clicked: the pair's midpoint, from scan 0 on
    spec = {"name": name, **({"k": 0, "x_m": 1.0, "y_m": 0.175}
                             if name == "annotated_pair" else {})}
    init = ROLE_REGISTRIES["init"].build(spec)
    empty = DetectionSeries([np.zeros((0, 2))] * 5, [[]] * 5)
    assert init.find(empty, 0.1) is None                     # nobody there: no track
    xy = [np.zeros((0, 2)), np.array([[1.0, 0.3], [1.0, 0.05]])]
    k, il, ir = init.find(DetectionSeries(xy, [[], ["SL", "SL"]]), 0.1)
    assert k == 1 and {il, ir} == {0, 1}


@pytest.mark.parametrize("name", ROLE_REGISTRIES["phase"].names())
def test_phase_model_contract(name):
    P = ROLE_REGISTRIES["phase"].build(name)
    still, fast = (0.0, 0.0, 0.0, 0.0), (0.5, 0.0, 3.0, 0.0)
    assert P.identify(still, (0.5, 0.0, 0.0, 0.0)) == 0
    assert P.identify((0.0, 0.0, 3.0, 0.0), (0.5, 0.0, 3.0, 0.0)) == 5
    assert P.identify((0.0, 0.0, 3.0, 0.0), (0.5, 0.0, 0.0, 0.0)) in (1, 2)
    assert P.identify(still, fast) in (3, 4)


# -- seed 001 Table 1 ---------------------------------------------------------------------
@pytest.mark.parametrize("swing, h, speed, want_cell, want_r", [
    # w_l = 0.10 m, Δt = 0.05 s, v_sw = 1.1, v_st = 0.55 (seed 001)
    (False, 0, 0.4, "stance_observable", 0.075 + 0.05 * 0.4),             # ¾w + Δt‖v‖
    (False, 3, 0.4, "stance_unobservable", 0.075 + 0.05 * 3 * 0.55),      # ¾w + ΔtHv_st
    (True, 0, 2.0, "swing_observable", 0.10 + 0.05 * 2.0),                # w + Δt‖v‖
    (True, 2, 2.0, "swing_unobservable", 0.10 + 0.05 * 2.0 + 0.05 * 2 * 1.1),
])
def test_variable_validation_region_table1(swing, h, speed, want_cell, want_r):
    g = VariableValidationRegion(v_sw=1.1, v_st=0.55)
    ctx = GateContext(leg_width_m=0.10, dt=0.05, speed=speed, swing=swing, n_unobserved=h)
    assert g.cell(ctx) == want_cell
    assert g.radius(ctx) == pytest.approx(want_r, abs=1e-12)
    assert g.admits(1e9, want_r - 1e-6, ctx)           # Euclidean, seed001 eq. (5):
    assert not g.admits(0.0, want_r + 1e-6, ctx)       # λ² plays no part
    # the tracker loop's call (candidates_at, no GateContext) gates exactly as candidates
    from gaitval.track.kalman import FILTERS
    F = FILTERS.build({"name": "kf", "q_accel_sd_mps2": 5.0, "r_sd_m": 0.05})
    prior = F.init(1.0, 0.0)                           # a leg predicted at (1, 0)
    obs = [(1.0 + want_r - 1e-6, 0.0), (1.0, want_r + 1e-6), (1.0 - 0.5 * want_r, 0.0)]
    via_ctx = g.candidates(F, prior, obs, ctx)
    assert [j for j, _ in via_ctx] == [1, 3]
    assert g.candidates_at(F, prior, obs, 0.10, 0.05, speed, swing, h) == via_ctx


def test_variable_region_recaptures_a_leg_that_moved_while_hidden():
    """Seed 001 §3: with a small fixed region (1.0 w_l, its Method 3) a leg that starts to
    move while hidden is lost; Table 1's stance region grows by Δt·H·v_st per hidden scan
    and finds it again (here it moves 0.15 m at 0.5 m/s during 6 hidden scans)."""
    t = np.arange(60) * 0.05
    x_sw = np.where(t < 1.0, 0.0, 0.5 * (t - 1.0))
    xy, pats = [], []
    for k in range(len(t)):
        obs = [(1.0, 0.1)] + ([] if 20 <= k < 26 else [(1.0 + x_sw[k], -0.1)])
        xy.append(np.array(obs))
        pats.append(["SL"] * len(obs))
    common = dict(filter={"name": "kf", "q_accel_sd_mps2": 5.0, "r_sd_m": 0.05},
                  motion="constant_velocity",
                  phase={"name": "speed_thresholds", "v_st_th": 0.18, "v_sw_th": 0.37},
                  associator={"name": "gnn", "cost": "mahalanobis2", "d_max": 1e9},
                  dt_s=0.05, sides="as_initialised",
                  # the left leg stands throughout: no walking subject for closest_pair's
                  # motion check, which this gate test is not about
                  init={"name": "closest_pair", "require_motion": False})
    var = Tracker(gate="variable_region", **common).run(t, xy, pats, 0.1)
    small = Tracker(gate={"name": "fixed_radius", "radius_leg_widths": 1.0},
                    **common).run(t, xy, pats, 0.1)
    assert var.observed[1, 26:].all()
    assert not small.observed[1, 26:].any()


# -- seed 002 §II filter ------------------------------------------------------------------
def test_anisotropic_kf_by_hand():
    """One prediction from rest, σ_ax = 1.63, σ_ay = 5.24 m/s², r = (0.059, 0.02) m."""
    F = FILTERS.build("kf_aniso")
    dt = 0.027
    s = F.predict(F.init(0.0, 0.0), dt, 0.0, 0.0)
    p0, v0 = 0.05 ** 2, 0.5 ** 2
    for a, q in ((4, 1.63), (7, 5.24)):                 # per-axis covariance blocks
        assert s[a] == pytest.approx(p0 + dt * dt * v0 + q * q * dt ** 4 / 4, rel=1e-12)
        assert s[a + 1] == pytest.approx(dt * v0 + q * q * dt ** 3 / 2, rel=1e-12)
        assert s[a + 2] == pytest.approx(v0 + q * q * dt * dt, rel=1e-12)
    # λ² uses each axis' own innovation variance: a 2 cm error costs more along y
    lx = F.mahalanobis2(s, 0.02, 0.0)
    ly = F.mahalanobis2(s, 0.0, 0.02)
    assert lx == pytest.approx(0.02 ** 2 / (s[4] + 0.059 ** 2))
    assert ly == pytest.approx(0.02 ** 2 / (s[7] + 0.02 ** 2))
    assert ly > lx


# -- plug-ins: a windowed detector and a raw-scan tracker kind -----------------------------
class _WindowAroundPrediction(WindowedDetector):
    """Test detector: truth positions, reported only inside a 0.3 m window around each
    predicted leg (everywhere before a track exists); records the windows it was given."""

    def __init__(self, truth=None, half_width_m: float = 0.3):
        self.truth, self.half_width_m, self.seen = truth, half_width_m, []

    def observe(self, scans, k, predicted, leg_width_m):
        pts = self.truth[:, k]
        if predicted is not None:
            self.seen.append((k, predicted))
            keep = [p for p in pts if any(abs(p[0] - c[0]) < self.half_width_m and
                                          abs(p[1] - c[1]) < self.half_width_m
                                          for c, _S in predicted)]
            pts = np.array(keep).reshape(-1, 2)
        return pts, ["SL"] * len(pts)


def _scans(t):
    n = len(t)
    return ScanSeries(t=t, ranges=np.ones((n, 5)), angle_min=-1.0, angle_increment=0.5,
                      range_min=0.1, range_max=30.0)


def test_a_windowed_detector_plugs_into_the_loop(monkeypatch):
    t, _, _, truth = _walk(hide=(0, 0))
    det = _WindowAroundPrediction(truth)
    monkeypatch.setitem(DETECTORS._items, "test_window", _WindowAroundPrediction)
    method = dict(METHODS["tug_m1"], detector={"name": "test_window", "truth": truth})
    kind = build_method(method, {"tracker__dt_s": DT, "tracker__sides": "as_initialised"})
    kind.detector = det
    res = kind.track(_scans(t), 0.1)
    assert det.seen and det.seen[0][0] == 1               # called per scan with predictions
    (c_l, S_l), (c_r, S_r) = det.seen[10][1]
    assert np.asarray(S_l).shape == (2, 2)
    assert math.hypot(c_l[0] - truth[0, 10, 0], c_l[1] - truth[0, 10, 1]) < 0.15
    err = np.hypot(res.x - truth[:, :, 0], res.y - truth[:, :, 1])
    assert np.nanmax(err) < 0.05


class _StandStill(RawScanTracker):
    """Test kind: both legs at fixed points (stands in for a particle filter)."""

    def __init__(self, left=(1.0, 0.1), right=(1.0, -0.1)):
        self.left, self.right = left, right

    def track(self, scans, leg_width_m):
        res = empty_result(scans.t)
        res.k_init = 0
        res.x[:], res.y[:] = [[self.left[0]], [self.right[0]]], [[self.left[1]], [self.right[1]]]
        res.vx[:], res.vy[:] = 0.0, 0.0
        res.phase[:] = 0
        return res


def test_a_raw_scan_tracker_kind_is_chosen_by_the_method_entry(monkeypatch):
    monkeypatch.setitem(TRACKER_KINDS._items, "test_stand_still", _StandStill)
    method = {"kind": {"name": "test_stand_still", "left": (2.0, 0.2)}}
    df = track_trial(_scans(np.arange(4) * DT), method, 0.1)
    assert isinstance(df, pd.DataFrame) and len(df) == 8
    assert df.loc[df["side"] == "L", "x_m"].tolist() == [2.0] * 4
    with pytest.raises(ConfigError, match="not detect-then-track"):
        build_tracker(method)


def test_an_occlusion_handler_can_restart_both_legs(monkeypatch):
    """The run interface a re-initialising handler (seed 002 §II) uses: ``run.restart``."""
    from gaitval.track import OCCLUSION_HANDLERS
    from gaitval.track.occlusion import OcclusionHandler

    class RestartAt(OcclusionHandler):
        def after_scan(self, state, run, k):
            if k == 50:
                obs, pats = run.source.at(k, None)
                run.restart(k, obs, pats, 0, 1)

    monkeypatch.setitem(OCCLUSION_HANDLERS._items, "test_restart", RestartAt)
    t, xy, pats, truth = _walk()
    res = Tracker(occlusion="test_restart", dt_s=DT, sides="as_initialised").run(t, xy, pats, 0.1)
    assert res.restarts == [50]
    assert (res.vx[:, 50] == 0).all() and (res.x[:, 50] == truth[:, 50, 0]).all()
    err = np.hypot(res.x - truth[:, :, 0], res.y - truth[:, :, 1])
    assert np.nanmax(err) < 0.05


def test_measurement_noise_in_leg_widths_is_set_per_subject():
    """seed001 eq. (2)–(3): R = diag((w_l/2)², (w_l/2)²) for each participant's w_l."""
    F = FILTERS.build({"name": "kf", "r_sd_m": 0.04, "r_sd_leg_widths": 0.5})
    assert F.for_leg_width(0.12).r_sd_m == pytest.approx(0.06)
    assert F.r_sd_m == 0.04                                    # the method's part unchanged
    plain = FILTERS.build("kf")
    assert plain.for_leg_width(0.12) is plain
    t, xy, pats, _ = _walk()
    a = Tracker(filter={"name": "kf", "r_sd_leg_widths": 0.4}, dt_s=DT).run(t, xy, pats, 0.1)
    b = Tracker(filter={"name": "kf", "r_sd_m": 0.04}, dt_s=DT).run(t, xy, pats, 0.1)
    np.testing.assert_allclose(a.x, b.x, rtol=1e-12)          # 0.4 w_l = 0.04 m here


def _generic(part, base):
    """``part`` with its filter and gate kernels replaced by ``base``'s generic ones (each
    leg on its own, through the per-leg methods)."""
    cls = type(f"Generic{type(part).__name__}", (type(part),),
               {name: getattr(base, name) for name in ("predict_pair", "gated_pair", "kernel")
                if name in vars(base)})
    out = object.__new__(cls)
    out.__dict__.update(vars(part))
    return out


def _noisy_walk():
    """A noisy walk with clutter, occlusions and a false alarm near the legs (so the
    associators rank candidates and Method 3 re-filters)."""
    t, xy, pats, _ = _walk(n=240, hide=(80, 88))
    rng = np.random.default_rng(7)
    noisy, npats = [], []
    for k, o in enumerate(xy):
        o = o + rng.normal(0.0, 0.01, o.shape)
        extra = [[1.5, 0.9]]                                  # a static object
        if k % 7 == 0:
            extra.append(o[0] + rng.normal(0.0, 0.05, 2))     # a false alarm near a leg
        if 150 <= k < 156:
            o = o[1:]                                         # the left leg hidden too
        noisy.append(np.vstack([o, extra]))
        npats.append(["SL"] * len(noisy[-1]))
    return t, noisy, npats


@pytest.mark.parametrize("method", ["tug_m1", "tug_m2", "tug_m3", "mtst_m1", "mtst_m3",
                                    "mtst_proposed"])
def test_the_roles_fast_kernels_equal_their_generic_form(method):
    """The filter's both-legs predict and χ² gating and the gate's per-run kernel are
    written out for speed; the tracker returns exactly what it returns with the role
    bases' generic forms (each leg through ``predict``, ``gated``, ``candidates``)."""
    from gaitval.track.gate import Gate
    from gaitval.track.kalman import LegFilter

    t, noisy, npats = _noisy_walk()
    _, tracker = build_tracker(method)
    got = tracker.run(t, noisy, npats, 0.1)
    tracker.filter = _generic(tracker.filter, LegFilter)
    tracker.gate = _generic(tracker.gate, Gate)
    assert type(tracker.filter).gated_pair is LegFilter.gated_pair
    want = tracker.run(t, noisy, npats, 0.1)
    assert got.k_init == want.k_init >= 0
    for name in ("x", "y", "vx", "vy", "observed", "interpolated", "pattern", "phase",
                 "obs_index"):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name), err_msg=name)
    assert got.refiltered == want.refiltered and got.swapped_sides == want.swapped_sides
    if method == "tug_m3":
        assert got.refiltered                                 # the re-filter path ran


def test_the_parameter_table_in_the_docs_is_the_declared_one():
    """docs/tracking.md's table of the parts' parameters is the one drawn from their
    declarations (gaitval/track/params.py), so the two cannot drift apart."""
    from pathlib import Path

    from gaitval.track.params import markdown_table, parameters
    from gaitval.track.roles import ROLE_REGISTRIES

    doc = (Path(__file__).resolve().parents[1] / "docs" / "tracking.md").read_text()
    begin, end = "<!-- parameters: begin (generated) -->\n", "<!-- parameters: end -->"
    assert doc[doc.index(begin) + len(begin):doc.index(end)] == markdown_table(ROLE_REGISTRIES)
    # the declarations are the constructors' parameters, with their defaults
    gate = ROLE_REGISTRIES["gate"]["chi2"]
    (g,) = parameters(gate)
    assert (g.name, g.default, g.source) == ("g", 13.82, "seed000 Table 2")
    assert gate().g == 13.82 and gate(g=9.21).g == 9.21
    assert "seed000 Table 2" in gate.__doc__


def test_every_method_s_tracker_pickles_and_tracks_the_same_afterwards():
    """A built tracker crosses process boundaries (the workflow's job pool); its parts'
    per-instance kernels (the phase model's bound ``identify``) are rebuilt on unpickling."""
    import pickle

    t, noisy, npats = _noisy_walk()
    for method in ("tug_m2", "mtst_proposed"):
        _, tracker = build_tracker(method)
        again = pickle.loads(pickle.dumps(tracker))
        a, b = tracker.run(t, noisy, npats, 0.1), again.run(t, noisy, npats, 0.1)
        np.testing.assert_array_equal(a.x, b.x)
        np.testing.assert_array_equal(a.phase, b.phase)
