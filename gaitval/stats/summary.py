"""Error summary of a measurement system against a reference (seed 003 Tables 2–6).

The differences are ``d = pro - ref`` (system minus reference) for every paired row.
:func:`rmse` is gaitval's one root-mean-square error (scalar or vector errors).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.stats._checks import as_by, groups, numeric, require_columns

SUMMARY_COLUMNS = ("n", "ref_mean", "ref_std", "pro_mean", "pro_std", "diff_mean",
                   "diff_std", "rmse", "mad", "rmse_pct", "peak_abs_error")


def rmse(e, axis: int | None = None) -> float:
    """Root mean square of errors: ``sqrt(mean(e^2))``.

    Parameters
    ----------
    e : array_like
        Errors (no NaN: drop them first).
    axis : int, optional
        The axis along which each error is a vector (e.g. ``1`` for (n, 3) position
        errors): then ``sqrt(mean(|e_i|^2))``, the RMSE of the Euclidean error.

    Returns
    -------
    float
        NaN when ``e`` is empty.
    """
    e = np.asarray(e, dtype=float)
    if e.size == 0:
        return float("nan")
    if axis is None:
        return float(np.sqrt(np.mean(e ** 2)))                # RMSE = sqrt(mean(d^2))
    return float(np.sqrt(np.mean(np.sum(e ** 2, axis=axis))))


def _std(x: np.ndarray) -> float:
    return float(np.std(x, ddof=1)) if x.size > 1 else float("nan")


def summarize_errors(ref: np.ndarray, pro: np.ndarray) -> dict[str, float]:
    """Error statistics of paired arrays (rows where either value is NaN are dropped).

    See :func:`error_summary` for the definitions.
    """
    ref = np.asarray(ref, dtype=float)
    pro = np.asarray(pro, dtype=float)
    ok = np.isfinite(ref) & np.isfinite(pro)
    ref, pro = ref[ok], pro[ok]
    n = int(ref.size)
    if n == 0:
        out = {k: float("nan") for k in SUMMARY_COLUMNS}
        out["n"] = 0
        return out
    d = pro - ref
    e_rms = rmse(d)
    ref_mean = float(np.mean(ref))
    return {
        "n": n,
        "ref_mean": ref_mean, "ref_std": _std(ref),
        "pro_mean": float(np.mean(pro)), "pro_std": _std(pro),
        "diff_mean": float(np.mean(d)), "diff_std": _std(d),
        "rmse": e_rms,
        "mad": float(np.mean(np.abs(d))),              # MAD = mean(|d|), as seed 002 uses it
        "rmse_pct": 100.0 * e_rms / ref_mean if ref_mean != 0 else float("nan"),
        "peak_abs_error": float(np.max(np.abs(d))),
    }


def error_summary(df: pd.DataFrame, ref: str, pro: str, by=None) -> pd.DataFrame:
    """Per-group agreement of a system (``pro``) with a reference (``ref``).

    Parameters
    ----------
    df : DataFrame
        One row per paired observation (e.g. one stride).
    ref, pro : str
        Columns with the reference and the proposed system's values (same unit).
    by : str or list of str, optional
        Grouping columns (e.g. ``"subject"``); the whole table is one group if omitted.

    Returns
    -------
    DataFrame
        One row per group, sorted by ``by``, with the ``by`` columns and

        - ``n``: number of pairs with both values finite (rows with a NaN are dropped);
        - ``ref_mean``, ``ref_std``, ``pro_mean``, ``pro_std``: mean and sample standard
          deviation (``ddof=1``, as MATLAB's ``std``) of each system;
        - ``diff_mean``, ``diff_std``: mean and sample std of ``d = pro - ref``;
        - ``rmse``: :math:`\\sqrt{\\frac1n\\sum d_i^2}`;
        - ``mad``: mean absolute difference :math:`\\frac1n\\sum |d_i|` (seed 002's
          "MAD"; *not* the median absolute deviation);
        - ``rmse_pct``: ``100 * rmse / ref_mean`` (seed 003 quotes RMSE as % of the
          reference mean);
        - ``peak_abs_error``: :math:`\\max_i |d_i|`.

    Notes
    -----
    Seed 003 §4.2: "the mean and standard deviation (std) were calculated on the datasets
    of difference, as well as the Root Mean Square Error (RMSE)".

    References
    ----------
    Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal
    gait parameters using a low-cost ultrasonic motion analysis system. *Sensors* 2014,
    14(8), 15434–15457 (seed 003), §4.2 and Tables 2–6.
    Chalvatzaki, G.; Papageorgiou, X.S.; Tzafestas, C.S.; Maragos, P. Comparative
    experimental validation of human gait tracking algorithms for an intelligent robotic
    rollator. IEEE ICRA 2017 (seed 002), Table I (MAD).
    """
    by = as_by(by)
    require_columns(df, [ref, pro, *by], "error_summary")
    rows = []
    for key, sub in groups(df, by):
        rows.append({**key, **summarize_errors(numeric(sub, ref, "error_summary"),
                                               numeric(sub, pro, "error_summary"))})
    out = pd.DataFrame(rows, columns=[*by, *SUMMARY_COLUMNS])
    out["n"] = out["n"].astype(int)
    return out
