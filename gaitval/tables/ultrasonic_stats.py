"""Qi et al. 2014 Tables 7, 8 and C1: normality, speed comparison (paired t-tests) and ANOVA.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal gait
parameters using a low-cost ultrasonic motion analysis system. Sensors 2014, 14(8),
15434–15457 (Qi et al. 2014), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.stats import anova_oneway, normality, paired_ttest
from gaitval.stats.summary import summarize_errors
from gaitval.tables import _published_qi2014 as pub
from gaitval.tables.ultrasonic_params import (PARAM_INFO, PARAMETERS, SPEEDS,
                                              SUMMARY_PARAMETERS, check_gait_params, n_text,
                                              select, strides_per_subject_of)

#: Table 7's comparability with the published table: the verdict page reads
#: the fixed prefix "not comparable: ".
TABLE7_NOT_COMPARABLE = (
    "not comparable: the published Table 7 is not a normality test - its H and p test the "
    "null hypothesis 'mean is zero' (H = 0, p = 1.000 for every parameter, Qi et al. 2014 "
    "§4.4.2), while gaitval's H and p are a Lilliefors test of normality")
#: Table C1's two readings of "between groups".
C1_GROUPINGS = ("subject", "stride_index")


def table7(gait_params: pd.DataFrame, speed: str = "normal", column: str = "system",
           method: str = "lilliefors") -> pd.DataFrame:
    """Normality of each gait parameter (Qi et al. 2014 Table 7), done as a normality test.

    Parameters
    ----------
    gait_params : DataFrame
        The gait parameter table.
    speed : str
        Speed whose strides are pooled over subjects (``"all"`` pools every speed).
    column : {"system", "reference"}
        Which system's estimates are tested (the paper: "the estimated parameters").
    method : {"lilliefors", "jarque_bera"}
        See :func:`gaitval.stats.normality`.

    Returns
    -------
    DataFrame
        One row per parameter S, T, V, hS, vS: ``parameter``, ``symbol``, ``unit``, ``n``,
        ``mean``, ``std``, ``ci95_low``, ``ci95_high``, ``method``, ``statistic``, ``p``,
        ``H`` (1 = normality rejected at 5%), and the published ``mean_published``,
        ``std_published``, ``H_published``, ``p_published``, ``ci95_low_published``,
        ``ci95_high_published``, and ``comparability``: :data:`TABLE7_NOT_COMPARABLE`
        (the paper's H and p answer another question; its mean, std and CI are
        comparable).

    Notes
    -----
    The paper's Table 7 reports H = 0 and p = 1.000 for a null hypothesis of "mean is
    zero" (§4.4.2); that is not a normality test and its p-values cannot be reproduced.
    gaitval tests normality itself (Lilliefors by default, MATLAB ``lillietest``'s test).
    """
    if column not in ("system", "reference"):
        raise GaitvalError(f"table7: column must be 'system' or 'reference', not {column!r}")
    df = check_gait_params(gait_params)
    parts = [select(df, p, None if speed == "all" else speed, "table7")
             for p in SUMMARY_PARAMETERS]
    nt = normality(pd.concat(parts), column, by="parameter", method=method)
    nt = nt.set_index("parameter").loc[list(SUMMARY_PARAMETERS)].reset_index()
    nt.insert(1, "symbol", [PARAM_INFO[p][0] for p in nt["parameter"]])
    nt.insert(2, "unit", [PARAM_INFO[p][2] for p in nt["parameter"]])
    names = ["mean", "std", "H", "p", "ci95_low", "ci95_high"]
    published = speed == "normal" and column == "system"
    for i, name in enumerate(names):
        nt[name + "_published"] = [pub.TABLE_7[p][i] if published else np.nan
                                   for p in nt["parameter"]]
    nt["comparability"] = TABLE7_NOT_COMPARABLE
    return nt


def _per_subject(df: pd.DataFrame) -> pd.DataFrame:
    """Per (parameter, speed, subject): mean ref, mean pro, RMSE (the Table 8 inputs)."""
    rows = []
    for (param, speed, subject), sub in df.groupby(["parameter", "speed", "subject"],
                                                   sort=True):
        e = summarize_errors(sub["reference"].to_numpy(), sub["system"].to_numpy())
        for q, v in (("ref", e["ref_mean"]), ("pro", e["pro_mean"]), ("rmse", e["rmse"])):
            rows.append({"parameter": param, "speed": speed, "subject": subject,
                         "quantity": q, "value": v})
    return pd.DataFrame(rows, columns=["parameter", "speed", "subject", "quantity", "value"])


def table8(gait_params: pd.DataFrame, alpha: float = 0.05) -> pd.DataFrame:
    """Gait parameters at slow, normal and fast speed with paired t-tests (Table 8).

    For every parameter present and quantity ``ref`` (subject mean of the reference),
    ``pro`` (subject mean of the system) and ``rmse`` (subject RMSE of system − reference),
    the per-subject values are summarised across subjects (mean, sample std) at each
    speed, and slow and fast are each compared with normal by a paired t-test over
    subjects (:func:`gaitval.stats.paired_ttest`, ``pair_by="subject"``).

    Returns
    -------
    DataFrame
        One row per (parameter, quantity): ``parameter``, ``symbol``, ``unit``,
        ``quantity``, ``slow_mean``, ``slow_std``, ``slow_n``, ``slow_p``,
        ``slow_significant``, ``normal_mean``, ``normal_std``, ``normal_n``, ``fast_mean``,
        ``fast_std``, ``fast_n``, ``fast_p``, ``fast_significant``, ``n_subjects``, and
        ``*_published`` beside each numeric
        column the paper prints.  ``p`` is NaN when all paired differences are equal
        (the paper prints "NaN" for cadence RMSE).  ``<speed>_n`` is, on the NS and NV
    rows, the ``n`` of eq. (18), (21) — the strides per subject at that speed (``"10"``,
    or the range over subjects such as ``"231-264"``); empty on the other rows.

    Notes
    -----
    The paper's §4.2 says "two-sample t-tests" while §4.4.3 and the caption say paired
    t-tests; gaitval pairs by subject (every subject walked at every speed).
    """
    df = check_gait_params(gait_params)
    present = [p for p in PARAMETERS if p in set(df["parameter"].unique())]
    ps = _per_subject(df[df["parameter"].isin(present)])
    rows = []
    for param in present:
        for q in ("ref", "pro", "rmse"):
            sub = ps[(ps["parameter"] == param) & (ps["quantity"] == q)]
            row = {"parameter": param, "symbol": PARAM_INFO[param][0],
                   "unit": PARAM_INFO[param][2], "quantity": q}
            for sp in SPEEDS:
                v = sub.loc[sub["speed"] == sp, "value"].to_numpy(dtype=float)
                v = v[np.isfinite(v)]
                row[f"{sp}_mean"] = float(np.mean(v)) if v.size else np.nan
                row[f"{sp}_std"] = float(np.std(v, ddof=1)) if v.size > 1 else np.nan
                row[f"{sp}_n"] = (n_text(strides_per_subject_of(df, sp))   # eq. (18), (21)
                                  if param.endswith("_norm") else "")
                if sp != "normal":
                    t = paired_ttest(sub, "value", "subject", "speed", sp, "normal",
                                     alpha=alpha).iloc[0]
                    row[f"{sp}_p"] = float(t["p"])
                    row[f"{sp}_significant"] = bool(t["significant"])
            row["n_subjects"] = int(sub["subject"].nunique())
            published = pub.TABLE_8.get((param, q))
            cols = ["slow_mean", "slow_std", "slow_p", "normal_mean", "normal_std",
                    "fast_mean", "fast_std", "fast_p"]
            for i, c in enumerate(cols):
                row[c + "_published"] = published[i] if published else np.nan
            rows.append(row)
    order = ["parameter", "symbol", "unit", "quantity", "slow_mean", "slow_std", "slow_n",
             "slow_p", "slow_significant", "normal_mean", "normal_std", "normal_n",
             "fast_mean", "fast_std", "fast_n", "fast_p", "fast_significant", "n_subjects"]
    out = pd.DataFrame(rows)
    return out[order + [c for c in out.columns if c.endswith("_published")]]


def tableC1(gait_params: pd.DataFrame, speed: str = "normal", column: str = "system",
            max_strides_per_subject: int | None = None,
            groupings: tuple[str, ...] = C1_GROUPINGS) -> pd.DataFrame:
    """One-way ANOVA of S, T, V, hS, vS (Qi et al. 2014 Table C1), in both readings of its groups.

    Parameters
    ----------
    gait_params : DataFrame
        The gait parameter table; the tables use the strides drawn by
        :func:`gaitval.tables.ultrasonic_params.sample_strides` (its ``stride_index``).
    speed : str
        Speed analysed (the paper's tables are at normal speed).
    column : {"system", "reference"}
        Which system's estimates are analysed.
    max_strides_per_subject : int, optional
        Use only the first ``m`` strides (by ``stride`` number) of each subject.
    groupings : tuple of str
        ``"subject"``: the groups are the subjects (what the paper's text says: "differences
        in the means of the ten subjects").  ``"stride_index"``: the groups are the
        position of a stride in its subject's sample (the columns of a subjects × strides
        matrix given to MATLAB's ``anova1``), what the paper's numbers imply: its
        within-group mean square (0.0144 m² for S) equals the between- plus
        within-subject variance of its Tables 2–6.  Without a ``stride_index`` column it
        is the stride's order within its subject and speed.

    Returns
    -------
    DataFrame
        One row per (parameter, grouping, source) with ``source`` in ``between``,
        ``within``, ``total``: ``parameter``, ``symbol``, ``grouping``, ``source``, ``SS``,
        ``df``, ``MS``, ``F``, ``p`` (:func:`gaitval.stats.anova_oneway`), and
        ``SS_published`` … ``p_published`` (the one published table, beside both
        readings).
    """
    if column not in ("system", "reference"):
        raise GaitvalError(f"tableC1: column must be 'system' or 'reference', not {column!r}")
    bad = [g for g in groupings if g not in C1_GROUPINGS]
    if bad:
        raise GaitvalError(f"tableC1: unknown grouping(s) {bad}; known: {list(C1_GROUPINGS)}")
    df = check_gait_params(gait_params)
    frames = []
    for param in SUMMARY_PARAMETERS:
        sub = select(df, param, speed, "tableC1")
        if max_strides_per_subject is not None:
            sub = (sub.sort_values(["subject", "trial", "stride"])
                   .groupby("subject", sort=True).head(max_strides_per_subject))
        if "stride_index" not in sub:
            sub = sub.sort_values(["subject", "trial", "stride"], kind="stable")
            sub = sub.assign(stride_index=sub.groupby("subject").cumcount())
        for grouping in groupings:
            try:
                a = anova_oneway(sub, column, grouping).reset_index()
            except GaitvalError:
                # fewer than two groups with data: the ANOVA is undefined, say so by NaN
                a = pd.DataFrame({"source": ["between", "within", "total"],
                                  **{c: np.nan for c in ("SS", "df", "MS", "F", "p")}})
            a.insert(0, "parameter", param)
            a.insert(1, "symbol", PARAM_INFO[param][0])
            a.insert(2, "grouping", grouping)
            published = pub.TABLE_C1[param] if speed == "normal" else None
            for i, c in enumerate(["SS", "df", "MS", "F", "p"]):
                a[c + "_published"] = [published[s][i] if published else np.nan
                                       for s in a["source"]]
            frames.append(a)
    return pd.concat(frames, ignore_index=True)
