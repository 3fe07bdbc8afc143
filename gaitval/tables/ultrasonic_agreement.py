"""Agreement of the ultrasonic system with the camera reference: pooled, repeated measures.

Issue 16.  The paper reports per-subject means, SDs and RMSEs; a validation reviewer also
asks for the bias and limits of agreement, and with many strides per subject those must
respect that strides of one subject share its bias.  :func:`agreement_row` gathers, for
one parameter at one speed, the pooled statistics (every stride an independent pair:
:func:`gaitval.stats.agreement`) beside the repeated-measures ones (subjects as a random
effect: :func:`gaitval.stats.loa_nested`, :func:`gaitval.stats.icc_mixed`,
:func:`gaitval.stats.proportional_bias`); :func:`agreement_table` stacks them for every
parameter and speed.  Tables 2–6 (:mod:`gaitval.tables.ultrasonic_subjects`) and the
Bland–Altman figures (:mod:`gaitval.report.stats_figures`) show them.

The true stride length, duration and velocity vary from stride to stride, so the limits
are those of the "true value varies" (nested) design of Bland & Altman (2007) and Zou
(2013).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.stats import agreement, icc_mixed, loa_nested, proportional_bias
from gaitval.tables.ultrasonic_params import (PARAM_INFO, SPEEDS, SUMMARY_PARAMETERS,
                                              check_gait_params)

#: pooled columns: table column -> column of :func:`gaitval.stats.agreement`
POOLED = {"bias": "bias", "bias_ci_low": "bias_ci_low", "bias_ci_high": "bias_ci_high",
          "sd": "bias_sd", "loa_low": "loa_low", "loa_high": "loa_high",
          "loa_low_ci_low": "loa_low_ci_low", "loa_low_ci_high": "loa_low_ci_high",
          "loa_high_ci_low": "loa_high_ci_low", "loa_high_ci_high": "loa_high_ci_high",
          "icc_a1": "icc_a1", "icc_c1": "icc_c1"}
#: repeated-measures columns: table column -> column of :func:`gaitval.stats.loa_nested`
REPEATED = {"bias_rm": "bias", "bias_rm_ci_low": "bias_ci_low",
            "bias_rm_ci_high": "bias_ci_high", "bias_rm_df": "bias_df",
            "sd_rm": "sd_total", "var_between_rm": "var_between",
            "var_within_rm": "var_within", "loa_low_rm": "loa_low",
            "loa_high_rm": "loa_high", "loa_low_rm_ci_low": "loa_low_ci_low",
            "loa_low_rm_ci_high": "loa_low_ci_high",
            "loa_high_rm_ci_low": "loa_high_ci_low",
            "loa_high_rm_ci_high": "loa_high_ci_high"}
#: ICC from variance components: table column -> column of :func:`gaitval.stats.icc_mixed`
ICC_RM = {"icc_agreement_rm": "icc_agreement", "icc_consistency_rm": "icc_consistency",
          "var_subject_rm": "var_subject", "var_stride_rm": "var_occasion",
          "var_subject_system_rm": "var_subject_rater", "var_residual_rm": "var_residual",
          "var_system_rm": "var_rater"}
#: proportional bias: table column -> column of :func:`gaitval.stats.proportional_bias`
PROP_BIAS = {"prop_bias_slope": "slope", "prop_bias_slope_ci_low": "slope_ci_low",
             "prop_bias_slope_ci_high": "slope_ci_high", "prop_bias_p": "p"}


def agreement_table(gait_params: pd.DataFrame, parameters=SUMMARY_PARAMETERS,
                    speeds=SPEEDS, alpha: float = 0.05) -> pd.DataFrame:
    """Pooled and repeated-measures agreement of every parameter at every speed.

    Parameters
    ----------
    gait_params : DataFrame
        The gait parameter table (:mod:`gaitval.tables.ultrasonic_params`).
    parameters : sequence of str
        Parameters to report (default S, T, V, hS, vS: those of Tables 2–6); absent ones
        are skipped.
    speeds : sequence of str
        Speeds to report; absent ones are skipped.
    alpha : float
        Every interval is a ``1 − alpha`` confidence interval; limits are 95% limits.

    Returns
    -------
    DataFrame
        One row per (parameter, speed): ``parameter``, ``symbol``, ``unit``, ``speed``,
        ``n_strides``, ``n_subjects``; pooled statistics (no suffix, :data:`POOLED`):
        bias with CI, SD of the differences, limits of agreement with CIs (Bland & Altman
        1999), ICC(A,1), ICC(C,1); repeated-measures statistics (``_rm``,
        :data:`REPEATED`): REML bias with its Satterthwaite CI and df, SD of a single
        difference and its between/within-subject variances, limits with MOVER CIs;
        ``loa_width_ratio`` (repeated-measures over pooled limit width) and
        ``loa_ci_ratio`` (the same for the CI of the upper limit); the mixed-model ICCs
        and their variance components (:data:`ICC_RM`: subject, stride within subject,
        subject × system, residual, systematic system variance); proportional bias
        (:data:`PROP_BIAS`, subject random intercept).  Values in ``unit`` (variances in
        ``unit``²); differences are system − reference.
    """
    df = check_gait_params(gait_params)
    rows = []
    for param in parameters:
        for speed in speeds:
            sub = df[(df["parameter"] == param) & (df["speed"] == speed)]
            if sub.empty:
                continue
            rows.append(agreement_row(sub, param, speed, alpha))
    return pd.DataFrame(rows)


def agreement_row(sub: pd.DataFrame, param: str, speed: str, alpha: float = 0.05) -> dict:
    """The :func:`agreement_table` row of one parameter's strides at one speed."""
    sym, _, unit = PARAM_INFO[param]
    ref, pro = "reference", "system"
    pooled = agreement(sub, ref, pro, alpha=alpha).iloc[0]
    rm = loa_nested(sub, ref, pro, "subject", alpha=alpha).iloc[0]
    ic = icc_mixed(sub, [ref, pro], subject="subject").iloc[0]
    pb = proportional_bias(sub, ref, pro, subject="subject", alpha=alpha).iloc[0]
    row = {"parameter": param, "symbol": sym, "unit": unit, "speed": speed,
           "n_strides": int(pooled["n"]), "n_subjects": int(rm["n_subjects"])}
    row.update({c: float(pooled[s]) for c, s in POOLED.items()})
    row.update({c: float(rm[s]) for c, s in REPEATED.items()})
    row["loa_width_ratio"] = _ratio(row["loa_high_rm"] - row["loa_low_rm"],
                                    row["loa_high"] - row["loa_low"])
    row["loa_ci_ratio"] = _ratio(row["loa_high_rm_ci_high"] - row["loa_high_rm_ci_low"],
                                 row["loa_high_ci_high"] - row["loa_high_ci_low"])
    row.update({c: float(ic[s]) for c, s in ICC_RM.items()})
    row.update({c: float(pb[s]) for c, s in PROP_BIAS.items()})
    return row


def _ratio(a: float, b: float) -> float:
    """``a / b``, NaN when ``b`` is 0 or either is undefined (e.g. all differences 0)."""
    return float(a / b) if np.isfinite(a) and np.isfinite(b) and b != 0 else float("nan")
