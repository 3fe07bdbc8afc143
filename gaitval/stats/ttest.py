"""Paired t-test between two conditions (seed 003 Table 8: speeds vs normal speed)."""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats._checks import as_by, groups, numeric, require_columns

TTEST_COLUMNS = ("a", "b", "n", "mean_a", "mean_b", "mean_diff", "std_diff", "t", "df",
                 "p", "ci_low", "ci_high", "significant")


def paired_t(x: np.ndarray, y: np.ndarray, alpha: float = 0.05) -> dict[str, float]:
    """Two-sided paired t-test of ``d = x - y`` (pairs with a NaN are dropped).

    Returns a dict with ``n, mean_a, mean_b, mean_diff, std_diff, t, df, p, ci_low,
    ci_high, significant``; ``t`` and ``p`` are NaN when all differences are equal
    (zero variance), which is how seed 003 Table 8 reports cadence errors ("NaN").
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    n = int(x.size)
    nan = float("nan")
    out = {"n": n, "mean_a": float(np.mean(x)) if n else nan,
           "mean_b": float(np.mean(y)) if n else nan}
    d = x - y
    md = float(np.mean(d)) if n else nan
    sd = float(np.std(d, ddof=1)) if n > 1 else nan
    t = p = lo = hi = nan
    # differences at round-off level of the data (e.g. identical RMSEs recomputed from
    # rounded sums) count as equal: relative tolerance 1e-12 of the data's magnitude
    scale = float(max(np.max(np.abs(x)), np.max(np.abs(y)))) if n else 0.0
    if n > 1 and sd > 1e-12 * scale:
        se = sd / np.sqrt(n)
        t = md / se                                              # t = mean(d) / (s_d/sqrt(n))
        p = float(2 * sps.t.sf(abs(t), n - 1))
        half = sps.t.ppf(1 - alpha / 2, n - 1) * se
        lo, hi = md - half, md + half
    out.update({"mean_diff": md, "std_diff": sd, "t": t, "df": n - 1 if n else 0, "p": p,
                "ci_low": lo, "ci_high": hi,
                "significant": bool(np.isfinite(p) and p < alpha)})
    return out


def paired_ttest(df: pd.DataFrame, value: str, pair_by, condition: str, a, b, by=None,
                 alpha: float = 0.05) -> pd.DataFrame:
    """Paired t-test of ``value`` between conditions ``a`` and ``b``.

    Parameters
    ----------
    df : DataFrame
        Long table with one row per (pair, condition), e.g. one row per subject and
        speed holding that subject's mean stride length.
    value : str
        The measured column.
    pair_by : str or list of str
        Columns identifying a pair (e.g. ``"subject"``).  Each pair must have at most
        one row per condition (aggregate first otherwise); pairs missing either
        condition are left out (``n`` says how many remain).
    condition : str
        Column holding the condition (e.g. ``"speed"``).
    a, b
        The two conditions compared; the difference is ``a - b``.
    by : str or list of str, optional
        Run one test per group of these columns (e.g. ``"parameter"``).
    alpha : float
        Two-sided significance level (0.05: seed 003 marks p < 0.05 with ``*``).

    Returns
    -------
    DataFrame
        One row per group: ``by`` columns, ``a``, ``b``, ``n`` (pairs), ``mean_a``,
        ``mean_b``, ``mean_diff`` (mean of ``a - b``), ``std_diff``, ``t``, ``df = n - 1``,
        ``p`` (two-sided), ``ci_low``/``ci_high`` (``1 - alpha`` CI of the mean
        difference) and ``significant`` (``p < alpha``).

    Notes
    -----
    :math:`t = \\bar d / (s_d / \\sqrt n)` with :math:`n - 1` degrees of freedom (the
    same statistic as ``scipy.stats.ttest_rel``).

    References
    ----------
    Qi, Y. et al. Sensors 2014, 14(8), 15434–15457 (seed 003), §4.4.3 and Table 8.
    """
    by = as_by(by)
    pair_by = as_by(pair_by)
    require_columns(df, [value, condition, *pair_by, *by], "paired_ttest")
    rows = []
    for key, sub in groups(df, by):
        sub = sub[sub[condition].isin([a, b])]
        dup = sub.duplicated([*pair_by, condition])
        if dup.any():
            first = sub.loc[dup, [*pair_by, condition]].iloc[0].to_dict()
            raise GaitvalError(
                f"paired_ttest: more than one row for {first} (group {key or 'all'})",
                hint=f"aggregate {value!r} to one value per {pair_by + [condition]} first")
        vals = sub.assign(_v=numeric(sub, value, "paired_ttest"))
        wide = vals.pivot_table(index=pair_by, columns=condition, values="_v",
                                aggfunc="first", dropna=False, observed=True)
        x = wide[a].to_numpy(dtype=float) if a in wide.columns else np.array([])
        y = wide[b].to_numpy(dtype=float) if b in wide.columns else np.array([])
        if x.size != y.size:
            x = y = np.array([])
        rows.append({**key, "a": a, "b": b, **paired_t(x, y, alpha)})
    out = pd.DataFrame(rows, columns=[*by, *TTEST_COLUMNS])
    out["n"] = out["n"].astype(int)
    out["df"] = out["df"].astype(int)
    out["significant"] = out["significant"].astype(bool)
    return out
