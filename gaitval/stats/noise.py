"""Noise identification of seed 003's UKF from the pendulum trials (§4.3, eq. 23).

* :func:`measurement_noise` — V: mean and variance of the range errors per anchor
  (eq. 23), from :func:`gaitval.evaluate.pendulum.pendulum_alignment`.
* :func:`identify_noise` — V, then W by the minimum-RMSE search of §4.3.1 over the
  tracker's errors against the camera (:func:`gaitval.evaluate.pendulum.pendulum_track_errors`,
  RMSE by :func:`gaitval.stats.summary.rmse`).
* :func:`noise_to_config` — the plain numbers, for ``noise.json`` and the track step.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.config import deep_merge
from gaitval.evaluate.pendulum import pendulum_alignment, pendulum_track_errors
from gaitval.evaluate.ultrasonic_config import build_tracker, resolve_cfg
from gaitval.stats.summary import rmse
from gaitval.types import MocapTrial, UltrasonicLog


def measurement_noise(aligned: list[dict], outlier_mad: float = 5.0) -> pd.DataFrame:
    """Mean and variance of the range errors per anchor (seed 003 eq. 23).

    ``u = 1/(MN) sum_i sum_j (m_i^j - r_i^j)``,
    ``e^2 = 1/(M(N-1)) sum_i sum_j (m_i^j - r_i^j - u)^2``, pooled over the M trials.
    The paper writes ``(m_i^j - u)^2`` and one actual distance ``r_i`` per test; a swinging
    pendulum has a camera distance per sample, so the error is taken per sample and the
    variance is of the error about its mean.  Multipath outliers (``|err - median| >
    outlier_mad * 1.4826 MAD``) are excluded and counted: the paper's line-of-sight
    experiment had none, and one late echo would dominate the variance.

    Returns
    -------
    DataFrame
        ``anchor`` (index 0..m-1), ``mean_m``, ``var_m2``, ``std_m``, ``n``, ``n_outliers``.
    """
    m = aligned[0]["d"].shape[1]
    rows = []
    for k in range(m):
        errs = [a["d"][:, k] - a["r"][:, k] for a in aligned]
        allv = np.concatenate(errs)
        allv = allv[np.isfinite(allv)]
        med = np.median(allv)
        mad = 1.4826 * np.median(np.abs(allv - med))
        keep_sets = [e[np.isfinite(e) & (np.abs(e - med) <= outlier_mad * mad)] for e in errs]
        M = sum(1 for e in keep_sets if e.size > 1)
        N_tot = sum(e.size for e in keep_sets)
        u = sum(e.sum() for e in keep_sets) / N_tot                  # seed003 eq. (23)
        e2 = sum(((e - u) ** 2).sum() for e in keep_sets) / (N_tot - M)  # seed003 eq. (23)
        rows.append({"anchor": k, "mean_m": u, "var_m2": e2, "std_m": np.sqrt(e2),
                     "n": int(N_tot), "n_outliers": int(allv.size - N_tot)})
    return pd.DataFrame(rows)


def identify_noise(trials: list[tuple[UltrasonicLog, MocapTrial]], cfg: dict | None = None,
                   *, names: list[str] | None = None) -> dict:
    """Measurement noise V per anchor and process noise W from pendulum trials (§4.3).

    Parameters
    ----------
    trials : list of (UltrasonicLog, MocapTrial)
        The pendulum trials: transmitter with a marker ``TX`` on the pendulum, receivers
        with markers ``ANC1..``.
    cfg : dict
        ``noise_id.W_grid_mps2`` (candidate sigmas, m/s^2), ``noise_id.outlier_mad``,
        ``noise_id.skip_start_s`` and the ``ukf`` keys used while searching.
    names : list of str, optional
        Trial ids for error messages.

    Returns
    -------
    dict
        ``V_m2`` (list, variance per anchor, eq. 23), ``bias_m`` (mean range error per
        anchor), ``W_sigma_mps2`` ([sx, sy, sz], minimum-RMSE search), ``rmse_m`` (3-D RMSE
        of the UKF track at that W), ``noise`` (DataFrame of :func:`measurement_noise`),
        ``search`` (DataFrame ``sx, sy, sz, rmse_m`` of every candidate tried),
        ``clock`` (DataFrame ``trial, clock_offset_s``), ``_aligned`` (the per-trial
        :func:`~gaitval.evaluate.pendulum.pendulum_alignment` dicts, to pass on to
        :func:`~gaitval.evaluate.pendulum.pendulum_errors`).

    Notes
    -----
    §4.3.1: "By varying the values of sigma_wx, sigma_wy and sigma_wz, we will get the
    corresponding trajectory ... to compute the RMSE value.  Typical values ... will be
    selected when their corresponding RMSE is minimal."  The search here first varies one
    common sigma over the grid, then each axis in turn (coordinate descent, one sweep per
    axis, twice), with the identified V in the filter.
    """
    c = resolve_cfg(cfg)
    names = names or [f"pendulum {i + 1}" for i in range(len(trials))]
    aligned = [pendulum_alignment(log, mo, c, trial=nm) for (log, mo), nm in zip(trials, names)]
    noise = measurement_noise(aligned, float(c["noise_id"]["outlier_mad"]))
    V = noise["var_m2"].to_list()
    best, cache = _search_W(c, [log for log, _ in trials], aligned, V)
    search = pd.DataFrame([{"sx": k[0], "sy": k[1], "sz": k[2], "rmse_m": v}
                           for k, v in cache.items()])
    clock = pd.DataFrame({"trial": names,
                          "clock_offset_s": [a["clock_offset_s"] for a in aligned]})
    return {"V_m2": V, "bias_m": noise["mean_m"].to_list(), "W_sigma_mps2": list(best),
            "rmse_m": cache[tuple(round(x, 9) for x in best)], "noise": noise,
            "search": search, "clock": clock, "_aligned": aligned}


def _search_W(c: dict, logs: list[UltrasonicLog], aligned: list[dict], V: list[float]):
    """The minimum-RMSE W (§4.3.1): one common sigma over ``noise_id.W_grid_mps2``, then
    each axis in turn, twice.  Returns the best ``[sx, sy, sz]`` and every candidate's
    3-D RMSE (m) keyed by its rounded sigmas."""
    grid = [float(g) for g in c["noise_id"]["W_grid_mps2"]]
    skip = float(c["noise_id"]["skip_start_s"])
    cache: dict[tuple, float] = {}

    def track_rmse(w):
        key = tuple(round(x, 9) for x in w)
        if key not in cache:
            tracker = build_tracker(deep_merge(c, {"ukf": {"W_sigma_mps2": list(key),
                                                           "V_m2": V}}))
            errs = []
            for a, log in zip(aligned, logs):
                e, keep = pendulum_track_errors(tracker, log, a, skip,
                                                lowpass_cfg=c["lowpass"])
                errs.append(e[keep])
            e = np.concatenate(errs)
            cache[key] = rmse(e[np.all(np.isfinite(e), axis=1)], axis=1)   # 3-D RMSE
        return cache[key]

    best = min(([g, g, g] for g in grid), key=track_rmse)
    for _ in range(2):
        for ax in range(3):
            cands = [best[:ax] + [g] + best[ax + 1:] for g in grid]
            best = min(cands, key=track_rmse)
    return best, cache


def noise_to_config(noise: dict) -> dict:
    """The plain-number part of :func:`identify_noise`'s result, ready for YAML/JSON.

    Returns ``{"ukf": {"W_sigma_mps2": [...], "V_m2": [...]}, "bias_m": [...],
    "rmse_m": float}``; merge the ``ukf`` part into the ``ultrasonic`` config to track
    with the identified noise.
    """
    return {"ukf": {"W_sigma_mps2": [float(w) for w in noise["W_sigma_mps2"]],
                    "V_m2": [float(v) for v in noise["V_m2"]]},
            "bias_m": [float(b) for b in noise["bias_m"]], "rmse_m": float(noise["rmse_m"])}
