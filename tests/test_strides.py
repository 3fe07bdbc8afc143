"""Stride segmentation and parameters (seed 003 eq. 16-22) on constructed heel signals."""
from __future__ import annotations

import numpy as np
import pytest

from gaitval.gait.strides import (autocorr_symmetry, autocorr_unbiased, dominant_period,
                                  match_strides, stride_table)


def test_unbiased_autocorrelation_by_hand():
    # a = [1, 2, 3]: A(0) = (1+4+9)/3, A(1) = (1*2 + 2*3)/2 = 4, A(2) = (1*3)/1 = 3  (eq. 16)
    A = autocorr_unbiased(np.array([1.0, 2.0, 3.0]))
    assert A == pytest.approx([14 / 3, 4.0, 3.0])
    # the biased estimator (eq. 15) would give 8/3 and 1 at lags 1 and 2
    assert autocorr_unbiased(np.array([1.0, 2.0, 3.0]), normalise=True)[1] == \
        pytest.approx(4.0 / (14 / 3))
    assert autocorr_unbiased(np.array([1.0, -1.0, 2.0, 0.5]), max_lag=2) == pytest.approx(
        [(1 + 1 + 4 + 0.25) / 4, (-1 - 2 + 1) / 3, (2 - 0.5) / 2])


def _heel(durations, amp, fs, back_frac=0.6):
    """Treadmill-like heel signal: maximum amp at each strike, linear back for
    back_frac of the stride to -amp, then linear forward to the next maximum."""
    t_hs = np.concatenate([[0.0], np.cumsum(durations)])
    t = np.arange(int(np.floor(t_hs[-1] * fs)) + 1) / fs
    x = np.empty_like(t)
    for a, b in zip(t_hs[:-1], t_hs[1:]):
        m = (t >= a) & (t <= b)
        u = (t[m] - a) / (b - a)
        x[m] = np.where(u < back_frac, amp - 2 * amp * u / back_frac,
                        -amp + 2 * amp * (u - back_frac) / (1 - back_frac))
    return t, x, t_hs


def test_stride_table_on_constructed_heel_signal():
    fs = 50.0
    durations = np.array([1.2, 1.1, 1.3, 1.2, 1.0, 1.4, 1.2])   # max and min on samples
    t, x, t_hs = _heel(durations, 0.3, fs)
    st = stride_table(x, fs)
    # cycles run between maxima = the heel strikes; a maximum on the first or last sample
    # is not a peak, so the strides are the interior ones
    inner = durations[1:-1]
    assert st["t_start_s"].to_numpy() == pytest.approx(t_hs[1:-2])
    got_T = st["stride_duration"].to_numpy()
    assert got_T == pytest.approx(inner, abs=1e-9)                 # eq. (19)
    assert st["stride_length"].to_numpy() == pytest.approx(1.2)    # eq. (17): 2 (0.3+0.3)
    assert st["stride_velocity"].to_numpy() == pytest.approx(1.2 / inner)       # eq. (20)
    assert st["cadence"].to_numpy() == pytest.approx(1 / inner)                 # eq. (22)
    n = len(st)
    assert st["stride_length_norm"].to_numpy() == pytest.approx(1.2 / n)         # eq. (18)
    assert st["stride_velocity_norm"].to_numpy() == pytest.approx(1.2 / inner / n)  # (21)


def test_stride_table_ignores_noise_wiggles():
    fs = 50.0
    rng = np.random.default_rng(1)
    durations = np.full(12, 1.2)
    t, x, _ = _heel(durations, 0.3, fs)
    x = x + 0.002 * rng.standard_normal(x.size)
    st = stride_table(x, fs)
    assert len(st) >= 10
    assert st["stride_duration"].median() == pytest.approx(1.2, abs=0.021)


def test_dominant_period_of_a_sine():
    fs = 50.0
    t = np.arange(1500) / fs
    assert dominant_period(np.sin(2 * np.pi * t / 1.18), fs) == pytest.approx(1.18, abs=0.02)


def test_symmetry_of_periodic_and_asymmetric_signals():
    fs = 50.0
    t = np.arange(int(6 * 1.2 * fs)) / fs
    sym = autocorr_symmetry(np.sin(2 * np.pi * t / 1.2), fs, 1.2)
    # unbiased estimator of a pure periodic signal: R1 and R2 at the period, ratio ~1
    assert sym["lag1_s"] == pytest.approx(1.2, abs=0.02)
    assert sym["lag2_s"] == pytest.approx(2.4, abs=0.02)
    assert sym["symmetry"] == pytest.approx(1.0, abs=0.01)
    # alternate strides of different amplitude: the first-stride regularity drops, the
    # two-stride one does not, so R2/R1 moves away from 1
    amp = np.where((t // 1.2) % 2 == 0, 1.0, 0.6)
    asym = autocorr_symmetry(amp * np.sin(2 * np.pi * t / 1.2), fs, 1.2)
    assert asym["R1"] < sym["R1"] and asym["symmetry"] > 1.05


def test_match_strides_by_start_time_each_system_stride_once():
    import pandas as pd

    ref = pd.DataFrame({"t_start_s": [0.0, 1.0, 2.0, 3.0], "stride_duration": 1.0})
    sys = pd.DataFrame({"t_start_s": [0.05, 1.4, 2.1, 2.15]})
    # 1.0 -> nearest 1.4 is 0.4 s away (> 0.25 T); 2.0 -> 2.1; 3.0 -> 2.15 (0.85 s away)
    assert match_strides(ref, sys, 0.25) == [(0, 0), (2, 2)]
    assert match_strides(ref, sys, 0.5) == [(0, 0), (1, 1), (2, 2)]
    assert match_strides(ref, sys.iloc[:0], 0.25) == []
