"""Seed 003 (Qi et al., Sensors 2014) Tables 2–8 and C1 from a gait-parameter table.

Input: the **gait parameter table** (one row per trial, stride and parameter, reference and
ultrasonic value side by side; the contract is in :mod:`gaitval.tables.ultrasonic_params`).
Every builder returns a tidy DataFrame (one row per cell group, units in column names or
in a ``unit`` column) with the paper's published values in ``*_published`` columns beside
the reproduced ones; :func:`write_ultrasonic_tables` renders them with
:func:`gaitval.tables.render.write_table`.  Where they live: the input contract in
:mod:`gaitval.tables.ultrasonic_params`, Tables 2–6 in
:mod:`gaitval.tables.ultrasonic_subjects`, Tables 7, 8, C1 in
:mod:`gaitval.tables.ultrasonic_stats`; this module gathers and writes them.  Table 1
(pendulum) is :mod:`gaitval.tables.ultrasonic_table1`.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal gait
parameters using a low-cost ultrasonic motion analysis system. Sensors 2014, 14(8),
15434–15457 (seed 003), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.tables.render import write_table
from gaitval.tables.ultrasonic_params import (CITATION, GAIT_PARAM_COLUMNS, PARAM_INFO,
                                              PARAMETERS, SPEEDS, SUMMARY_PARAMETERS,
                                              TABLE_PARAMETER, check_gait_params,
                                              subject_order)
from gaitval.tables.ultrasonic_stats import table7, table8, tableC1
from gaitval.tables.ultrasonic_subjects import (agreement_note, subject_table, table2,
                                                table3, table4, table5, table6)

__all__ = ["CITATION", "GAIT_PARAM_COLUMNS", "PARAM_INFO", "PARAMETERS", "SPEEDS",
           "SUMMARY_PARAMETERS", "TABLE_PARAMETER", "build_ultrasonic_tables",
           "check_gait_params", "subject_order", "subject_table", "table2", "table3",
           "table4", "table5", "table6", "table7", "table8", "tableC1",
           "write_ultrasonic_tables"]

#: Former private name, still imported by :mod:`gaitval.report.stats_figures`.
_subject_order = subject_order


def _captions() -> dict[str, tuple[str, list[str]]]:
    common = ("Reproduced values from gaitval's gait parameter table; *_published columns "
              f"transcribed from {CITATION}.")
    subj_note = ("Published per-subject values are matched to subjects by position "
                 "(paper subject k = k-th subject in natural order); the subjects are "
                 "not the paper's, so compare the average and peak rows.")
    caps = {}
    names = {2: "stride length (m)", 3: "stride duration (s)", 4: "stride velocity (m/s)",
             5: "horizontal stride symmetry hS", 6: "vertical stride symmetry vS"}
    for k, name in names.items():
        caps[f"table{k}"] = (
            f"Reproduces Table {k} of Qi et al. 2014: mean and standard deviation of the "
            f"reference (Ref) and ultrasonic (Pro) estimates and RMSE of {name} per "
            "subject at normal walking speed, with the average and peak over subjects. "
            + common,
            [subj_note, "std is the sample standard deviation (ddof = 1); RMSE is over "
             "the strides of each subject; diff_mean (Pro - Ref) is an extra column."])
    caps["table7"] = (
        "Reproduces Table 7 of Qi et al. 2014: normality of the ultrasonic estimates of "
        "S, T, V, hS, vS (all strides at normal speed pooled over subjects) with mean, "
        "std and t-based 95% confidence interval of the mean. " + common,
        ["Deviation: the paper reports H = 0 and p = 1.000 for a null hypothesis of "
         "'mean is zero', which is not a normality test; gaitval applies the Lilliefors "
         "test (MATLAB lillietest default, alpha = 0.05; H = 1 rejects normality), so "
         "its p and H are not comparable with the published ones.",
         "Pooling strides of different subjects mixes subject means, so normality may "
         "be rejected even when each subject's strides are normal."])
    caps["table8"] = (
        "Reproduces Table 8 of Qi et al. 2014: across-subject mean and std of the "
        "per-subject Ref mean, Pro mean and RMSE of each gait parameter at slow, normal "
        "and fast speed; p from paired t-tests over subjects of slow vs normal and fast "
        "vs normal (significant: p < 0.05, the paper's *). " + common,
        ["The paper's §4.2 calls the test 'two-sample', §4.4.3 'paired'; gaitval pairs "
         "by subject.", "p is empty (NaN) when every paired difference is equal, as the "
         "paper prints NaN for cadence RMSE.",
         "NS = S/n and NV = V/n (eq. 18, 21) divide by the number of strides n. gaitval's "
         "n is the number of matched strides of each 5-min trial (about 180 slow, 250 "
         "normal, 300 fast at the paper's stride durations 1.645/1.180/1.006 s), so its NS "
         "is about S/250 = 0.005 m at normal speed. The paper's values imply n = S/NS = "
         "V/NV of about 12 strides slow (0.884/0.075, 0.539/0.044), 27 normal "
         "(1.169/0.043, 0.990/0.035) and 26 fast (1.410/0.054, 1.402/0.053), and their "
         "std (as large as the mean at slow speed) implies n varied widely between "
         "subjects: the paper normalised by the strides of an analysed segment, not of the "
         "whole 5 min (its Table C1 uses 10 strides per subject). With n of that size "
         "gaitval's NS would be 0.04-0.07 m; the NS and NV rows compare definitions of n, "
         "not accuracy (their RMSE, about 0.001, is S's and V's RMSE divided by n)."])
    caps["tableC1"] = (
        "Reproduces Table C1 of Qi et al. 2014: one-way ANOVA of the ultrasonic "
        "estimates of S, T, V, hS, vS across subjects at normal speed (between groups = "
        "subjects). " + common,
        ["Finding: the published table is not consistent with subjects as groups. Its "
         "total SS equals 99 x the pooled variance, but its within-group MS (e.g. 0.0144 "
         "m^2 for S) matches the between-subject variance of the Table 2 means plus the "
         "within-subject variance, i.e. the groups were most likely the stride index "
         "(the columns of a subjects x strides matrix passed to MATLAB anova1). With "
         "subjects as groups, Table 2's subject means (1.04-1.42 m, std ~0.04 m) give F "
         ">> 1, so gaitval's F and p differ from the published ones by design.",
         "The paper used 10 strides per subject (df total 99); gaitval uses all strides "
         "unless max_strides_per_subject is set."])
    return caps


def build_ultrasonic_tables(gait_params: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """All seed 003 tables gaitval's statistics layer renders: ``{"table2": df, ...}``."""
    return {"table2": table2(gait_params), "table3": table3(gait_params),
            "table4": table4(gait_params), "table5": table5(gait_params),
            "table6": table6(gait_params), "table7": table7(gait_params),
            "table8": table8(gait_params), "tableC1": tableC1(gait_params)}


def write_ultrasonic_tables(gait_params_df: pd.DataFrame, out_dir: str | Path) -> list[Path]:
    """Write ``ultrasonic_table2`` … ``ultrasonic_table8`` and ``ultrasonic_tableC1``.

    Parameters
    ----------
    gait_params_df : DataFrame
        The gait parameter table (module docstring).
    out_dir : path
        Folder for the tables (e.g. ``reports/tables``).

    Returns
    -------
    list of Path
        The CSV, Markdown and LaTeX files written (three per table).
    """
    out_dir = Path(out_dir)
    caps = _captions()
    paths: list[Path] = []
    per_subject = {f"table{k}": p for k, p in TABLE_PARAMETER.items()}
    for name, table in build_ultrasonic_tables(gait_params_df).items():
        caption, notes = caps[name]
        if name in per_subject:                 # pooled vs repeated-measures limits
            notes = [*notes, agreement_note(table, per_subject[name])]
        paths += write_table(table, out_dir / f"ultrasonic_{name}", caption=caption,
                             notes=notes, digits=5 if name == "tableC1" else 3)
    return paths
