"""The faster forms of two registration steps give the values of the plain ones."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from gaitval.registration import occupancy as occ
from gaitval.registration.poledetect import nanmedian0, static_background
from gaitval.types import ScanSeries

ANGLES = np.deg2rad(-135 + 0.25 * np.arange(1081))        # a 270 deg, 0.25 deg LRS


def _legs(rng, n, d_lo=0.1):
    bearing = rng.uniform(-2.9, 2.9, (n, 2))
    d = rng.uniform(d_lo, 4.0, (n, 2))
    legs = np.stack([d * np.cos(bearing), d * np.sin(bearing)], axis=-1)
    legs[rng.random((n, 2)) < 0.05] = np.nan                 # unknown leg centres
    return legs


@pytest.mark.slow
def test_windowed_occupancy_equals_every_beam_evaluated():
    rng = np.random.default_rng(7)
    windowed = 0
    for _ in range(150):
        legs, r = _legs(rng, 300), rng.uniform(0.03, 0.07)
        windowed += occ._windows(legs, ANGLES, r) is not None
        assert np.array_equal(occ.predicted_occupancy(legs, ANGLES, r),
                              occ.predicted_occupancy_full(legs, ANGLES, r), equal_nan=True)
    assert 20 < windowed < 150          # both paths ran: windows, and the fall-backs


def test_occupancy_of_a_leg_straight_ahead():
    legs = np.array([[[1.0, 0.0], [np.nan, np.nan]], [[1.0, 0.0], [0.0, 1.0]]])
    hit = occ.predicted_occupancy(legs, ANGLES, 0.05)
    assert np.isnan(hit[0]).all()                          # a leg unknown: frame unknown
    on = np.flatnonzero(hit[1] == 1)
    half = np.rad2deg(np.arcsin(0.05))                      # 2.87 deg either side
    ahead = np.rad2deg(ANGLES[on])
    assert ahead[(ahead > -10) & (ahead < 10)].max() < half + 1e-9
    assert (np.abs(np.rad2deg(ANGLES[on]) - 90) < half + 1e-9).sum() > 0   # the left leg


def test_nanmedian0_is_numpys_nanmedian_bit_for_bit():
    rng = np.random.default_rng(3)
    for _ in range(100):
        x = rng.normal(size=(int(rng.integers(1, 900)), 40))
        x[rng.random(x.shape) < 0.4] = np.nan
        x[rng.random(x.shape) < 0.01] = np.inf
        x[:, 0] = np.nan                                    # a beam that never returns
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ref = np.nanmedian(x, axis=0)
        assert np.array_equal(nanmedian0(x), ref, equal_nan=True)


def test_static_background_is_kept_per_scan_series_and_returned_as_copies():
    rng = np.random.default_rng(5)
    ranges = 2.0 + 0.001 * rng.standard_normal((50, 1081))
    scans = ScanSeries(t=np.arange(50) * 0.025, ranges=ranges, angle_min=ANGLES[0],
                       angle_increment=ANGLES[1] - ANGLES[0], range_min=0.1, range_max=30.0)
    med, static = static_background(scans)
    med[:] = -1.0                                           # the caller's copy only
    again, _ = static_background(scans)
    assert np.allclose(again, 2.0, atol=0.01) and np.all(static == 1.0)
    other = ScanSeries(t=np.arange(50) * 0.025, ranges=ranges + 1.0, angle_min=ANGLES[0],
                       angle_increment=ANGLES[1] - ANGLES[0], range_min=0.1, range_max=30.0)
    assert np.allclose(static_background(other)[0], 3.0, atol=0.01)
