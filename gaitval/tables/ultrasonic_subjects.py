"""Qi et al. 2014 Tables 2–6: per-subject reference and ultrasonic means, stds and RMSE.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal gait
parameters using a low-cost ultrasonic motion analysis system. Sensors 2014, 14(8),
15434–15457 (Qi et al. 2014), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from scipy import stats as sps

from gaitval.stats import error_summary
from gaitval.tables import _published_qi2014 as pub
from gaitval.tables.numbers import format_value
from gaitval.tables.ultrasonic_agreement import agreement_row
from gaitval.tables.ultrasonic_params import (PARAM_INFO, check_gait_params, select,
                                              subject_order)

#: agreement columns after the published ones: table column (before the unit
#: suffix) -> column of :func:`gaitval.tables.ultrasonic_agreement.agreement_row` shown on
#: the ``average`` row; ``loa_low``/``loa_high`` also on every subject row (its strides)
AGREEMENT_COLUMNS = {"loa_low": "loa_low", "loa_high": "loa_high",
                     "loa_low_ci_low": "loa_low_ci_low",
                     "loa_high_ci_high": "loa_high_ci_high",
                     "bias_rm": "bias_rm", "loa_low_rm": "loa_low_rm",
                     "loa_high_rm": "loa_high_rm", "loa_low_rm_ci_low": "loa_low_rm_ci_low",
                     "loa_high_rm_ci_high": "loa_high_rm_ci_high"}
#: average-row columns without a unit suffix (SDs carry it: see :func:`subject_table`)
AGREEMENT_RATIOS = ("loa_width_ratio", "loa_ci_ratio", "icc_agreement_rm",
                    "icc_consistency_rm")


def subject_table(gait_params: pd.DataFrame, parameter: str,
                  speed: str = "normal") -> pd.DataFrame:
    """Per-subject Ref/Pro mean and std and RMSE of one parameter (Tables 2–6 layout).

    Parameters
    ----------
    gait_params : DataFrame
        The gait parameter table (module docstring).
    parameter : str
        One of :data:`PARAMETERS`.
    speed : str
        Walking speed the table is built for (the paper: ``"normal"``).

    Returns
    -------
    DataFrame
        One row per subject (natural order), then an ``average`` row (mean of the
        per-subject values, as the paper's "Average" column) and a ``peak`` row (their
        maximum, the paper's "Peak").  Columns ``subject``, ``paper_subject`` (1..10:
        the paper's subject matched by position), ``n_strides`` (``average`` row: all
        strides), ``ref_mean<u>``, ``ref_std<u>``, ``pro_mean<u>``, ``pro_std<u>``,
        ``diff_mean<u>`` (mean of system − reference), ``rmse<u>``, and the published
        ``ref_mean<u>_published`` … ``rmse<u>_published`` where the paper gives them
        (``<u>`` is the unit suffix, e.g. ``_m``; none for symmetries).

        Then agreement columns (not in the paper; issue 16), see
        :func:`gaitval.tables.ultrasonic_agreement.agreement_row`:

        - ``loa_low<u>``, ``loa_high<u>``: Bland–Altman limits (bias ∓ 1.96 SD of the
          differences) of the row's strides — the subject's own on a subject row, all
          strides pooled as independent pairs on the ``average`` row (empty on ``peak``);
        - ``average`` row only: the pooled limits' outer 95% CI bounds
          ``loa_low_ci_low<u>``, ``loa_high_ci_high<u>``; the repeated-measures bias and
          limits (subjects as a random effect) ``bias_rm<u>``, ``loa_low_rm<u>``,
          ``loa_high_rm<u>`` with outer MOVER 95% bounds ``loa_low_rm_ci_low<u>``,
          ``loa_high_rm_ci_high<u>``; the between- and within-subject SDs of the
          differences ``sd_between_rm<u>``, ``sd_within_rm<u>``; ``loa_width_ratio``
          (repeated-measures over pooled limit width), ``loa_ci_ratio`` (the same for the
          CI of the upper limit), ``icc_agreement_rm``, ``icc_consistency_rm`` (ICC from
          variance components).
    """
    df = check_gait_params(gait_params)
    sub = select(df, parameter, speed, f"table for {parameter}")
    u = PARAM_INFO[parameter][1]
    es = error_summary(sub, "reference", "system", by="subject").set_index("subject")
    order = subject_order(es.index)
    stats = ["ref_mean", "ref_std", "pro_mean", "pro_std", "diff_mean", "rmse"]
    body = pd.DataFrame({"subject": order,
                         "paper_subject": [str(i + 1) if i < 10 else "" for i in
                                           range(len(order))],
                         "n_strides": es.loc[order, "n"].to_numpy(dtype=float)})
    for s in stats:
        body[s + u] = es.loc[order, s].to_numpy(dtype=float)
    avg = {"subject": "average", "paper_subject": "average",
           "n_strides": float(body["n_strides"].sum())}
    peak = {"subject": "peak", "paper_subject": "peak",
            "n_strides": float(body["n_strides"].max())}
    for s in stats:
        avg[s + u] = float(body[s + u].mean())
        peak[s + u] = float(body[s + u].max())
    out = pd.concat([body, pd.DataFrame([avg, peak])], ignore_index=True)
    published = pub.TABLES_2_6.get(parameter) if speed == "normal" else None
    for s in ["ref_mean", "ref_std", "pro_mean", "pro_std", "rmse"]:
        vals = dict(zip(pub.SUBJECT_KEYS, published[s])) if published else {}
        out[s + u + "_published"] = [vals.get(k, np.nan) for k in out["paper_subject"]]
    out["n_strides"] = out["n_strides"].astype(int)
    return _with_agreement(out, sub, es, order, parameter, speed, u)


def _with_agreement(out: pd.DataFrame, sub: pd.DataFrame, es: pd.DataFrame, order: list,
                    parameter: str, speed: str, u: str) -> pd.DataFrame:
    """Append the agreement columns of :func:`subject_table`."""
    nan = np.full(len(out), np.nan)
    n_sub = len(order)
    row = agreement_row(sub, parameter, speed)
    z = sps.norm.ppf(0.975)                               # limits: bias ∓ 1.96 SD
    cols = {}
    for name, src in AGREEMENT_COLUMNS.items():
        col = nan.copy()
        col[n_sub] = row[src]                             # the average row
        cols[name + u] = col
    bias = es.loc[order, "diff_mean"].to_numpy(dtype=float)
    sd = es.loc[order, "diff_std"].to_numpy(dtype=float)
    cols["loa_low" + u][:n_sub] = bias - z * sd           # each subject's own limits
    cols["loa_high" + u][:n_sub] = bias + z * sd
    for name, var in (("sd_between_rm", "var_between_rm"),
                      ("sd_within_rm", "var_within_rm")):
        col = nan.copy()
        col[n_sub] = np.sqrt(row[var])
        cols[name + u] = col
    for name in AGREEMENT_RATIOS:
        col = nan.copy()
        col[n_sub] = row[name]
        cols[name] = col
    return pd.concat([out, pd.DataFrame(cols, index=out.index)], axis=1)


def agreement_note(table: pd.DataFrame, parameter: str) -> str:
    """Table note on the agreement columns of :func:`subject_table`: which is which, and
    how much wider the repeated-measures limits are than the pooled ones."""
    u = PARAM_INFO[parameter][1]
    avg = table.set_index("subject").loc["average"]
    text = ("Agreement columns (not in the paper): loa_low/loa_high are Bland-Altman "
            "limits (bias -/+ 1.96 SD of Pro - Ref) of the row's strides - a subject's own "
            "on its row, all strides pooled as if independent on the average row, with "
            "the pooled limits' outer 95% CI bounds loa_low_ci_low/loa_high_ci_high "
            "(Bland & Altman 1999). *_rm (average row only) treat the strides as repeated "
            "measures of each subject (Bland & Altman 2007; Zou 2013): bias_rm from a "
            "random-intercept model (REML), limits bias_rm -/+ 1.96 sqrt(sd_between_rm^2 "
            "+ sd_within_rm^2) with outer MOVER 95% bounds; icc_*_rm from the variance "
            "components subject, stride, subject x system and residual.")
    ratio, ci = avg["loa_width_ratio"], avg["loa_ci_ratio"]
    if not np.isfinite(ratio):
        return text + (" The repeated-measures limits need two subjects and a subject "
                       "with two strides; they are empty here.")
    n_sub = len(table) - 2                                # rows: subjects, average, peak
    unit = PARAM_INFO[parameter][2]
    unit = "" if unit == "-" else f" {unit}"

    def f(col):                         # as the table's cells print it (one format)
        return format_value(avg[col + u], col + u, "ultrasonic_table2")
    return text + (f" Here the repeated-measures limits [{f('loa_low_rm')}, "
                   f"{f('loa_high_rm')}]{unit} are {ratio:.2f} times as wide as the "
                   f"pooled [{f('loa_low')}, {f('loa_high')}]{unit} and the "
                   f"95% CI of the upper limit {ci:.1f} times as long ({n_sub} subjects, "
                   f"{int(avg['n_strides'])} strides): the subject, not the stride, is the "
                   "unit of replication.")


def table2(gait_params, speed="normal"):
    """Qi et al. 2014 Table 2: stride length per subject (m). See :func:`subject_table`."""
    return subject_table(gait_params, "stride_length", speed)


def table3(gait_params, speed="normal"):
    """Qi et al. 2014 Table 3: stride duration per subject (s). See :func:`subject_table`."""
    return subject_table(gait_params, "stride_duration", speed)


def table4(gait_params, speed="normal"):
    """Qi et al. 2014 Table 4: stride velocity per subject (m/s). See :func:`subject_table`."""
    return subject_table(gait_params, "stride_velocity", speed)


def table5(gait_params, speed="normal"):
    """Qi et al. 2014 Table 5: horizontal stride symmetry hS per subject. See :func:`subject_table`."""
    return subject_table(gait_params, "h_symmetry", speed)


def table6(gait_params, speed="normal"):
    """Qi et al. 2014 Table 6: vertical stride symmetry vS per subject. See :func:`subject_table`."""
    return subject_table(gait_params, "v_symmetry", speed)
