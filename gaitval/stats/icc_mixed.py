"""Intraclass correlations from the variance components of a mixed model (repeated
measures): subject, occasion within subject, subject × rater and residual, plus the
systematic rater variance (Carrasco & Jover 2003; Carrasco et al. 2009); with one row per
subject they reduce to McGraw & Wong's ICC(A,1) and ICC(C,1).  See
:mod:`gaitval.stats.repeated` for the agreement statistics they sit beside.
"""
from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.stats._checks import as_by, groups, numeric, require_columns
from gaitval.stats.repeated import ICC_MIXED_COLUMNS

from gaitval.stats._mixed import _FIT_ERRORS, _fit_random_intercept, _nan_row, _subject_codes


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
