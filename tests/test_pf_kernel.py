"""Seed 002 §III: the particle filter's compiled kernels (gaitval/track/pf_kernels.py) against
numpy references — the likelihood against the §III.C formula written out in numpy, the
building blocks against the numpy calls they replaced (same numbers, bit for bit), and the
compiled step against the numpy step it replaced."""
from __future__ import annotations

import ctypes
import ctypes.util
import math
import platform

import numpy as np
import pytest
from numba import njit

from gaitval.track import pf_kernels as K
from gaitval.track.pf import ParticleFilterTracker, _Scan
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


def _sums(P, px, py, X, Y, exact):
    near = K.near_points(X, Y, px, py, P.hx, P.hy)
    s, n = np.zeros((4, px.size)), np.zeros((4, px.size), np.int64)
    f = K._region_sums_exact if exact else K._region_sums
    return f(px, py, X, Y, near, P.hx, P.hy, P.abc, s, n), s, n


def test_vectorised_region_sums_equal_the_pair_by_pair_sums(model):
    """The particle-inner, vectorised region sums (libc_exp's formula inlined) against the
    pair-by-pair loop with libc_exp: bit for bit; and an exponent beyond the formula's
    range (σ = 0.1 mm: exponents ≪ −512) makes the vectorised sums report it, and the
    likelihood, taking the pair-by-pair path, still equals the §III.C formula (to 1e-9:
    A d² + B d + C cancels terms ≈ 10⁵ at so small a σ)."""
    rng = np.random.default_rng(6)
    P = PFArrays(model)
    X, Y = 0.40 + rng.normal(0, 0.05, 80), rng.normal(0, 0.05, 80)
    px, py = 0.45 + rng.normal(0, 0.03, 300), rng.normal(0, 0.03, 300)
    ok, s, n = _sums(P, px, py, X, Y, exact=False)
    _, s_ref, n_ref = _sums(P, px, py, X, Y, exact=True)
    assert ok and np.array_equal(s, s_ref) and np.array_equal(n, n_ref) and n.sum() > 1000
    sharp = dict(model, regions=dict(model["regions"], sd_m=[1e-4] * 4))
    P = PFArrays(sharp)
    assert not _sums(P, px, py, X, Y, exact=False)[0]                 # out of range: seen
    w, cnt = likelihood(P, px, py, X, Y, 0.45, 0.2)
    w_ref, n_ref = reference_likelihood(sharp, px, py, X, Y, 0.45, 0.2)
    assert np.array_equal(cnt, n_ref) and (cnt > 0).sum() > 100 and (w > 0).sum() > 10
    np.testing.assert_allclose(w, w_ref, rtol=1e-9, atol=1e-300)      # 1e-300: subnormals


@pytest.mark.skipif(not (platform.system() == "Linux" and platform.machine() == "x86_64"
                         and platform.libc_ver()[0] == "glibc"),
                    reason="libc_exp reproduces glibc's x86-64 exp; other C libraries differ")
def test_inlined_exp_is_the_c_librarys():
    """libc_exp == the C library's exp (libm through ctypes) bit for bit on 2 million
    arguments over the likelihood's range and beyond, and on the special values (which it
    hands to the library).  Not numpy's ``np.exp``: on a CPU with AVX-512 numpy uses its own
    vectorised exp, which may differ in the last bit (seen on an Intel Xeon, 2026-11-26)."""
    rng = np.random.default_rng(2)
    x = np.concatenate([rng.uniform(-80.0, 6.0, 1_500_000), rng.uniform(-750, 750, 500_000),
                        [0.0, -0.0, 2.0 ** -54, -(2.0 ** -54), 1e-300, 511.99, -511.99, 512.0,
                         709.7, -745.2, np.inf, -np.inf, np.nan]])
    libm = ctypes.CDLL(ctypes.util.find_library("m"))
    libm.exp.restype, libm.exp.argtypes = ctypes.c_double, [ctypes.c_double]
    ref = np.fromiter(map(libm.exp, x.tolist()), float, x.size)
    assert np.array_equal(_libc_exp_all(x), ref, equal_nan=True)


@njit(cache=False)
def _libc_exp_all(a):
    out = np.empty_like(a)
    for i in range(a.size):
        out[i] = K.libc_exp(a[i])
    return out


def test_pairwise_sum_normalise_and_resampling_equal_numpy():
    rng = np.random.default_rng(3)
    for n in (1, 7, 8, 9, 127, 128, 129, 500, 1000, 4099):
        a = rng.random(n) ** 6
        assert 0.0 + K.pairwise_sum(a, 0, n) == a.sum()               # np.sum's order
        w = np.empty(n)
        neff = K.normalise(a, w)
        s = a.sum()
        assert np.array_equal(w, a / s) and neff == 1.0 / np.sum(w * w)
        for u in (0.0, 0.3, 1 - 2 ** -53):
            c = np.cumsum(w)
            c[-1] = 1.0
            ref = np.searchsorted(c, (np.arange(n) + u) / n)
            assert np.array_equal(K.systematic_resample(w, u), ref)
    w = np.empty(4)
    K.normalise(np.zeros(4), w)
    assert np.array_equal(w, np.full(4, 0.25))                        # no information


def test_estimate_equals_the_einsum_mean():
    rng = np.random.default_rng(4)
    w = rng.random((2, 500))
    w /= w.sum(axis=1, keepdims=True)
    vx, vy, px, py = (rng.normal(size=(2, 500)) for _ in range(4))
    best = w >= 0.8 * w.max(axis=1, keepdims=True)
    ws = np.where(best, w, 0.0)
    ws /= ws.sum(axis=1, keepdims=True)
    pos, v = np.stack([px, py], axis=2), np.stack([vx, vy], axis=2)
    ref = np.concatenate([np.einsum("ln,lnj->lj", ws, pos), np.einsum("ln,lnj->lj", ws, v)],
                         axis=1)
    assert np.array_equal(K.estimate(vx, vy, px, py, w, 0.8), ref)


def test_compiled_step_follows_the_numpy_step(model):
    """Twenty scans of a synthetic walk, the compiled step against the numpy step it
    replaced (same draws), estimates within 1e-12 (bit-equal on the machine of issue 12;
    the numpy step's ``exp`` and BLAS may round differently elsewhere)."""
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
        idx = np.stack([K.systematic_resample(w[f], u[r]) for r, f in enumerate(need)])
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


def test_warm_up_compiles_what_a_track_then_uses(tmp_path):
    """gaitval.track.pf.warm_up (run by the fork server before it forks its workers, and by
    run.py after installing) gives every kernel a track calls the specialisation the track
    needs: a track afterwards compiles nothing new.  In a fresh process, so that no other
    test's track has compiled them first."""
    from fresh_process import run_fresh

    code = (
        "from gaitval.track import pf_kernels as K\n"
        "from gaitval.track.pf import ParticleFilterTracker, warm_up\n"
        "from rollator_synth import walk\n"
        "names = [n for n in dir(K) if hasattr(getattr(K, n), 'signatures')]\n"
        "warm_up()\n"
        "before = {n: list(getattr(K, n).signatures) for n in names}\n"
        "assert before['propagate_weigh'] and before['resample_move'] and before['estimate']\n"
        "assert before['leg_likelihood']\n"
        "scans, _ = walk(40, seed=3)\n"
        "res = ParticleFilterTracker(seed=0, resample_fraction=1.0).track(scans, 0.10)\n"
        "assert res.k_init is not None and res.k_init >= 0\n"
        "after = {n: list(getattr(K, n).signatures) for n in names}\n"
        "print({n: (len(before[n]), len(after[n])) for n in names})\n"
        "assert after == before, (before, after)\n")
    run_fresh(code, tmp_path)
