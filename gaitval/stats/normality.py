"""Normality tests per group (seed 003 Table 7, done as a proper normality test)."""
from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats._checks import as_by, groups, numeric, require_columns

METHODS = ("lilliefors", "jarque_bera")
NORMALITY_COLUMNS = ("method", "n", "mean", "std", "ci95_low", "ci95_high", "statistic",
                     "p", "H")


def _test(x: np.ndarray, method: str) -> tuple[float, float]:
    if method == "lilliefors":
        if x.size < 4 or np.ptp(x) == 0:
            return float("nan"), float("nan")
        from statsmodels.stats.diagnostic import lilliefors
        stat, p = lilliefors(x, dist="norm", pvalmethod="table")
        return float(stat), float(p)
    if x.size < 3 or np.ptp(x) == 0:
        return float("nan"), float("nan")
    from statsmodels.stats.stattools import jarque_bera
    jb, p, _skew, _kurt = jarque_bera(x)
    return float(jb), float(p)


def normality(df: pd.DataFrame, value: str, by=None, method: str = "lilliefors",
              alpha: float = 0.05) -> pd.DataFrame:
    """Test each group of ``value`` for normality.

    Parameters
    ----------
    df : DataFrame
        One row per observation.
    value : str
        Column to test (NaN values are dropped).
    by : str or list of str, optional
        Grouping columns (e.g. ``"parameter"``).
    method : {"lilliefors", "jarque_bera"}
        ``"lilliefors"``: statsmodels ``lilliefors(x, dist="norm", pvalmethod="table")``,
        the Kolmogorov–Smirnov test with estimated mean and variance (MATLAB's
        ``lillietest`` default).  ``"jarque_bera"``: statsmodels ``jarque_bera`` with the
        asymptotic chi-square(2) p-value (MATLAB's ``jbtest`` uses a Monte-Carlo table for
        small samples instead, so p differs for small n).
    alpha : float
        Significance level for ``H`` and the confidence level ``1 - alpha`` of the mean.

    Returns
    -------
    DataFrame
        One row per group with the ``by`` columns and ``method``, ``n``, ``mean``, ``std``
        (``ddof=1``), ``ci95_low``/``ci95_high`` (t-based ``1 - alpha`` confidence
        interval of the mean, as seed 003 Table 7 reports), ``statistic`` (KS distance D or
        JB), ``p`` and ``H`` (1 = normality rejected at ``alpha``, 0 = not rejected; NaN
        when the test is undefined: fewer than 4 (Lilliefors) / 3 (JB) values or all values
        equal).

    Notes
    -----
    statsmodels' Lilliefors table p-values are clipped to [0.001, 0.99] (MATLAB's
    ``lillietest`` clips to [0.001, 0.5]); compare ``H`` rather than large p-values.
    Seed 003's Table 7 reports H = 0 and p = 1.000 for every parameter under a null of
    "mean is zero", which is not a normality test; this function is the proper test.

    References
    ----------
    Lilliefors, H.W. On the Kolmogorov–Smirnov test for normality with mean and variance
    unknown. J. Am. Stat. Assoc. 1967, 62, 399–402.
    Jarque, C.M.; Bera, A.K. A test for normality of observations and regression
    residuals. Int. Stat. Rev. 1987, 55, 163–172.
    Qi, Y. et al. Sensors 2014, 14(8), 15434–15457 (seed 003), Table 7.
    """
    if method not in METHODS:
        raise GaitvalError(f"normality: unknown method {method!r}",
                           hint=f"use one of {list(METHODS)}")
    by = as_by(by)
    require_columns(df, [value, *by], "normality")
    rows = []
    for key, sub in groups(df, by):
        x = numeric(sub, value, "normality")
        x = x[np.isfinite(x)]
        n = int(x.size)
        mean = float(np.mean(x)) if n else float("nan")
        std = float(np.std(x, ddof=1)) if n > 1 else float("nan")
        if n > 1:
            half = sps.t.ppf(1 - alpha / 2, n - 1) * std / np.sqrt(n)
            lo, hi = mean - half, mean + half
        else:
            lo = hi = float("nan")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            stat, p = _test(x, method)
        h = float(p < alpha) if np.isfinite(p) else float("nan")
        rows.append({**key, "method": method, "n": n, "mean": mean, "std": std,
                     "ci95_low": lo, "ci95_high": hi, "statistic": stat, "p": p, "H": h})
    return pd.DataFrame(rows, columns=[*by, *NORMALITY_COLUMNS])
