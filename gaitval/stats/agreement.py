"""Agreement statistics of a system with a reference: bias, limits of agreement, ICC.

Validation studies beyond seed 003 report these (e.g. Single et al. 2024); they are
computed here with NumPy/SciPy from the published formulas, so every line can be checked
against the equation beside it.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats as sps

from gaitval.stats._checks import as_by, groups, numeric, require_columns
from gaitval.stats.summary import summarize_errors
from gaitval.stats.ttest import paired_t

ICC_TYPES = ("ICC(A,1)", "ICC(C,1)", "ICC(A,k)", "ICC(C,k)")
ICC_COLUMNS = ("icc", "ci_low", "ci_high", "F", "df1", "df2", "p", "n", "k")
AGREEMENT_COLUMNS = (
    "n", "ref_mean", "pro_mean", "bias", "bias_sd", "bias_ci_low", "bias_ci_high",
    "loa_low", "loa_high", "loa_low_ci_low", "loa_low_ci_high", "loa_high_ci_low",
    "loa_high_ci_high", "rmse", "mad",
    "icc_a1", "icc_a1_ci_low", "icc_a1_ci_high", "icc_c1", "icc_c1_ci_low", "icc_c1_ci_high",
    "t", "df", "p", "significant")


def two_way_mean_squares(x: np.ndarray) -> tuple[float, float, float]:
    """Mean squares of rows (targets), columns (raters) and error of an (n, k) table.

    Two-way ANOVA without replication: ``MSR = k Σ(r̄_i - x̄)² / (n-1)``,
    ``MSC = n Σ(c̄_j - x̄)² / (k-1)``, ``MSE = (SST - SSR - SSC) / ((n-1)(k-1))``.
    """
    n, k = x.shape
    grand = x.mean()
    ssr = k * np.sum((x.mean(axis=1) - grand) ** 2)
    ssc = n * np.sum((x.mean(axis=0) - grand) ** 2)
    sse = np.sum((x - grand) ** 2) - ssr - ssc
    return ssr / (n - 1), ssc / (k - 1), sse / ((n - 1) * (k - 1))


def icc(ratings, alpha: float = 0.05) -> pd.DataFrame:
    """Intraclass correlations of the two-way model (McGraw & Wong 1996).

    Parameters
    ----------
    ratings : array_like, shape (n, k)
        ``n`` targets (e.g. strides) rated by ``k`` raters (e.g. reference and system).
        Rows with a NaN are dropped.
    alpha : float
        The confidence intervals have level ``1 - alpha``.

    Returns
    -------
    DataFrame
        Indexed by ICC type ``ICC(A,1)`` (absolute agreement, single measure; Shrout &
        Fleiss ICC(2,1)), ``ICC(C,1)`` (consistency; ICC(3,1)), ``ICC(A,k)`` and
        ``ICC(C,k)`` (average of k measures), with columns ``icc``, ``ci_low``,
        ``ci_high``, ``F``, ``df1``, ``df2``, ``p`` (test of ICC = 0), ``n``, ``k``.
        Select rows by type name (``out.loc["ICC(A,1)"]``), never by position.

    Notes
    -----
    With ``MSR, MSC, MSE`` from :func:`two_way_mean_squares` (McGraw & Wong 1996, Table 4
    and 7, cases 3/3A and 4/4A; Shrout & Fleiss 1979 eqs. for ICC(2,1), ICC(3,1)):

    - ICC(C,1) = (MSR − MSE) / (MSR + (k−1) MSE)
    - ICC(A,1) = (MSR − MSE) / (MSR + (k−1) MSE + k (MSC − MSE) / n)
    - ICC(C,k) = (MSR − MSE) / MSR
    - ICC(A,k) = (MSR − MSE) / (MSR + (MSC − MSE) / n)

    Consistency CIs: ``F0 = MSR/MSE``, ``FL = F0 / F(1−α/2; n−1, (n−1)(k−1))``,
    ``FU = F0 · F(1−α/2; (n−1)(k−1), n−1)``; ICC(C,1) ∈ [(FL−1)/(FL+k−1), (FU−1)/(FU+k−1)],
    ICC(C,k) ∈ [1 − 1/FL, 1 − 1/FU].  Absolute-agreement CIs use Satterthwaite's
    ``v = (a MSC + b MSE)² / ((a MSC)²/(k−1) + (b MSE)²/((n−1)(k−1)))`` with
    ``a = k ρ / (n (1−ρ))``, ``b = 1 + k ρ (n−1) / (n (1−ρ))``, ``ρ`` = ICC(A,1), and
    ``F* = F(1−α/2; n−1, v)``, ``F_* = F(1−α/2; v, n−1)``:
    lower = n (MSR − F* MSE) / (F* (k MSC + (kn − k − n) MSE) + n MSR),
    upper = n (F_* MSR − MSE) / (k MSC + (kn − k − n) MSE + n F_* MSR);
    ICC(A,k) bounds are the ICC(A,1) bounds stepped up by Spearman–Brown,
    ``L k / (1 + (k−1) L)``.

    References
    ----------
    McGraw, K.O.; Wong, S.P. Forming inferences about some intraclass correlation
    coefficients. Psychol. Methods 1996, 1(1), 30–46.
    Shrout, P.E.; Fleiss, J.L. Intraclass correlations: uses in assessing rater
    reliability. Psychol. Bull. 1979, 86(2), 420–428.
    """
    x = np.asarray(ratings, dtype=float)
    if x.ndim != 2:
        x = x.reshape(len(x), -1)
    x = x[np.all(np.isfinite(x), axis=1)]
    n, k = x.shape
    nan = float("nan")
    rows = {t: dict.fromkeys(ICC_COLUMNS, nan) for t in ICC_TYPES}
    for t in ICC_TYPES:
        rows[t].update(n=n, k=k)
    if n < 2 or k < 2:
        return pd.DataFrame.from_dict(rows, orient="index")[list(ICC_COLUMNS)]
    msr, msc, mse = two_way_mean_squares(x)
    df1, df2 = n - 1, (n - 1) * (k - 1)
    q = 1 - alpha / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        f0 = msr / mse
        p_f0 = float(sps.f.sf(f0, df1, df2))
        # F test of ICC(A,.) = 0: McGraw & Wong 1996 Table 8 case 3A with rho0 = 0
        # (a = 0, b = 1) reduces to F = MSR / MSE on (n-1, (n-1)(k-1)) df, as for ICC(C,.)
        test = {"F": f0, "df1": df1, "df2": df2, "p": p_f0}
        c_1, c_k = _icc_consistency(msr, mse, n, k, q)
        a_1, a_k = _icc_absolute(msr, msc, mse, n, k, q)
        rows["ICC(C,1)"].update(**c_1, **test)
        rows["ICC(C,k)"].update(**c_k, **test)
        rows["ICC(A,1)"].update(**a_1, **test)
        rows["ICC(A,k)"].update(**a_k, **test)
    out = pd.DataFrame.from_dict(rows, orient="index")[list(ICC_COLUMNS)]
    out.index.name = "type"
    return out.astype(float)


def _icc_consistency(msr: float, mse: float, n: int, k: int, q: float
                     ) -> tuple[dict, dict]:
    """ICC(C,1) and ICC(C,k) with their F-based CIs (formulas in :func:`icc`'s notes).

    ``q = 1 − α/2``.  Call inside ``np.errstate(divide="ignore", invalid="ignore")``.
    """
    df1, df2 = n - 1, (n - 1) * (k - 1)
    c1 = (msr - mse) / (msr + (k - 1) * mse)                      # ICC(C,1), S&F ICC(3,1)
    ck = (msr - mse) / msr                                        # ICC(C,k), ICC(3,k)
    f0 = msr / mse
    fl = f0 / sps.f.ppf(q, df1, df2)
    fu = f0 * sps.f.ppf(q, df2, df1)
    return ({"icc": c1, "ci_low": (fl - 1) / (fl + k - 1), "ci_high": (fu - 1) / (fu + k - 1)},
            {"icc": ck, "ci_low": 1 - 1 / fl, "ci_high": 1 - 1 / fu})


def _icc_absolute(msr: float, msc: float, mse: float, n: int, k: int, q: float
                  ) -> tuple[dict, dict]:
    """ICC(A,1) and ICC(A,k) with Satterthwaite CIs (formulas in :func:`icc`'s notes).

    ``q = 1 − α/2``.  Call inside ``np.errstate(divide="ignore", invalid="ignore")``.
    """
    df1, df2 = n - 1, (n - 1) * (k - 1)
    a1 = (msr - mse) / (msr + (k - 1) * mse + k * (msc - mse) / n)  # ICC(A,1), ICC(2,1)
    ak = (msr - mse) / (msr + (msc - mse) / n)                    # ICC(A,k), ICC(2,k)
    # absolute agreement: McGraw & Wong 1996 Table 7, case 3A (Satterthwaite df)
    a = k * a1 / (n * (1 - a1))
    b = 1 + k * a1 * (n - 1) / (n * (1 - a1))
    v = (a * msc + b * mse) ** 2 / ((a * msc) ** 2 / (k - 1) + (b * mse) ** 2 / df2)
    f_star = sps.f.ppf(q, df1, v)
    f_low = sps.f.ppf(q, v, df1)
    lo = n * (msr - f_star * mse) / (f_star * (k * msc + (k * n - k - n) * mse)
                                     + n * msr)
    hi = n * (f_low * msr - mse) / (k * msc + (k * n - k - n) * mse + n * f_low * msr)
    # ICC(A,k) bounds: the ICC(A,1) bounds stepped up by Spearman–Brown
    return ({"icc": a1, "ci_low": lo, "ci_high": hi},
            {"icc": ak, "ci_low": lo * k / (1 + (k - 1) * lo),
             "ci_high": hi * k / (1 + (k - 1) * hi)})


def bland_altman(ref: np.ndarray, pro: np.ndarray, alpha: float = 0.05) -> dict[str, float]:
    """Bias and Bland–Altman 95% limits of agreement with their approximate CIs.

    ``d = pro - ref``; bias ``d̄`` with CI ``d̄ ± t(1−α/2; n−1) s/√n``; limits
    ``d̄ ± 1.96 s``, each with CI ``± t(1−α/2; n−1) · sqrt(3 s²/n)`` (Bland & Altman 1999,
    §2.1: SE of a limit ≈ sqrt(3 s²/n)).  Pairs with a NaN are dropped.
    """
    ref = np.asarray(ref, dtype=float)
    pro = np.asarray(pro, dtype=float)
    ok = np.isfinite(ref) & np.isfinite(pro)
    d = pro[ok] - ref[ok]
    n = int(d.size)
    nan = float("nan")
    out = dict.fromkeys(("bias", "bias_sd", "bias_ci_low", "bias_ci_high", "loa_low",
                         "loa_high", "loa_low_ci_low", "loa_low_ci_high", "loa_high_ci_low",
                         "loa_high_ci_high"), nan)
    if n == 0:
        return out
    bias = float(np.mean(d))
    out["bias"] = bias
    if n < 2:
        return out
    s = float(np.std(d, ddof=1))
    tq = sps.t.ppf(1 - alpha / 2, n - 1)
    z = sps.norm.ppf(1 - alpha / 2)                         # 1.96 for alpha = 0.05
    se_bias = s / np.sqrt(n)                                # SE(d̄) = s/√n
    se_loa = np.sqrt(3 * s ** 2 / n)                        # SE(LoA) ≈ sqrt(3 s²/n)
    lo, hi = bias - z * s, bias + z * s                     # LoA = d̄ ± 1.96 s
    out.update(bias_sd=s, bias_ci_low=bias - tq * se_bias, bias_ci_high=bias + tq * se_bias,
               loa_low=lo, loa_high=hi,
               loa_low_ci_low=lo - tq * se_loa, loa_low_ci_high=lo + tq * se_loa,
               loa_high_ci_low=hi - tq * se_loa, loa_high_ci_high=hi + tq * se_loa)
    return out


def agreement(df: pd.DataFrame, ref: str, pro: str, by=None,
              alpha: float = 0.05) -> pd.DataFrame:
    """Agreement of ``pro`` (system) with ``ref`` (reference) per group.

    Parameters
    ----------
    df : DataFrame
        One row per paired observation.
    ref, pro : str
        Reference and system columns (same unit).
    by : str or list of str, optional
        Grouping columns (e.g. ``"parameter"``).
    alpha : float
        1 − confidence level of every interval (0.05 → 95%).

    Returns
    -------
    DataFrame
        One row per group with the ``by`` columns and

        - ``n``, ``ref_mean``, ``pro_mean``;
        - ``bias`` (mean of ``pro − ref``), ``bias_sd``, ``bias_ci_low``/``_high``;
        - ``loa_low``/``loa_high`` (bias ∓ 1.96 sd) and their CIs
          ``loa_low_ci_low`` … ``loa_high_ci_high``;
        - ``rmse``, ``mad`` (mean absolute difference);
        - ``icc_a1``, ``icc_c1`` with ``_ci_low``/``_ci_high`` (see :func:`icc`);
        - ``t``, ``df``, ``p``, ``significant``: paired t-test of the bias
          (``scipy.stats.ttest_rel(pro, ref)``).

    References
    ----------
    Bland, J.M.; Altman, D.G. Measuring agreement in method comparison studies. Stat.
    Methods Med. Res. 1999, 8, 135–160.
    McGraw, K.O.; Wong, S.P. Psychol. Methods 1996, 1(1), 30–46.
    """
    by = as_by(by)
    require_columns(df, [ref, pro, *by], "agreement")
    rows = []
    for key, sub in groups(df, by):
        r = numeric(sub, ref, "agreement")
        s = numeric(sub, pro, "agreement")
        ok = np.isfinite(r) & np.isfinite(s)
        r, s = r[ok], s[ok]
        err = summarize_errors(r, s)
        ba = bland_altman(r, s, alpha)
        ic = icc(np.column_stack([r, s]), alpha)
        tt = paired_t(s, r, alpha)
        rows.append({
            **key, "n": int(r.size), "ref_mean": err["ref_mean"], "pro_mean": err["pro_mean"],
            **ba, "rmse": err["rmse"], "mad": err["mad"],
            "icc_a1": ic.loc["ICC(A,1)", "icc"], "icc_a1_ci_low": ic.loc["ICC(A,1)", "ci_low"],
            "icc_a1_ci_high": ic.loc["ICC(A,1)", "ci_high"],
            "icc_c1": ic.loc["ICC(C,1)", "icc"], "icc_c1_ci_low": ic.loc["ICC(C,1)", "ci_low"],
            "icc_c1_ci_high": ic.loc["ICC(C,1)", "ci_high"],
            "t": tt["t"], "df": tt["df"], "p": tt["p"], "significant": tt["significant"]})
    out = pd.DataFrame(rows, columns=[*by, *AGREEMENT_COLUMNS])
    out["n"] = out["n"].astype(int)
    out["df"] = out["df"].astype(int)
    return out
