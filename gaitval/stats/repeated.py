"""Agreement statistics with several observations per subject (repeated measures).

A validation study pools many strides of few subjects.  Strides of one subject share that
subject's bias, so treating them as independent rows makes the Bland–Altman limits of
agreement too narrow and every confidence interval too short.  This module gives the
standard answers, tidy DataFrame in, tidy DataFrame out:

- :func:`loa_nested` — the true value varies within a subject (one stride, one walk, one
  time point per row; both systems measure the same stride): limits of agreement from the
  between- and within-subject variance of the differences, bias with a CI from a
  random-intercept mixed model (REML, Satterthwaite df; the same estimates as
  statsmodels ``MixedLM`` where it converges), MOVER confidence limits for the limits
  (Zou 2013).  ``method="moments"`` gives Zou's
  method-of-moments estimator instead (SimplyAgree ``agree_nest``).
- :func:`loa_replicates` — the true value is constant within a subject (replicates; the
  two systems' replicates need not be paired or equal in number): Bland & Altman (2007)
  §3 / Zou (2013) estimator with MOVER limits (SimplyAgree ``agree_reps``).
- :func:`proportional_bias` — regression of the difference on the mean of the two
  systems (Bland & Altman 1999 §3.2), with a subject random intercept when subjects
  repeat.
- :func:`~gaitval.stats.icc_mixed.icc_mixed` — intraclass correlations (agreement and consistency) from the
  variance components of a mixed model: subject, occasion within subject (e.g. stride),
  subject × rater and residual, plus the systematic rater variance (Carrasco & Jover
  2003; Carrasco et al. 2009).  With one row per subject it reduces to McGraw & Wong's
  ICC(A,1) and ICC(C,1).
- :func:`mover_limits` — the MOVER step on its own (limits of agreement and their CIs
  from a bias CI and a sum of variance components with their degrees of freedom).

Differences are always ``d = pro − ref`` (system − reference), as in
:func:`gaitval.stats.agreement`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats._checks import as_by, groups, numeric, require_columns
from gaitval.stats._mixed import (_FIT_ERRORS, _fit_random_intercept, _nan_row, _prepare,  # noqa: F401
                                  _subject_codes, mover_limits)

#: Full citations of the methods (used in docstrings and table notes).
BLAND_ALTMAN_2007 = ("Bland, J.M.; Altman, D.G. Agreement between methods of measurement "
                     "with multiple observations per individual. J. Biopharm. Stat. 2007, "
                     "17(4), 571-582")
ZOU_2013 = ("Zou, G.Y. Confidence interval estimation for the Bland-Altman limits of "
            "agreement with multiple observations per individual. Stat. Methods Med. Res. "
            "2013, 22(6), 630-642")
ZOU_DONNER_2008 = ("Zou, G.Y.; Donner, A. Construction of confidence limits about effect "
                   "measures: a general approach. Stat. Med. 2008, 27(10), 1693-1702")
CARRASCO_JOVER_2003 = ("Carrasco, J.L.; Jover, L. Estimating the generalized concordance "
                       "correlation coefficient through variance components. Biometrics "
                       "2003, 59(4), 849-858")
CARRASCO_2009 = ("Carrasco, J.L.; King, T.S.; Chinchilli, V.M. The concordance correlation "
                 "coefficient for repeated measures estimated by variance components. "
                 "J. Biopharm. Stat. 2009, 19(1), 90-105")
SATTERTHWAITE_1946 = ("Satterthwaite, F.E. An approximate distribution of estimates of "
                      "variance components. Biometrics Bull. 1946, 2(6), 110-114")
CALDWELL_2022 = ("Caldwell, A.R. SimplyAgree: an R package and jamovi module for "
                 "simplifying agreement and reliability analyses. J. Open Source Softw. "
                 "2022, 7(71), 4148")

LOA_COLUMNS = ("n_subjects", "n", "m_harmonic", "bias", "bias_se", "bias_df", "bias_ci_low",
               "bias_ci_high", "var_between", "var_within", "sd_total", "loa_low",
               "loa_high", "loa_low_ci_low", "loa_low_ci_high", "loa_high_ci_low",
               "loa_high_ci_high")
REPLICATE_COLUMNS = ("n_subjects", "n_ref", "n_pro", "m_harmonic_ref", "m_harmonic_pro",
                     "bias", "bias_se", "bias_ci_low", "bias_ci_high", "var_between",
                     "var_within_ref", "var_within_pro", "sd_total", "loa_low", "loa_high",
                     "loa_low_ci_low", "loa_low_ci_high", "loa_high_ci_low",
                     "loa_high_ci_high")
PROP_BIAS_COLUMNS = ("n", "n_subjects", "intercept", "slope", "slope_se", "slope_df",
                     "slope_ci_low", "slope_ci_high", "p", "significant", "model")
ICC_MIXED_COLUMNS = ("design", "n_subjects", "n_occasions", "k", "var_subject",
                     "var_occasion", "var_subject_rater", "var_residual", "var_rater",
                     "icc_agreement", "icc_consistency")
NESTED_METHODS = ("reml", "moments", "anova")
#: what a mixed-model fit on degenerate data raises (the result is then NaN)




def _nested_one(d: np.ndarray, codes: np.ndarray, agree: float, alpha: float,
                method: str) -> dict:
    """Limits of agreement of paired differences ``d`` grouped by subject ``codes``."""
    out = _nan_row(LOA_COLUMNS)
    m = np.bincount(codes).astype(float)                        # pairs per subject m_i
    n, N = int(m.size), int(d.size)
    out.update(n_subjects=n, n=N)
    if n == 0:
        return out
    mh = n / np.sum(1 / m)                                      # harmonic mean m_h
    out["m_harmonic"] = mh
    if n < 2 or (method == "reml" and N == n):
        # one subject: no between-subject variance; REML needs a subject with 2+ pairs
        out["bias"] = float(np.mean(d))
        return out
    if np.ptp(d) <= 1e-12 * max(float(np.max(np.abs(d))), 1.0):
        # every difference equal: exact bias, no spread, no sampling distribution
        out.update(bias=float(d[0]), var_between=0.0, var_within=0.0, sd_total=0.0,
                   loa_low=float(d[0]), loa_high=float(d[0]))
        return out
    z_c = sps.norm.ppf(1 - alpha / 2)
    if method == "anova":
        # Bland & Altman 2007 (true value varies): one-way ANOVA of d by subject
        dbar_i = np.bincount(codes, weights=d) / m
        bias = float(np.mean(d))                                # d̄ over all N pairs
        ms_b = float(np.sum(m * (dbar_i - bias) ** 2) / (n - 1))
        ms_w = float(np.sum((d - dbar_i[codes]) ** 2) / (N - n)) if N > n else 0.0
        divisor = (N ** 2 - np.sum(m ** 2)) / ((n - 1) * N)     # (N² − Σm_i²)/((n−1)N)
        vb = (ms_b - ms_w) / divisor                            # σ²_db = (MS_b − MS_w)/div
        z = sps.norm.ppf(1 - (1 - agree) / 2)
        sd = float(np.sqrt(vb + ms_w))                          # σ²_d = σ²_db + σ²_dw
        out.update(bias=bias, var_between=vb, var_within=ms_w, sd_total=sd,
                   loa_low=bias - z * sd, loa_high=bias + z * sd)
        return out
    if method == "moments":
        dbar_i = np.bincount(codes, weights=d) / m              # subject means d̄_i
        bias = float(np.mean(dbar_i))                           # d̄ = Σ d̄_i / n
        s2_dbar = float(np.var(dbar_i, ddof=1))                 # s²_d̄
        ss_w = np.sum((d - dbar_i[codes]) ** 2)
        s2_w = float(ss_w / (N - n)) if N > n else 0.0          # s²_w = Σ(m_i−1)s²_i/(N−n)
        se = np.sqrt(s2_dbar / n)
        half = z_c * se                                         # Zou 2013: d̄ ∓ z s_d̄/√n
        out.update(bias=bias, bias_se=se, bias_df=np.inf,
                   var_between=s2_dbar - s2_w / mh, var_within=s2_w)
        comps = [(s2_dbar, n - 1), ((1 - 1 / mh) * s2_w, N - n)]
    else:
        try:
            fit = _fit_random_intercept(d, np.ones((N, 1)), codes, np.ones(1))
        except _FIT_ERRORS:                                     # degenerate: say so by NaN
            return out
        bias, se, nu = fit["estimate"], fit["se"], fit["df"]
        vb, vw = fit["var_between"], fit["var_within"]
        half = sps.t.ppf(1 - alpha / 2, nu) * se                # bias ∓ t(ν) SE
        out.update(bias=bias, bias_se=se, bias_df=nu, var_between=vb, var_within=vw)
        # σ² = (σ²_b + σ²_w/m_h) + (1 − 1/m_h) σ²_w: the variance of a subject mean
        # (n − 1 df) plus the rest of the within-subject variance (N − n df), Zou 2013
        comps = [(vb + vw / mh, n - 1), ((1 - 1 / mh) * vw, N - n)]
    out.update(bias_ci_low=bias - half, bias_ci_high=bias + half)
    out.update(mover_limits(bias, (bias - half, bias + half), comps, agree, alpha))
    return out


def loa_nested(df: pd.DataFrame, ref: str, pro: str, subject: str, by=None,
               agree: float = 0.95, alpha: float = 0.05,
               method: str = "reml") -> pd.DataFrame:
    """Limits of agreement when subjects contribute several pairs and the true value varies.

    Each row is one paired observation (e.g. one stride measured by the reference and the
    system); ``subject`` says whose it is.  The variance of a single difference is split
    into a between-subject part (each subject's own bias) and a within-subject part.

    Parameters
    ----------
    df : DataFrame
        One row per pair.  Rows where ``ref`` or ``pro`` is missing are dropped.
    ref, pro : str
        Reference and system columns (same unit); ``d = pro − ref``.
    subject : str
        Subject identifier column.
    by : str or list of str, optional
        Grouping columns (one result row per group, sorted).
    agree : float
        Proportion of differences the limits cover (0.95: bias ∓ 1.96 σ).
    alpha : float
        Confidence intervals have level ``1 − α``.
    method : {"reml", "moments", "anova"}
        ``"reml"`` (default): random-intercept model ``d_ij = μ + b_i + e_ij`` fitted by
        REML (profiled likelihood, :func:`_reml_fit`; statsmodels ``MixedLM`` and lme4
        give the same estimates where they converge); bias = ``μ̂`` with a t interval on
        Satterthwaite degrees of freedom; ``σ̂²_b``, ``σ̂²_w`` its variance components.
        ``"moments"``: Zou's (2013) estimator from subject means (SimplyAgree
        ``agree_nest``), bias CI with the normal quantile as Zou does.
        ``"anova"``: Bland & Altman's (2007) one-way ANOVA estimator, bias = mean of all
        differences; the paper gives no confidence intervals, so the CI columns are NaN.

    Returns
    -------
    DataFrame
        One row per group with the ``by`` columns and

        - ``n_subjects``, ``n`` (pairs), ``m_harmonic`` (harmonic mean pairs per subject);
        - ``bias``, ``bias_se``, ``bias_df`` (inf for the normal quantile),
          ``bias_ci_low``, ``bias_ci_high``;
        - ``var_between`` (σ²_b), ``var_within`` (σ²_w), ``sd_total`` = sqrt(σ²_b + σ²_w),
          the SD of a single difference;
        - ``loa_low``, ``loa_high`` = bias ∓ z sd_total and their MOVER confidence limits
          ``loa_low_ci_low``, ``loa_low_ci_high``, ``loa_high_ci_low``,
          ``loa_high_ci_high``.

        Quantities that are undefined are NaN: a single subject, or (REML) no subject
        with two pairs; equal differences give zero variances and no CIs.

    Notes
    -----
    ANOVA (Bland & Altman 2007, true value varies): ``d̄ = Σ d_ij / N``; from the one-way
    analysis of variance of ``d`` by subject, ``σ̂²_w = MS_within`` and
    ``σ̂²_b = (MS_between − MS_within) / D`` with ``D = (N² − Σ m_i²) / ((n − 1) N)``
    (``D = m`` when every subject has ``m`` pairs); ``σ̂² = σ̂²_b + σ̂²_w``.

    Moments (Zou 2013; identical to the ANOVA form when all ``m_i`` are equal):
    ``d̄_i`` subject means, ``d̄ = Σ d̄_i / n``,
    ``s²_d̄ = Σ (d̄_i − d̄)² / (n − 1)``, ``s²_w = Σ_i Σ_j (d_ij − d̄_i)² / (N − n)``,
    ``m_h = n / Σ m_i⁻¹``, and the variance of a single difference
    ``σ̂² = s²_d̄ + (1 − 1/m_h) s²_w`` (because ``var(d̄_i) = σ²_b + σ²_w / m_i``).
    Reported ``var_between = s²_d̄ − s²_w / m_h``.

    REML: ``σ̂² = σ̂²_b + σ̂²_w``, written for the MOVER step as the same two terms,
    ``(σ̂²_b + σ̂²_w/m_h)`` on ``n − 1`` df and ``(1 − 1/m_h) σ̂²_w`` on ``N − n`` df.

    Limits ``d̄ ∓ z σ̂`` with MOVER confidence limits (:func:`mover_limits`).

    References
    ----------
    Bland, J.M.; Altman, D.G. Agreement between methods of measurement with multiple
    observations per individual. J. Biopharm. Stat. 2007, 17(4), 571–582.
    Zou, G.Y. Confidence interval estimation for the Bland–Altman limits of agreement
    with multiple observations per individual. Stat. Methods Med. Res. 2013, 22(6),
    630–642.
    Satterthwaite, F.E. Biometrics Bull. 1946, 2(6), 110–114.
    Caldwell, A.R. SimplyAgree. J. Open Source Softw. 2022, 7(71), 4148.
    """
    if method not in NESTED_METHODS:
        raise GaitvalError(f"loa_nested: unknown method {method!r}",
                           hint=f"use one of {list(NESTED_METHODS)}")
    by = as_by(by)
    _prepare(df, ref, pro, subject, by, "loa_nested")
    rows = []
    for key, sub in groups(df, by):
        r = numeric(sub, ref, "loa_nested")
        p = numeric(sub, pro, "loa_nested")
        ok = np.isfinite(r) & np.isfinite(p) & sub[subject].notna().to_numpy()
        sub = sub[ok]
        codes = _subject_codes(sub, subject)
        rows.append({**key, **_nested_one(p[ok] - r[ok], codes, agree, alpha, method)})
    out = pd.DataFrame(rows, columns=[*by, *LOA_COLUMNS])
    return out.astype({"n_subjects": int, "n": int})


# ----------------------------------------------------------------------------- replicates
def _replicates_one(r: np.ndarray, p: np.ndarray, codes: np.ndarray, agree: float,
                    alpha: float) -> dict:
    out = _nan_row(REPLICATE_COLUMNS)
    fr, fp = np.isfinite(r), np.isfinite(p)
    n_all = int(codes.max()) + 1 if codes.size else 0
    mx = np.bincount(codes[fr], minlength=n_all).astype(float)     # m_xi (reference)
    my = np.bincount(codes[fp], minlength=n_all).astype(float)     # m_yi (system)
    keep = (mx > 0) & (my > 0)                                  # subjects seen by both
    mx, my = mx[keep], my[keep]
    n = int(keep.sum())
    out.update(n_subjects=n, n_ref=int(mx.sum()), n_pro=int(my.sum()))
    if n == 0:
        return out
    sel = keep[codes]
    new = np.cumsum(keep) - 1                                   # renumber kept subjects
    cr, cp = new[codes[fr & sel]], new[codes[fp & sel]]
    rv, pv = r[fr & sel], p[fp & sel]
    xbar = np.bincount(cr, weights=rv, minlength=n) / mx        # reference subject means
    ybar = np.bincount(cp, weights=pv, minlength=n) / my        # system subject means
    dbar_i = ybar - xbar                                        # d̄_i = ȳ_i − x̄_i
    bias = float(np.mean(dbar_i))
    Nx, Ny = float(mx.sum()), float(my.sum())
    mxh, myh = n / np.sum(1 / mx), n / np.sum(1 / my)           # harmonic means
    # pooled within-subject variances: s²_xw = Σ (m_xi − 1) s²_xi / (N_x − n)
    s2_xw = float(np.sum((rv - xbar[cr]) ** 2) / (Nx - n)) if Nx > n else 0.0
    s2_yw = float(np.sum((pv - ybar[cp]) ** 2) / (Ny - n)) if Ny > n else 0.0
    out.update(bias=bias, m_harmonic_ref=mxh, m_harmonic_pro=myh, var_within_ref=s2_xw,
               var_within_pro=s2_yw)
    if n < 2:
        return out
    s2_dbar = float(np.var(dbar_i, ddof=1))                     # s²_d̄
    se = np.sqrt(s2_dbar / n)
    half = sps.norm.ppf(1 - alpha / 2) * se                     # Zou 2013: d̄ ∓ z s_d̄/√n
    out.update(bias_se=se, bias_ci_low=bias - half, bias_ci_high=bias + half,
               var_between=s2_dbar - s2_xw / mxh - s2_yw / myh)
    # σ̂² = s²_d̄ + (1 − 1/m_xh) s²_xw + (1 − 1/m_yh) s²_yw   (B&A 2007 §3; Zou 2013)
    comps = [(s2_dbar, n - 1), ((1 - 1 / mxh) * s2_xw, Nx - n),
             ((1 - 1 / myh) * s2_yw, Ny - n)]
    out.update(mover_limits(bias, (bias - half, bias + half), comps, agree, alpha))
    return out


def loa_replicates(df: pd.DataFrame, ref: str, pro: str, subject: str, by=None,
                   agree: float = 0.95, alpha: float = 0.05) -> pd.DataFrame:
    """Limits of agreement from replicates: the true value is constant within a subject.

    Each row holds one replicate of ``ref`` and/or ``pro`` for a subject (a missing value
    is allowed: the two systems' replicates are not paired and their numbers may differ,
    e.g. a static pose measured five times by the reference and four by the system).

    Parameters
    ----------
    df : DataFrame
        One row per replicate.
    ref, pro : str
        Reference and system columns (same unit); differences are ``pro − ref``.
    subject : str
        Subject identifier column.
    by : str or list of str, optional
        Grouping columns.
    agree, alpha : float
        Coverage of the limits and ``1 −`` confidence level, as in :func:`loa_nested`.

    Returns
    -------
    DataFrame
        One row per group with the ``by`` columns and ``n_subjects`` (subjects measured by
        both systems), ``n_ref``, ``n_pro`` (replicates), ``m_harmonic_ref``,
        ``m_harmonic_pro``, ``bias`` (mean of the subject differences ``ȳ_i − x̄_i``),
        ``bias_se``, ``bias_ci_low``, ``bias_ci_high`` (normal quantile, as Zou 2013),
        ``var_between`` (``s²_d̄ − s²_xw/m_xh − s²_yw/m_yh``), ``var_within_ref``,
        ``var_within_pro`` (pooled within-subject variances), ``sd_total`` and the limits
        ``loa_low``, ``loa_high`` with MOVER limits ``loa_low_ci_low`` …
        ``loa_high_ci_high``.

    Notes
    -----
    With ``x̄_i``, ``ȳ_i`` the subject means of ``m_xi`` reference and ``m_yi`` system
    replicates, ``d̄_i = ȳ_i − x̄_i``, ``s²_d̄`` their variance, ``s²_xw`` and ``s²_yw`` the
    pooled within-subject variances and ``m_xh``, ``m_yh`` the harmonic means of the
    replicate numbers, the variance of the difference of single measurements is
    (Bland & Altman 2007 §3; Zou 2013 eq. for the replicate design)

    ``σ̂² = s²_d̄ + (1 − 1/m_xh) s²_xw + (1 − 1/m_yh) s²_yw``

    on ``n − 1``, ``N_x − n`` and ``N_y − n`` degrees of freedom; limits ``d̄ ∓ z σ̂``
    with MOVER confidence limits (:func:`mover_limits`).  SimplyAgree ``agree_reps``
    computes the same.

    References
    ----------
    Bland, J.M.; Altman, D.G. J. Biopharm. Stat. 2007, 17(4), 571–582.
    Zou, G.Y. Stat. Methods Med. Res. 2013, 22(6), 630–642.
    """
    by = as_by(by)
    _prepare(df, ref, pro, subject, by, "loa_replicates")
    rows = []
    for key, sub in groups(df, by):
        sub = sub[sub[subject].notna()]
        r = numeric(sub, ref, "loa_replicates")
        p = numeric(sub, pro, "loa_replicates")
        codes = _subject_codes(sub, subject)
        rows.append({**key, **_replicates_one(r, p, codes, agree, alpha)})
    out = pd.DataFrame(rows, columns=[*by, *REPLICATE_COLUMNS])
    return out.astype({"n_subjects": int, "n_ref": int, "n_pro": int})


# ----------------------------------------------------------------------------- prop. bias
def _prop_bias_one(r: np.ndarray, p: np.ndarray, codes: np.ndarray | None,
                   alpha: float) -> dict:
    out = _nan_row(PROP_BIAS_COLUMNS)
    d, a = p - r, (p + r) / 2                                   # difference, mean
    N = int(d.size)
    n_sub = int(codes.max()) + 1 if codes is not None and N else N
    out.update(n=N, n_subjects=n_sub, significant=False,
               model="ols" if codes is None else "mixed")
    # differences that vary by round-off only (a system that is the reference up to a
    # unit or frame conversion) have no slope to test: the fit would regress noise
    scale = float(np.max(np.abs(a))) if N else 0.0
    if N < 3 or np.ptp(a) == 0 or np.ptp(d) <= 1e-9 * scale:
        return out
    X = np.column_stack([np.ones(N), a])
    if codes is None or n_sub == N:
        # d = β₀ + β₁ (x+y)/2 + e by least squares (Bland & Altman 1999 §3.2)
        beta, *_ = np.linalg.lstsq(X, d, rcond=None)
        res = d - X @ beta
        nu = N - 2
        s2 = float(res @ res / nu)
        se = float(np.sqrt(s2 * np.linalg.inv(X.T @ X)[1, 1]))
        out["model"] = "ols"
    elif n_sub < 2:
        return out
    else:
        try:
            fit = _fit_random_intercept(d, X, codes, np.array([0.0, 1.0]))
        except _FIT_ERRORS:
            return out
        beta, se, nu = fit["beta"], fit["se"], fit["df"]
    t = beta[1] / se
    half = sps.t.ppf(1 - alpha / 2, nu) * se
    pval = float(2 * sps.t.sf(abs(t), nu))
    out.update(intercept=float(beta[0]), slope=float(beta[1]), slope_se=se, slope_df=nu,
               slope_ci_low=beta[1] - half, slope_ci_high=beta[1] + half, p=pval,
               significant=bool(pval < alpha))
    return out


def proportional_bias(df: pd.DataFrame, ref: str, pro: str, subject: str | None = None,
                      by=None, alpha: float = 0.05) -> pd.DataFrame:
    """Proportional bias: regression of the difference on the mean of the two systems.

    Parameters
    ----------
    df : DataFrame
        One row per pair (rows with a missing value are dropped).
    ref, pro : str
        Reference and system columns; ``d = pro − ref``, ``a = (pro + ref) / 2``.
    subject : str, optional
        Subject column.  When given and subjects repeat, the model has a subject random
        intercept, ``d_ij = β₀ + β₁ a_ij + b_i + e_ij`` (REML, as :func:`loa_nested`),
        and the slope's t interval uses Satterthwaite degrees of freedom; otherwise
        ordinary least squares on ``N − 2`` df.
    by : str or list of str, optional
        Grouping columns.
    alpha : float
        Level of the slope's CI and of ``significant``.

    Returns
    -------
    DataFrame
        One row per group with the ``by`` columns and ``n``, ``n_subjects``,
        ``intercept``, ``slope`` (β₁; 0 = no proportional bias), ``slope_se``,
        ``slope_df``, ``slope_ci_low``, ``slope_ci_high``, ``p`` (two-sided t test of
        β₁ = 0), ``significant`` (p < α) and ``model`` (``"ols"`` or ``"mixed"``).

    References
    ----------
    Bland, J.M.; Altman, D.G. Measuring agreement in method comparison studies. Stat.
    Methods Med. Res. 1999, 8, 135–160 (§3.2).
    Satterthwaite, F.E. Biometrics Bull. 1946, 2(6), 110–114.
    """
    by = as_by(by)
    require_columns(df, [ref, pro, *by] + ([subject] if subject else []),
                    "proportional_bias")
    rows = []
    for key, sub in groups(df, by):
        r = numeric(sub, ref, "proportional_bias")
        p = numeric(sub, pro, "proportional_bias")
        ok = np.isfinite(r) & np.isfinite(p)
        if subject:
            ok &= sub[subject].notna().to_numpy()
        codes = _subject_codes(sub[ok], subject) if subject else None
        rows.append({**key, **_prop_bias_one(r[ok], p[ok], codes, alpha)})
    out = pd.DataFrame(rows, columns=[*by, *PROP_BIAS_COLUMNS])
    return out.astype({"n": int, "n_subjects": int, "significant": bool})


# ----------------------------------------------------------------------------- ICC
