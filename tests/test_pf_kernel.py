"""Seed 002 §III: the particle filter's likelihood (compiled loops in
gaitval/track/pf_kernels.py) against the §III.C formula written out in numpy, systematic
resampling against its defining property, and the step against the numpy step of
gaitval ≤ ddd5125 (within round-off, docs/numerics.md)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gaitval.track.pf import ParticleFilterTracker, _Scan, systematic_resample
from gaitval.track.pf_likelihood import PFArrays, likelihood, sample_velocities
from gaitval.track.pf_model import default_pf_model, regions
from rollator_synth import walk

HX, HY = 0.0625, 0.046875                     # dyadic: the border tests subtract exactly


@pytest.fixture(scope="module")
def model():
    """A model whose four regions differ (μ, σ, π) and whose λ varies with the count, so
    that a region or count mix-up changes the weights."""
    m = default_pf_model(0.10)
    m["window_half_m"] = [HX, HY]
    m["regions"] = {"mu_m": [0.045, 0.05, 0.055, 0.06], "sd_m": [0.004, 0.006, 0.008, 0.01],
                    "pi": [0.1, 0.4, 0.35, 0.15]}
    m["count_pdf"] = list(np.exp(-0.5 * ((np.arange(60) - 20) / 8.0) ** 2) + 0.01)
    return m


def reference_likelihood(model, px, py, X, Y, ox, oy):
    """seed002 §III.C written out: p(y|x_i) = β_i · λ_i · Σ_m π_Rm · mean_j N(d_j | μ_m, σ_m)
    over the points j of region R_m (R1..R4) of the rectangle ±(h_x, h_y) around particle i,
    the far half R0 ignored; λ at the number of points in R1..R4; β the Gamma density of the
    distance to the other leg."""
    hx, hy = model["window_half_m"]
    reg, lam, ga = model["regions"], np.asarray(model["count_pdf"]), model["gamma"]
    ok = np.isfinite(X) & np.isfinite(Y)
    X, Y = X[ok], Y[ok]
    w, n = np.zeros(len(px)), np.zeros(len(px), int)
    for i in range(len(px)):
        dx, dy = X - px[i], Y - py[i]                                 # point − particle
        r = np.where((dx >= -hx) & (np.abs(dy) <= hy), regions(dx, dy), -1)
        total = 0.0
        for m in range(4):
            d = np.hypot(dx[r == m], dy[r == m])
            if d.size:
                mu, sd = reg["mu_m"][m], reg["sd_m"][m]
                dens = np.exp(-0.5 * ((d - mu) / sd) ** 2) / (sd * math.sqrt(2 * math.pi))
                total += reg["pi"][m] * dens.mean()
        n[i] = int((r >= 0).sum())
        dist = math.hypot(px[i] - ox, py[i] - oy)
        beta = math.exp((ga["a"] - 1) * math.log(dist) - dist / ga["scale"]
                        - math.lgamma(ga["a"]) - ga["a"] * math.log(ga["scale"]))
        w[i] = beta * lam[min(n[i], len(lam) - 1)] * total
    return w, n


def test_likelihood_equals_the_formula_on_random_particles(model):
    rng = np.random.default_rng(1)
    P = PFArrays(model)
    for trial in range(5):
        X = 0.40 + rng.normal(0, 0.05, 60)
        Y = rng.normal(0, 0.05, 60)
        X[rng.random(60) < 0.1] = np.nan                              # beams without return
        px, py = 0.45 + rng.normal(0, 0.03, 300), rng.normal(0, 0.03, 300)
        w, n = likelihood(P, px, py, X, Y, 0.45, 0.2)
        w_ref, n_ref = reference_likelihood(model, px, py, X, Y, 0.45, 0.2)
        assert np.array_equal(n, n_ref)
        assert (n > 0).sum() > 100                                    # the windows are hit
        np.testing.assert_allclose(w, w_ref, rtol=1e-12, atol=0.0)


def test_likelihood_borders_regions_and_no_points(model):
    """Points exactly on the window's borders (u = h_x in, u = 0 out, |v| = h_y in), on the
    45° lines (|v| = u: outer region) and on v = 0; one point in each region; no points."""
    P = PFArrays(model)
    px, py = np.array([0.5]), np.array([0.0])
    cases = {                                    # (X, Y) -> expected region (None: outside)
        (0.5 - HX, 0.0): 2, (0.5, 0.01): None, (0.5 - HX, HY): 1, (0.5 - HX, -HY): 2,
        (0.5 - 0.03125, 0.03125): 0, (0.5 - 0.03125, -0.03125): 3,   # |v| = u: outer
        (0.5 - HX - 2 ** -20, 0.0): None, (0.5 - 0.03, HY + 2 ** -20): None,
        (0.5 - 0.05, 0.01): 1, (0.5 - 0.05, -0.01): 2, (0.5 + 0.01, 0.0): None}
    for (x, y), region in cases.items():
        w, n = likelihood(P, px, py, np.array([x]), np.array([y]), 0.5, 0.2)
        w_ref, n_ref = reference_likelihood(model, px, py, np.array([x]), np.array([y]),
                                            0.5, 0.2)
        assert n[0] == n_ref[0] == (region is not None), (x, y)
        assert region is None or regions(np.array([x - 0.5]), np.array([y]))[0] == region
        np.testing.assert_allclose(w, w_ref, rtol=1e-12, atol=0.0)
        assert (w[0] > 0) == (region is not None)
    w, n = likelihood(P, px, py, np.array([]), np.array([]), 0.5, 0.2)
    assert w[0] == 0.0 and n[0] == 0                                  # no points: weight 0
    w, n = likelihood(P, px, py, np.array([np.nan]), np.array([np.nan]), 0.5, 0.2)
    assert w[0] == 0.0 and n[0] == 0
    w, _ = likelihood(P, px, py, np.array([0.48]), np.array([0.0]), 0.5, 0.0)
    assert w[0] == 0.0                                                # on the other leg: β 0


def test_exponents_far_below_exps_range_give_zero_densities(model):
    """σ = 0.1 mm: most exponents are ≪ −745 (exp underflows to 0); the likelihood still
    equals the §III.C formula (to 1e-9: at so small a σ the formula's own exp rounds)."""
    rng = np.random.default_rng(6)
    sharp = dict(model, regions=dict(model["regions"], sd_m=[1e-4] * 4))
    P = PFArrays(sharp)
    X, Y = 0.40 + rng.normal(0, 0.05, 80), rng.normal(0, 0.05, 80)
    px, py = 0.45 + rng.normal(0, 0.03, 300), rng.normal(0, 0.03, 300)
    w, cnt = likelihood(P, px, py, X, Y, 0.45, 0.2)
    w_ref, n_ref = reference_likelihood(sharp, px, py, X, Y, 0.45, 0.2)
    assert np.array_equal(cnt, n_ref) and (cnt > 0).sum() > 100 and (w > 0).sum() > 10
    np.testing.assert_allclose(w, w_ref, rtol=1e-9, atol=1e-300)      # 1e-300: subnormals


def test_systematic_resampling_keeps_each_particle_floor_or_ceil_of_n_w():
    """Systematic resampling (Arulampalam et al. 2002, Algorithm 2) gives particle i
    ⌊N w_i⌋ or ⌈N w_i⌉ copies, indices ascending; uniform weights: every particle once."""
    rng = np.random.default_rng(3)
    for n in (1, 7, 128, 500, 4099):
        w = rng.random(n) ** 6
        w /= w.sum()
        for u in (0.0, 0.3, 1 - 2 ** -53):
            idx = systematic_resample(w, u)
            copies = np.bincount(idx, minlength=n)
            assert idx.size == n and np.all(np.diff(idx) >= 0)
            assert np.all(copies >= np.floor(n * w - 1e-9))
            assert np.all(copies <= np.ceil(n * w + 1e-9))
        assert np.array_equal(systematic_resample(np.full(n, 1.0 / n), 0.5), np.arange(n))


def test_step_follows_the_numpy_step(model):
    """Twenty scans of a synthetic walk, the step against the numpy step of gaitval ≤
    ddd5125 (same draws), estimates within 1e-12: the same draws in the same order and the
    same decisions (resampling, MH acceptance)."""
    scans, _ = walk(25, seed=5)
    tracker = ParticleFilterTracker(model=model, seed=0)
    k0, p0 = tracker.start(scans, 0.10)
    P, pts, dt = PFArrays(model), _Scan(scans), 0.028
    rng_a, rng_b = np.random.default_rng(9), np.random.default_rng(9)
    prev = np.concatenate([p0, np.zeros((2, 2))], axis=1)
    ref, moved = prev.copy(), 0
    for k in range(k0 + 1, k0 + 21):
        prev, seen = tracker.step(P, rng_a, pts, k, prev, dt)
        ref, seen_ref, n_moved = _numpy_step(P, rng_b, pts.X[k], pts.Y[k], ref, dt)
        np.testing.assert_allclose(prev, ref, rtol=0, atol=1e-12)
        assert np.array_equal(seen, seen_ref)
        moved += n_moved
    assert rng_a.random() == rng_b.random()                           # same draws consumed
    assert moved > 0                                                  # §III.D was exercised


def _numpy_step(P, rng, X, Y, prev, dt, N=500):
    """The numpy step of gaitval ≤ ddd5125 (B–E), weighing with :func:`likelihood` (tested
    above against the formula)."""
    def weigh(pos, legs):
        out = [likelihood(P, pos[i, :, 0], pos[i, :, 1], X, Y, prev[1 - f, 0],
                          prev[1 - f, 1]) for i, f in enumerate(legs)]
        return np.array([o[0] for o in out]), np.array([o[1] for o in out])

    def norm(lik):
        s = lik.sum(axis=1, keepdims=True)
        return np.where(s > 0, lik / np.where(s > 0, s, 1.0), 1.0 / lik.shape[1])

    v = sample_velocities(P, rng, N)
    pos = prev[:, None, :2] + v * dt
    lik, cnt = weigh(pos, (0, 1))
    w = norm(lik)
    need = np.flatnonzero(1.0 / np.sum(w * w, axis=-1) < 0.5 * N)
    if need.size:
        u = rng.random(need.size)
        idx = np.stack([systematic_resample(w[f], u[r]) for r, f in enumerate(need)])
        v[need] = np.take_along_axis(v[need], idx[..., None], axis=1)
        lik[need] = np.take_along_axis(lik[need], idx, axis=1)
        v_new = v[need] + rng.standard_normal((need.size, N, 2)) * P.walk_sd
        lik_new, _ = weigh(prev[need, None, :2] + v_new * dt, need)
        um = rng.random((need.size, N))
        acc = (lik[need] <= 0.0) | (um * lik[need] < lik_new)
        v[need] = np.where(acc[..., None], v_new, v[need])
        lik[need] = np.where(acc, lik_new, lik[need])
        w[need] = norm(lik[need])
        pos = prev[:, None, :2] + v * dt
    best = w >= 0.8 * w.max(axis=1, keepdims=True)
    ws = np.where(best, w, 0.0)
    ws /= ws.sum(axis=1, keepdims=True)
    est = np.concatenate([np.einsum("ln,lnj->lj", ws, pos), np.einsum("ln,lnj->lj", ws, v)],
                         axis=1)
    return est, cnt.max(axis=1) > 0, need.size


@pytest.mark.slow
def test_warm_up_compiles_what_a_track_then_uses(tmp_path):
    """gaitval.track.pf.warm_up (run by the fork server before it forks its workers, and by
    run.py after installing) gives the compiled loops a track calls the specialisation the
    track needs: a track afterwards compiles nothing new.  In a fresh process, so that no
    other test's track has compiled them first."""
    from fresh_process import run_fresh

    code = (
        "from gaitval.track import pf_kernels as K\n"
        "from gaitval.track.pf import ParticleFilterTracker, warm_up\n"
        "from rollator_synth import walk\n"
        "names = ['pair_exponents', 'region_likelihood']\n"
        "warm_up()\n"
        "before = {n: list(getattr(K, n).signatures) for n in names}\n"
        "assert all(before.values()), before\n"
        "scans, _ = walk(40, seed=3)\n"
        "res = ParticleFilterTracker(seed=0, resample_fraction=1.0).track(scans, 0.10)\n"
        "assert res.k_init is not None and res.k_init >= 0\n"
        "after = {n: list(getattr(K, n).signatures) for n in names}\n"
        "print({n: (len(before[n]), len(after[n])) for n in names})\n"
        "assert after == before, (before, after)\n")
    run_fresh(code, tmp_path)
