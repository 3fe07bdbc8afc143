"""One-way analysis of variance (seed 003 Table C1) via statsmodels."""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.stats._checks import numeric, require_columns

ANOVA_ROWS = ("between", "within", "total")
ANOVA_COLUMNS = ("SS", "df", "MS", "F", "p")


def anova_oneway(data: pd.DataFrame, value: str, group: str) -> pd.DataFrame:
    """One-way ANOVA of ``value`` across the levels of ``group``.

    Parameters
    ----------
    data : DataFrame
        One row per observation; rows with a missing value or group are dropped.
    value : str
        The response column.
    group : str
        The factor column (e.g. ``"subject"``).

    Returns
    -------
    DataFrame
        Indexed by ``between``, ``within``, ``total`` with columns ``SS`` (sum of
        squares), ``df`` (degrees of freedom), ``MS = SS/df``, ``F = MS_between /
        MS_within`` and ``p = P(F_{df_b, df_w} > F)``.  ``MS`` of ``total`` and ``F``/``p``
        of ``within`` and ``total`` are NaN, as in a classical ANOVA table.

    Notes
    -----
    Fitted as the linear model ``value ~ C(group)`` with ``statsmodels.formula.api.ols``
    and ``statsmodels.stats.anova.anova_lm`` (type I sums of squares).  Before fitting,
    the response is shifted by one of its own values; the shift is exact in floating
    point for data with many constant leading digits (NIST SmLs07–09) and leaves every
    sum of squares unchanged, but keeps the least-squares fit well conditioned.

    ``SS_total = SS_between + SS_within``, ``df_total = N - 1`` (seed 003 Table C1 rows
    "Between groups", "Within groups", "Total").

    References
    ----------
    Qi, Y. et al. Sensors 2014, 14(8), 15434–15457 (seed 003), §4.4.2 and Table C1.
    NIST/ITL StRD, Analysis of Variance datasets (certified values).
    """
    require_columns(data, [value, group], "anova_oneway")
    y = numeric(data, value, "anova_oneway")
    g = data[group].to_numpy(dtype=object)
    ok = np.isfinite(y) & ~pd.isna(data[group]).to_numpy()
    y, g = y[ok], g[ok]
    levels = pd.unique(pd.Series(g, dtype=object))
    if levels.size < 2:
        raise GaitvalError(f"anova_oneway: {group!r} has {levels.size} level(s) with data; "
                           "a one-way ANOVA needs at least 2 groups")
    if y.size - levels.size < 1:
        raise GaitvalError(f"anova_oneway: {y.size} observations in {levels.size} groups "
                           "leave no degrees of freedom within groups",
                           hint="each group needs more than one observation")
    from statsmodels.formula.api import ols
    from statsmodels.stats.anova import anova_lm

    codes = {lv: i for i, lv in enumerate(sorted(levels, key=str))}
    frame = pd.DataFrame({"y": y - y[0],                     # exact shift, SS unchanged
                          "g": [f"g{codes[v]:06d}" for v in g]})
    fit = ols("y ~ C(g)", data=frame).fit()
    a = anova_lm(fit, typ=1)
    ss_b, ss_w = float(a.loc["C(g)", "sum_sq"]), float(a.loc["Residual", "sum_sq"])
    df_b, df_w = float(a.loc["C(g)", "df"]), float(a.loc["Residual", "df"])
    ms_b, ms_w = ss_b / df_b, ss_w / df_w
    out = pd.DataFrame(
        {"SS": [ss_b, ss_w, ss_b + ss_w],
         "df": [int(df_b), int(df_w), int(df_b + df_w)],
         "MS": [ms_b, ms_w, np.nan],
         "F": [float(a.loc["C(g)", "F"]), np.nan, np.nan],
         "p": [float(a.loc["C(g)", "PR(>F)"]), np.nan, np.nan]},
        index=pd.Index(list(ANOVA_ROWS), name="source"))
    return out
