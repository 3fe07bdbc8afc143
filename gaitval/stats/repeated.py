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
- :func:`icc_mixed` — intraclass correlations (agreement and consistency) from the
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

import warnings
from collections.abc import Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats._checks import as_by, groups, numeric, require_columns

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
_FIT_ERRORS = (np.linalg.LinAlgError, ValueError, ZeroDivisionError)


# ----------------------------------------------------------------------------- MOVER
def _variance_sum_limits(components: Sequence[tuple[float, float]], alpha: float
                         ) -> tuple[float, float, float]:
    """MOVER confidence limits of a sum of variance components (Zou 2013, eq. for l, u).

    ``components``: ``(c_k σ̂²_k, ν_k)`` pairs; ``σ̂² = Σ c_k σ̂²_k`` and

    - ``l = σ̂² − sqrt(Σ [c_k σ̂²_k (1 − ν_k / χ²(1−α/2; ν_k))]²)``
    - ``u = σ̂² + sqrt(Σ [c_k σ̂²_k (ν_k / χ²(α/2; ν_k) − 1)]²)``

    Components with a zero coefficient or ``ν_k ≤ 0`` add nothing.  Returns ``(σ̂², l, u)``
    with ``l`` clipped at 0.
    """
    total = float(sum(c for c, _ in components))
    lo2 = hi2 = 0.0
    for c, nu in components:
        if c == 0 or not nu > 0:
            continue
        lo2 += (c * (1 - nu / sps.chi2.ppf(1 - alpha / 2, nu))) ** 2
        hi2 += (c * (nu / sps.chi2.ppf(alpha / 2, nu) - 1)) ** 2
    return total, max(total - np.sqrt(lo2), 0.0), total + np.sqrt(hi2)


def mover_limits(bias: float, bias_ci: tuple[float, float],
                 components: Sequence[tuple[float, float]], agree: float = 0.95,
                 alpha: float = 0.05) -> dict[str, float]:
    """Limits of agreement ``bias ∓ z σ`` and their MOVER confidence limits.

    Parameters
    ----------
    bias : float
        Estimated mean difference ``θ̂``.
    bias_ci : (float, float)
        Its ``1 − α`` confidence limits ``(l₁, u₁)``.
    components : sequence of (float, float)
        ``(c_k σ̂²_k, ν_k)``: the terms whose sum is the variance of a single difference,
        each with its degrees of freedom (e.g. ``(s²_d̄, n − 1)`` and
        ``((1 − 1/m_h) s²_w, N − n)``).
    agree : float
        Proportion of differences the limits should cover (0.95 → ``z = 1.96``).
    alpha : float
        The confidence limits have level ``1 − α`` (two-sided).

    Returns
    -------
    dict
        ``sd_total``, ``loa_low``, ``loa_high``, ``loa_low_ci_low``, ``loa_low_ci_high``,
        ``loa_high_ci_low``, ``loa_high_ci_high``.

    Notes
    -----
    MOVER (Zou & Donner 2008): with ``(l, u)`` the limits of ``σ²`` from
    :func:`_variance_sum_limits` and ``z = Φ⁻¹(1 − (1 − agree)/2)``, the lower limit of
    agreement ``θ − zσ`` has confidence limits

    - ``θ̂ − zσ̂ − sqrt((θ̂ − l₁)² + z² (√u − σ̂)²)``
    - ``θ̂ − zσ̂ + sqrt((u₁ − θ̂)² + z² (σ̂ − √l)²)``

    and the upper limit ``θ + zσ`` symmetrically (Zou 2013, §2.2).

    References
    ----------
    Zou, G.Y.; Donner, A. Stat. Med. 2008, 27(10), 1693–1702.
    Zou, G.Y. Stat. Methods Med. Res. 2013, 22(6), 630–642.
    """
    s2, l, u = _variance_sum_limits(components, alpha)
    z = sps.norm.ppf(1 - (1 - agree) / 2)
    sd = float(np.sqrt(s2))
    lo, hi = bias - z * sd, bias + z * sd                       # LoA = θ ∓ z σ
    below, above = bias - bias_ci[0], bias_ci[1] - bias         # θ̂ − l₁, u₁ − θ̂
    wide = z * (np.sqrt(u) - sd)                                # z (√u − σ̂)
    narrow = z * (sd - np.sqrt(l))                              # z (σ̂ − √l)
    return {"sd_total": sd, "loa_low": lo, "loa_high": hi,
            "loa_low_ci_low": lo - np.hypot(below, wide),
            "loa_low_ci_high": lo + np.hypot(above, narrow),
            "loa_high_ci_low": hi - np.hypot(below, narrow),
            "loa_high_ci_high": hi + np.hypot(above, wide)}


# ----------------------------------------------------------------------------- REML
def _reml_pieces(y: np.ndarray, X: np.ndarray, codes: np.ndarray, var_b: float,
                 var_w: float) -> tuple[float, np.ndarray, float, np.ndarray]:
    """REML deviance, ``Φ = (X'V⁻¹X)⁻¹``, ``r'V⁻¹r`` and GLS ``β̂``, random-intercept model.

    ``y_i = X_i β + b_i 1 + e_i``, ``b_i ~ N(0, σ²_b)``, ``e ~ N(0, σ²_w I)``, so
    ``V_i⁻¹ = (I − γ_i 11') / σ²_w`` with ``γ_i = σ²_b / (σ²_w + m_i σ²_b)`` and
    ``log|V_i| = (m_i − 1) log σ²_w + log(σ²_w + m_i σ²_b)``.  The deviance (−2 × REML
    log-likelihood without its constant) is
    ``Σ log|V_i| + log|X'V⁻¹X| + (y − Xβ̂)'V⁻¹(y − Xβ̂)`` with ``β̂`` the GLS estimate.
    """
    m = np.bincount(codes).astype(float)
    gam = var_b / (var_w + m * var_b)
    sx = np.column_stack([np.bincount(codes, weights=X[:, j], minlength=m.size)
                          for j in range(X.shape[1])])          # 1'X_i per group
    sy = np.bincount(codes, weights=y)                          # 1'y_i per group
    xtvx = (X.T @ X - (sx * gam[:, None]).T @ sx) / var_w       # X'V⁻¹X
    xtvy = (X.T @ y - (sx * gam[:, None]).T @ sy) / var_w       # X'V⁻¹y
    phi = np.linalg.inv(xtvx)
    beta = phi @ xtvy
    r = y - X @ beta
    sr = np.bincount(codes, weights=r)
    quad = (r @ r - np.sum(gam * sr ** 2)) / var_w              # r'V⁻¹r
    logdet = np.sum((m - 1) * np.log(var_w) + np.log(var_w + m * var_b))
    dev = logdet + np.linalg.slogdet(xtvx)[1] + quad
    return float(dev), phi, float(quad), beta


def _satterthwaite_df(y: np.ndarray, X: np.ndarray, codes: np.ndarray, var_b: float,
                      var_w: float, c: np.ndarray) -> float:
    """Satterthwaite degrees of freedom of ``c'β̂`` in the random-intercept model.

    ``ν = 2 (c'Φc)² / (g' A g)`` with ``Φ = (X'V⁻¹X)⁻¹``, ``g = ∂(c'Φc)/∂θ`` and
    ``A = 2 H⁻¹`` the asymptotic covariance of the REML estimates ``θ = (log σ²_b,
    log σ²_w)`` from the Hessian ``H`` of the REML deviance (central differences), as
    lmerTest does (Kuznetsova et al. 2017; Satterthwaite 1946).  At the REML optimum the
    result does not depend on the parametrisation.
    """
    theta = np.log([var_b, var_w])
    h = 1e-4

    def dev(t):
        return _reml_pieces(y, X, codes, *np.exp(t))[0]

    def var_c(t):
        phi = _reml_pieces(y, X, codes, *np.exp(t))[1]
        return float(c @ phi @ c)

    e = np.eye(2) * h
    H = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            H[i, j] = (dev(theta + e[i] + e[j]) - dev(theta + e[i] - e[j])
                       - dev(theta - e[i] + e[j]) + dev(theta - e[i] - e[j])) / (4 * h * h)
    g = np.array([(var_c(theta + e[i]) - var_c(theta - e[i])) / (2 * h) for i in range(2)])
    A = 2 * np.linalg.inv(H)
    return float(2 * var_c(theta) ** 2 / (g @ A @ g))


def _reml_fit(y: np.ndarray, X: np.ndarray, codes: np.ndarray) -> tuple[float, float]:
    """REML estimates ``(σ̂²_b, σ̂²_w)`` of the random-intercept model, by profiling.

    With ``λ = σ²_b / σ²_w`` and ``W = V / σ²_w`` (``W_i⁻¹ = I − 11' λ / (1 + m_i λ)``),
    ``σ²_w`` has the closed form ``σ̂²_w(λ) = r'W⁻¹r / (N − p)`` and the profiled REML
    deviance is ``(N − p) log σ̂²_w(λ) + Σ log(1 + m_i λ) + log|X'W⁻¹X|`` (+ const).  It is
    minimised over ``λ ≥ 0`` on a log grid (and at ``λ = 0``), then by bounded Brent
    search around the best grid point: deterministic, and exact on the boundary
    ``σ̂²_b = 0``, where statsmodels' ``MixedLM`` optimiser can fail (it returned a mean
    difference of 0.0065 for differences averaging −0.0009 when one subject's
    differences were all 0; the tests check that both agree where it converges).
    """
    from scipy.optimize import minimize_scalar

    N, p = X.shape

    def profiled(lam: float) -> tuple[float, float]:
        # at σ²_w = 1, σ²_b = λ: dev1 = Σ log(1 + m_i λ) + log|X'W⁻¹X| + r'W⁻¹r
        dev1, _, q, _ = _reml_pieces(y, X, codes, lam, 1.0)
        s2w = q / (N - p)                                        # σ̂²_w(λ) = r'W⁻¹r/(N−p)
        return dev1 - q + (N - p) * np.log(s2w), s2w

    grid = np.r_[0.0, np.logspace(-8, 8, 65)]
    with np.errstate(divide="ignore"):                  # r'W⁻¹r = 0: caller's ValueError
        vals = [profiled(lam)[0] for lam in grid]
    i = int(np.argmin(vals))
    lam = grid[i]
    if i > 0:
        lo = np.log(grid[i - 1]) if i > 1 else np.log(grid[1]) - 2.0
        hi = np.log(grid[min(i + 1, grid.size - 1)])
        res = minimize_scalar(lambda t: profiled(np.exp(t))[0], bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-10})
        if res.fun <= vals[i]:
            lam = float(np.exp(res.x))
    with np.errstate(divide="ignore"):
        s2w = profiled(lam)[1]
    return lam * s2w, s2w


def _fit_random_intercept(y: np.ndarray, X: np.ndarray, subject: np.ndarray,
                          contrast: np.ndarray) -> dict[str, float]:
    """REML fit of ``y = Xβ + b_subject + e`` and inference on one contrast ``c'β``.

    Returns ``estimate`` (``c'β̂``, GLS at the REML variances), ``se``
    (``sqrt(c'(X'V⁻¹X)⁻¹c)``, as lme4), ``df`` (Satterthwaite), ``var_between``,
    ``var_within`` and ``beta`` (all fixed effects).  When ``σ̂²_b`` is on the boundary
    (0) the model is ordinary least squares and ``df = N − p``, the limit Satterthwaite's
    df approaches as ``σ̂²_b → 0``.  Variances from :func:`_reml_fit`.
    """
    codes = pd.factorize(subject, sort=True)[0]
    var_b, var_w = _reml_fit(y, X, codes)
    if not var_w > 0:
        raise ValueError("no within-subject variation")
    _, phi, _, beta = _reml_pieces(y, X, codes, max(var_b, 1e-300), var_w)
    se = float(np.sqrt(contrast @ phi @ contrast))
    if var_b > 1e-10 * var_w:
        with np.errstate(all="ignore"):
            df = _satterthwaite_df(y, X, codes, var_b, var_w, contrast)
        if not np.isfinite(df) or df <= 0:
            df = float(y.size - X.shape[1])
    else:
        df = float(y.size - X.shape[1])
    return {"estimate": float(contrast @ beta), "se": se, "df": df, "var_between": var_b,
            "var_within": var_w, "beta": beta}


# ----------------------------------------------------------------------------- helpers
def _prepare(df: pd.DataFrame, ref: str, pro: str, subject: str, by: list[str],
             what: str) -> None:
    require_columns(df, [ref, pro, subject, *by], what)


def _subject_codes(sub: pd.DataFrame, subject: str) -> np.ndarray:
    return pd.factorize(sub[subject], sort=True)[0]


def _nan_row(columns: Sequence[str]) -> dict:
    return dict.fromkeys(columns, float("nan"))


# ----------------------------------------------------------------------------- nested
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
    if N < 3 or np.ptp(a) == 0 or np.ptp(d) == 0:
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
def _rater_variance(beta: np.ndarray, cov: np.ndarray) -> float:
    """Systematic rater variance θ²_R from the fixed rater effects.

    ``θ²_R = Σ_{j<l} [(β̂_j − β̂_l)² − Var(β̂_j − β̂_l)] / (k(k−1))``.

    ``beta``/``cov``: the k − 1 rater contrasts against rater 1 (β₁ = 0) and their
    covariance.  Unbiased for ``Σ (β_j − β̄)² / (k − 1)``; with one row per subject it
    equals McGraw & Wong's ``(MSC − MSE) / n``.  It may be negative, as ``MSC − MSE``.
    """
    k = beta.size + 1
    b = np.r_[0.0, beta]
    C = np.zeros((k, k))
    C[1:, 1:] = cov
    tot = 0.0
    for j in range(k):
        for l in range(j + 1, k):
            var = C[j, j] + C[l, l] - 2 * C[j, l]
            tot += (b[j] - b[l]) ** 2 - var
    return float(tot / (k * (k - 1)))


def _icc_from(vc: dict) -> dict:
    true = vc["var_subject"] + np.nan_to_num(vc["var_occasion"])
    err = vc["var_residual"] + np.nan_to_num(vc["var_subject_rater"])
    with np.errstate(divide="ignore", invalid="ignore"):
        return {"icc_agreement": true / (true + err + vc["var_rater"]),
                "icc_consistency": true / (true + err)}


def _icc_two_raters(y: np.ndarray, codes: np.ndarray | None) -> dict:
    """k = 2: the model factorises into the mean and the difference of each pair.

    With ``y_ijk = μ + β_k + s_i + o_ij + (sr)_ik + e_ijk`` and two raters, the pair mean
    ``(y₁ + y₂)/2`` has between-subject variance ``σ²_s + σ²_sr/2`` and within
    ``σ²_o + σ²_e/2``; the difference ``y₂ − y₁`` has between ``2σ²_sr`` and within
    ``2σ²_e``, and the two are independent.  Two random-intercept REML fits therefore
    give the components (exactly the full model's REML estimates whenever all are
    positive; a negative σ²_o or σ²_s is set to 0, the boundary the full model would
    take).  Without subjects (one row each) the fits are ordinary variances and the
    result is McGraw & Wong's ICC(A,1), ICC(C,1), which may be negative.
    """
    dif = y[:, 1] - y[:, 0]
    mean = (y[:, 0] + y[:, 1]) / 2
    N = dif.size
    one = np.ones((N, 1))
    if codes is None:
        vd_b, vd_w = 0.0, float(np.var(dif, ddof=1))
        vm_b, vm_w = 0.0, float(np.var(mean, ddof=1))
        delta, var_delta = float(np.mean(dif)), vd_w / N
        occ = float("nan")
    else:
        fm = _fit_random_intercept(mean, one, codes, np.ones(1))
        vm_b, vm_w = fm["var_between"], fm["var_within"]
        if np.ptp(dif) == 0:                    # the raters agree exactly: no error
            vd_b = vd_w = var_delta = 0.0
            delta = float(dif[0])
        else:
            fd = _fit_random_intercept(dif, one, codes, np.ones(1))
            vd_b, vd_w = fd["var_between"], fd["var_within"]
            delta, var_delta = fd["estimate"], fd["se"] ** 2
        occ = max(vm_w - vd_w / 4, 0.0)                         # σ²_o = V_m,w − σ²_e/2
    res = vd_w / 2                                              # σ²_e = V_d,w / 2
    sr = vd_b / 2 if codes is not None else float("nan")        # σ²_sr = V_d,b / 2
    if codes is None:
        subj = vm_w - res / 2                                   # ANOVA: (MSR − MSE)/2
    else:
        subj = max(vm_b - sr / 2, 0.0)                          # σ²_s = V_m,b − σ²_sr/2
    return {"var_subject": subj, "var_occasion": occ, "var_subject_rater": sr,
            "var_residual": res,
            "var_rater": ((delta ** 2) - var_delta) / 2}        # ((Δ̂)² − Var Δ̂) / 2


def _icc_general(y: np.ndarray, codes: np.ndarray | None) -> dict:
    """Any k: statsmodels ``MixedLM`` on the long table (slow for many occasions)."""
    import statsmodels.formula.api as smf

    N, k = y.shape
    long = pd.DataFrame({"value": y.ravel(), "rater": np.tile(np.arange(k), N),
                         "occasion": np.repeat(np.arange(N), k)})
    repeated = codes is not None
    long["subject"] = np.repeat(codes, k) if repeated else long["occasion"]
    vcf = {"occasion": "0 + C(occasion)", "rater": "0 + C(rater)"} if repeated else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                 # boundary: see the components
        res = smf.mixedlm("value ~ C(rater)", long, groups="subject", re_formula="1",
                          vc_formula=vcf).fit(reml=True)
    names = [f"C(rater)[T.{j}]" for j in range(1, k)]
    beta = np.asarray(res.fe_params[names], dtype=float)
    cov = np.asarray(res.cov_params().loc[names, names], dtype=float)
    vcomp = dict(zip(res.model.exog_vc.names, np.atleast_1d(res.vcomp))) if repeated else {}
    return {"var_subject": max(float(np.asarray(res.cov_re)[0, 0]), 0.0),
            "var_occasion": float(vcomp["occasion"]) if repeated else float("nan"),
            "var_subject_rater": float(vcomp["rater"]) if repeated else float("nan"),
            "var_residual": float(res.scale), "var_rater": _rater_variance(beta, cov)}


def icc_mixed(df: pd.DataFrame, raters: Sequence[str], subject: str | None = None,
              by=None, method: str = "auto") -> pd.DataFrame:
    """Intraclass correlations from the variance components of a linear mixed model.

    Parameters
    ----------
    df : DataFrame
        One row per occasion (e.g. a stride), with one column per rater/system; rows with
        a missing rating are dropped.
    raters : sequence of str
        Two or more columns (e.g. ``["reference", "system"]``).
    subject : str, optional
        Subject column.  When subjects contribute several occasions the model is
        ``y_ijk = μ + β_k + s_i + o_ij + (sr)_ik + e_ijk`` (subject ``s``, occasion within
        subject ``o``, subject × rater ``sr``, residual ``e``; raters fixed).  Without it,
        or with one occasion per subject, ``y_ik = μ + β_k + s_i + e_ik``.
    by : str or list of str, optional
        Grouping columns.
    method : {"auto", "general"}
        ``"auto"`` uses the exact two-fit shortcut for two raters
        (:func:`_icc_two_raters`); ``"general"`` always fits the full model with
        statsmodels ``MixedLM`` variance components (slow with thousands of occasions).

    Returns
    -------
    DataFrame
        One row per group with the ``by`` columns and ``design`` (``"single"`` or
        ``"repeated"``), ``n_subjects``, ``n_occasions``, ``k``, the REML variance
        components ``var_subject`` (σ²_s), ``var_occasion`` (σ²_o; NaN for a single
        design), ``var_subject_rater`` (σ²_sr; NaN for a single design),
        ``var_residual`` (σ²_e), the systematic rater variance ``var_rater`` (θ²_R), and

        - ``icc_agreement`` = (σ²_s + σ²_o) / (σ²_s + σ²_o + σ²_sr + σ²_e + θ²_R)
        - ``icc_consistency`` = (σ²_s + σ²_o) / (σ²_s + σ²_o + σ²_sr + σ²_e).

        No confidence intervals: use :func:`gaitval.stats.icc` for the single design.

    Notes
    -----
    The ICC is the concordance correlation coefficient estimated by variance components
    (Carrasco & Jover 2003 for one or replicated measurements; Carrasco et al. 2009 for
    repeated occasions, where the occasion-within-subject variance is part of the true
    variation).  ``θ²_R = Σ_{j<l} [(β̂_j − β̂_l)² − Var(β̂_j − β̂_l)] / (k(k − 1))``
    corrects the squared rater differences for their sampling variance, so that in the
    single design (balanced, REML = ANOVA) ``icc_agreement`` is McGraw & Wong's ICC(A,1)
    and ``icc_consistency`` their ICC(C,1) (Shrout & Fleiss ICC(2,1), ICC(3,1)).

    References
    ----------
    Carrasco, J.L.; Jover, L. Biometrics 2003, 59(4), 849–858.
    Carrasco, J.L.; King, T.S.; Chinchilli, V.M. J. Biopharm. Stat. 2009, 19(1), 90–105.
    McGraw, K.O.; Wong, S.P. Psychol. Methods 1996, 1(1), 30–46.
    """
    raters = list(raters)
    if len(raters) < 2:
        raise GaitvalError("icc_mixed: need at least two rater columns",
                           hint="pass e.g. raters=['reference', 'system']")
    if method not in ("auto", "general"):
        raise GaitvalError(f"icc_mixed: unknown method {method!r}",
                           hint="use 'auto' or 'general'")
    by = as_by(by)
    require_columns(df, [*raters, *by] + ([subject] if subject else []), "icc_mixed")
    rows = []
    for key, sub in groups(df, by):
        y = np.column_stack([numeric(sub, c, "icc_mixed") for c in raters])
        ok = np.all(np.isfinite(y), axis=1)
        if subject:
            ok &= sub[subject].notna().to_numpy()
        y, sub = y[ok], sub[ok]
        N, k = y.shape
        codes = _subject_codes(sub, subject) if subject else None
        n_sub = int(codes.max()) + 1 if codes is not None and N else N
        repeated = codes is not None and n_sub < N
        row = {**key, **_nan_row(ICC_MIXED_COLUMNS), "design":
               "repeated" if repeated else "single", "n_subjects": n_sub,
               "n_occasions": N, "k": k}
        if n_sub >= 2 and N > (n_sub if repeated else 1) and np.ptp(y) > 0:
            c = codes if repeated else None
            try:
                vc = (_icc_two_raters(y, c) if k == 2 and method == "auto"
                      else _icc_general(y, c))
            except _FIT_ERRORS:                                 # degenerate: NaN row
                vc = None
            if vc is not None:
                row.update(vc)
                row.update(_icc_from(vc))
        rows.append(row)
    out = pd.DataFrame(rows, columns=[*by, *ICC_MIXED_COLUMNS])
    return out.astype({"n_subjects": int, "n_occasions": int, "k": int})
