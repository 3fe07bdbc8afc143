"""Calibration poles in the laser scans: the static background, thin static objects of the
pole diameter (candidates) and the foreground returns (motion evidence).

Steps 1-3 of the pole registration (:mod:`gaitval.registration.poles` has the whole method
and the matching to the C3D markers); all in the sensor frame, metres / radians.

1. **Static background.**  The per-beam median range over the calibration window (by
   default every scan of the trial, evenly subsampled to at most ``pole_max_scans``) and the
   per-beam *static fraction* (share of scans whose range lies within ``pole_static_tol_m``
   of that median).  A leg passing in front of a pole changes the range of a few beams in a
   minority of scans, so the median is unaffected as long as the pole is visible in more
   than half of the window; beams with a static fraction below
   ``pole_min_static_fraction`` (default 0.5) are not used.
2. **Candidates.**  The median scan is cut into segments at range jumps larger than
   ``pole_segment_jump_m`` (0.05 m) and at missing beams.  A segment is a pole candidate
   when (a) its chord width (first-to-last point plus one beam spacing) is within
   ``max(0.5 d, 1.5 r dtheta)`` of the pole diameter ``d`` (``pole_diameter_m``, default
   0.05 m); and (b) it has a depth step on both sides: the next beam outside it (skipping
   one mixed pixel) is at least ``pole_edge_step_m`` (0.10 m) farther away, or returns
   nothing.
3. **Centre.**  Fixed-radius least-squares circle fit (Gauss-Newton on
   ``|p_i - c| - d/2``), starting from the mean return pushed back by ``d/2`` along its
   bearing; one-beam candidates get ``c = p + d/2 * u``.

The foreground returns (nearer than the background) are the time-agnostic motion evidence
that tells apart pose hypotheses with the same pole residuals (step 4).
"""
from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.types import ScanSeries

#: Defaults of the ``registration:`` config keys of the pole registration (this module and
#: :mod:`gaitval.registration.poles`).
DEFAULTS = {
    "pole_labels": None,            # None: every C3D label matching POLE<n>
    "pole_diameter_m": 0.05,
    "max_pole_residual_m": 0.02,
    "pole_match_tol_m": 0.10,
    "pole_min_static_fraction": 0.5,
    "pole_static_tol_m": 0.03,
    "pole_segment_jump_m": 0.05,
    "pole_edge_step_m": 0.10,
    "pole_window_s": None,          # None: whole trial; else the first N seconds
    "pole_max_scans": 800,
    "pole_ambiguity": "motion",     # or "bearing"
}


def pole_cfg(cfg: dict | None) -> dict:
    """The pole keys of a ``registration:`` section, defaults filled in."""
    out = dict(DEFAULTS)
    out.update({k: v for k, v in (cfg or {}).items() if k in DEFAULTS})
    return out


def nanmedian0(a: np.ndarray) -> np.ndarray:
    """``np.nanmedian(a, axis=0)`` of a 2-D float array, the same values, ~3x faster: one
    sort (NaN last), then the middle value, or the mean of the two middle values as numpy
    computes it ((low + high) / 2); NaN where a column has no number."""
    s = np.sort(a, axis=0)
    n = (~np.isnan(a)).sum(axis=0)
    cols = np.arange(a.shape[1])
    hi = s[np.maximum(n // 2, 0).clip(max=len(a) - 1), cols]
    lo = s[np.maximum((n - 1) // 2, 0), cols]
    with np.errstate(invalid="ignore"):
        med = np.where(n % 2 == 1, hi, (lo + hi) / 2.0)
    med[n == 0] = np.nan
    return med


def static_background(sensor: ScanSeries, cfg: dict | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Per-beam median range and static fraction over the calibration window.

    Returns
    -------
    median_m : ndarray (n_beams,)
        NaN where a beam returns nothing in more than half of the window.
    static_fraction : ndarray (n_beams,)
        Fraction of scans within ``pole_static_tol_m`` of the median.
    """
    return _static_background(sensor, pole_cfg(cfg))


def _static_background(sensor: ScanSeries, c: dict) -> tuple[np.ndarray, np.ndarray]:
    r = sensor.ranges
    idx = np.arange(sensor.n_scans)
    if c["pole_window_s"] is not None:
        idx = idx[sensor.t - sensor.t[0] <= float(c["pole_window_s"])]
    if len(idx) > c["pole_max_scans"]:
        idx = idx[np.linspace(0, len(idx) - 1, int(c["pole_max_scans"])).astype(int)]
    sub = r[idx]
    valid_frac = np.mean(np.isfinite(sub), axis=0)
    with np.errstate(all="ignore"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            med = nanmedian0(sub)
        static = np.mean(np.abs(sub - med) <= c["pole_static_tol_m"], axis=0)
    med[valid_frac < 0.5] = np.nan
    return med, static


def _fit_fixed_radius(p: np.ndarray, R: float) -> np.ndarray:
    """Circle centre with known radius R through points p (k, 2) seen from the origin."""
    m = p.mean(axis=0)
    c = m + R * m / np.linalg.norm(m)
    if len(p) < 2:
        return c
    for _ in range(20):
        d = p - c
        n = np.linalg.norm(d, axis=1)
        res = n - R
        J = -d / n[:, None]
        step, *_ = np.linalg.lstsq(J, -res, rcond=None)
        c = c + step
        if np.linalg.norm(step) < 1e-7:
            break
    return c


def find_pole_candidates(sensor: ScanSeries, cfg: dict | None = None) -> pd.DataFrame:
    """Thin static objects of the pole diameter in the scans (sensor frame).

    Returns
    -------
    DataFrame ``xs_m, ys_m, range_m, bearing_rad, n_beams, width_m`` (centres, metres),
    one row per candidate, ordered by bearing.  See the module docstring for the method.
    """
    c = pole_cfg(cfg)
    d = float(c["pole_diameter_m"])
    R = d / 2.0
    med, static = static_background(sensor, c)
    r = med.copy()
    r[static < c["pole_min_static_fraction"]] = np.nan
    a = sensor.angles
    dth = abs(sensor.angle_increment)
    nb = len(r)
    ok = np.isfinite(r)
    # segments: split at missing beams and range jumps
    brk = np.ones(nb + 1, dtype=bool)
    with np.errstate(invalid="ignore"):
        brk[1:nb] = ~(ok[1:] & ok[:-1] & (np.abs(np.diff(r)) <= c["pole_segment_jump_m"]))
    starts = np.flatnonzero(brk[:-1] & ok)
    rows = []
    for s in starts:
        e = s
        while e + 1 < nb and not brk[e + 1]:
            e += 1
        n = e - s + 1
        rmin = np.nanmin(r[s:e + 1])
        if n * dth * rmin > 3 * d:          # far too wide to be a pole
            continue
        pts = np.column_stack([r[s:e + 1] * np.cos(a[s:e + 1]), r[s:e + 1] * np.sin(a[s:e + 1])])
        width = np.linalg.norm(pts[-1] - pts[0]) + rmin * dth
        if abs(width - d) > max(0.5 * d, 1.5 * rmin * dth):
            continue

        def step_ok(i0, direction):
            # depth step beside the segment, allowing one mixed pixel in between
            for k in (1, 2):
                j = i0 + direction * k
                if j < 0 or j >= nb:
                    return True  # edge of the field of view counts as open space
                if not np.isfinite(med[j]):
                    return True
                if med[j] >= rmin + c["pole_edge_step_m"]:
                    return True
                if med[j] < rmin + 0.5 * R:   # a nearer or equal surface: not a free pole
                    return False
            return False

        if not (step_ok(s, -1) and step_ok(e, +1)):
            continue
        keep = r[s:e + 1] <= rmin + 1.2 * R     # drop mixed pixels at the edges
        cen = _fit_fixed_radius(pts[keep], R)
        rows.append((cen[0], cen[1], float(np.hypot(*cen)), float(np.arctan2(cen[1], cen[0])),
                     int(n), float(width)))
    return pd.DataFrame(rows, columns=[C.XS, C.YS, C.RANGE, "bearing_rad", "n_beams",
                                       "width_m"])


def foreground_points(sensor: ScanSeries, background: np.ndarray, *, margin_m: float = 0.10,
                      max_scans: int = 300, max_range_m: float | None = None) -> np.ndarray:
    """Sensor-frame points of returns nearer than the static background (pooled scans).

    Returns an (m, 2) array of points (metres) from at most ``max_scans`` evenly spaced
    scans; used as time-agnostic motion evidence.
    """
    idx = np.linspace(0, sensor.n_scans - 1, min(max_scans, sensor.n_scans)).astype(int)
    r = sensor.ranges[idx]
    bg = np.where(np.isfinite(background), background, np.inf)
    with np.errstate(invalid="ignore"):
        fg = np.isfinite(r) & (r < bg - margin_m)
        if max_range_m is not None:
            fg &= r <= max_range_m
    k, i = np.nonzero(fg)
    a = sensor.angles[i]
    return np.column_stack([r[k, i] * np.cos(a), r[k, i] * np.sin(a)])


