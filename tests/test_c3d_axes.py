"""The up-axis detection's percentile equals numpy's nan-aware one on gappy marker data."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from gaitval.io.c3d_axes import detect_vertical, nanpercentile, to_z_up


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("q", [5, 10, 37.3, 90, 95])
def test_nanpercentile_matches_numpy(seed, q):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(rng.integers(2, 80), rng.integers(1, 12), 3))
    a[rng.random(a.shape) < 0.3 + 0.1 * seed] = np.nan
    a[:, 0] = np.nan                                   # an all-NaN marker
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for axis in (0, 1):
            ref = np.nanpercentile(a, q, axis=axis)
            got = nanpercentile(a, q, axis=axis)
            assert got.shape == ref.shape
            assert np.array_equal(got, ref, equal_nan=True)


def test_y_up_walk_is_found():
    """A synthetic body (8 markers, 0-1 m tall) walking along x, stored y-up."""
    t = np.linspace(0, 4, 400)[:, None]
    heights = np.linspace(0.05, 1.0, 8)[None, :]
    xyz = np.stack([0.8 * t + 0.02 * np.sin(3 * t + heights), 0.1 * np.cos(heights * 7 + 0 * t),
                    heights + 0.01 * np.sin(6 * t)], axis=-1)
    xyz[::7, 3] = np.nan
    y_up = np.stack([xyz[..., 0], xyz[..., 2], -xyz[..., 1]], axis=-1)   # z -> y
    up, ratio = detect_vertical(y_up)
    assert up == "+y" and ratio > 1.5
    assert np.allclose(to_z_up(y_up, up), xyz, equal_nan=True)
