"""Random-intercept mixed model and MOVER limits: the machinery of the repeated-measures
agreement statistics (:mod:`gaitval.stats.repeated`).

REML of y = X β + u_subject + e by profiling the likelihood in the variance ratio (exact,
1-D), Satterthwaite degrees of freedom of the fixed effects, and the MOVER step of Zou &
Donner (2008) for limits of agreement and their confidence limits.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from gaitval.stats._checks import require_columns

_FIT_ERRORS = (np.linalg.LinAlgError, ValueError, ZeroDivisionError)


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

    The difference steps are ``h_i = ε^¼ · max(1, |θ_i|)`` (Press et al., Numerical
    Recipes §5.7: the step that balances a central second difference's truncation error
    against the rounding error of a deviance whose size grows with ``|θ|``).  A fixed
    ``h = 1e-4`` was below that at the log-variances of gait data (|θ| ≈ 10–16): on the
    tiny study's four symmetry windows (two subjects) a change of the inputs by 1e-13
    moved ν by 3e-4 (relative), and the balanced design's exact ν = n − 1 came out within
    1e-4 only; with these steps ν is stable to 1e-6 there (``tests/test_stats_repeated``).
    """
    theta = np.log([var_b, var_w])
    h = np.finfo(float).eps ** 0.25 * np.maximum(1.0, np.abs(theta))

    def dev(t):
        return _reml_pieces(y, X, codes, *np.exp(t))[0]

    def var_c(t):
        phi = _reml_pieces(y, X, codes, *np.exp(t))[1]
        return float(c @ phi @ c)

    e = np.diag(h)
    H = np.empty((2, 2))
    for i in range(2):
        for j in range(2):
            H[i, j] = (dev(theta + e[i] + e[j]) - dev(theta + e[i] - e[j])
                       - dev(theta - e[i] + e[j]) + dev(theta - e[i] - e[j])
                       ) / (4 * h[i] * h[j])
    g = np.array([(var_c(theta + e[i]) - var_c(theta - e[i])) / (2 * h[i])
                  for i in range(2)])
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
