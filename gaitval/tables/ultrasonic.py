"""Qi et al. 2014 (Qi et al., Sensors 2014) Tables 2–8 and C1 from a gait-parameter table.

Input: the **gait parameter table** (one row per trial, stride and parameter, reference and
ultrasonic value side by side; the contract is in :mod:`gaitval.tables.ultrasonic_params`).
The tables are computed on the paper's sample size: a seeded draw of
``strides_per_subject`` strides (default 10, the paper's; ``"all"`` for every stride) per
subject and speed (:func:`gaitval.tables.ultrasonic_params.sample_strides`, config
``ultrasonic.tables``), with NS and NV normalised by that n (eq. 18, 21).
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
15434–15457 (Qi et al. 2014), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.tables.render import write_table
from gaitval.tables.ultrasonic_params import (CITATION, GAIT_PARAM_COLUMNS, PARAM_INFO,
                                              PARAMETERS, PAPER_STRIDES_PER_SUBJECT,
                                              SAMPLE_SEED, SPEEDS, SUMMARY_PARAMETERS,
                                              TABLE_PARAMETER, check_gait_params,
                                              sample_strides, subject_order)
from gaitval.tables.ultrasonic_stats import TABLE7_NOT_COMPARABLE, table7, table8, tableC1
from gaitval.tables.ultrasonic_subjects import (agreement_note, subject_table, table2,
                                                table3, table4, table5, table6)

__all__ = ["CITATION", "GAIT_PARAM_COLUMNS", "PARAM_INFO", "PARAMETERS", "SPEEDS",
           "SUMMARY_PARAMETERS", "TABLE_PARAMETER", "build_ultrasonic_tables",
           "check_gait_params", "sample_strides", "subject_order", "subject_table",
           "table2", "table3",
           "table4", "table5", "table6", "table7", "table8", "tableC1",
           "write_ultrasonic_tables"]

#: Former private name, still imported by :mod:`gaitval.report.stats_figures`.
_subject_order = subject_order


def _sample_note(sample: pd.DataFrame) -> str:
    """What the tables were computed on: the setting, the seed and the strides used."""
    k = sample.attrs.get("strides_per_subject", "all")
    n = sample[sample["parameter"] == "stride_length"].groupby(["subject", "speed"]).size()
    rng = (f"{int(n.min())}" if len(n) and n.min() == n.max() else
           f"{int(n.min())}-{int(n.max())}" if len(n) else "0")
    how = (f"a seeded random draw (seed {sample.attrs.get('sample_seed')}) of {k} strides "
           f"(and {k} symmetry windows) per subject and speed, the paper's sample size "
           "(Table C1: 10 subjects, df total 99)" if k != "all" else
           "every matched stride of each trial")
    return (f"Strides used: {how} (config ultrasonic.tables.strides_per_subject; 'all' "
            f"uses every stride): {rng} strides per subject and speed.")


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
        "S, T, V, hS, vS (the sampled strides at normal speed pooled over subjects) with "
        "mean, std and t-based 95% confidence interval of the mean. " + common,
        [TABLE7_NOT_COMPARABLE[:1].upper() + TABLE7_NOT_COMPARABLE[1:] + " (MATLAB "
         "lillietest default, alpha = 0.05; H = 1 rejects normality); column "
         "comparability says so on every row. The mean, std and CI columns are "
         "comparable.",
         "Pooling strides of different subjects mixes subject means, so normality may "
         "be rejected even when each subject's strides are normal. T (eq. 19) is a "
         "difference of sample indices at 50 Hz, so it takes few distinct values and "
         "a normality test rejects it once the sample is large."])
    caps["table8"] = (
        "Reproduces Table 8 of Qi et al. 2014: across-subject mean and std of the "
        "per-subject Ref mean, Pro mean and RMSE of each gait parameter at slow, normal "
        "and fast speed; p from paired t-tests over subjects of slow vs normal and fast "
        "vs normal (significant: p < 0.05, the paper's *). " + common,
        ["The paper's §4.2 calls the test 'two-sample', §4.4.3 'paired'; gaitval pairs "
         "by subject.", "p is empty (NaN) when every paired difference is equal, as the "
         "paper prints NaN for cadence RMSE.",
         "NS = S/n and NV = V/n (eq. 18, 21) divide by the number of strides n; the "
         "<speed>_n columns give the n used (strides per subject at that speed). The "
         "paper's values imply n = S/NS = V/NV of about 12 strides slow (0.884/0.075, "
         "0.539/0.044), 27 normal (1.169/0.043, 0.990/0.035) and 26 fast (1.410/0.054, "
         "1.402/0.053), and their std (as large as the mean at slow speed) implies n "
         "varied widely between subjects; it never states n. NS and NV therefore compare "
         "definitions of n, not accuracy (their RMSE is S's and V's RMSE divided by n)."])
    caps["tableC1"] = (
        "Reproduces Table C1 of Qi et al. 2014: one-way ANOVA of the ultrasonic "
        "estimates of S, T, V, hS, vS at normal speed in two readings of its groups: "
        "grouping = subject (between groups = subjects, as the paper's text says) and "
        "grouping = stride_index (between groups = the position of a stride in each "
        "subject's sample, as the paper's numbers imply). " + common,
        ["Finding: the published table is not consistent with subjects as groups. Its "
         "total SS equals 99 x the pooled variance, but its within-group MS (e.g. 0.0144 "
         "m^2 for S) matches the between-subject variance of the Table 2 means plus the "
         "within-subject variance, i.e. the groups were most likely the stride index "
         "(the columns of a subjects x strides matrix passed to MATLAB anova1). With "
         "subjects as groups, Table 2's subject means (1.04-1.42 m, std ~0.04 m) give F "
         ">> 1 (about 55 for S, 46 for T, 6.8 for V from the paper's own Tables 2-4). "
         "The published values are shown beside both readings; compare them with the "
         "stride_index rows."])
    return caps


def build_ultrasonic_tables(gait_params: pd.DataFrame,
                            strides_per_subject=PAPER_STRIDES_PER_SUBJECT,
                            seed: int = SAMPLE_SEED) -> dict[str, pd.DataFrame]:
    """All Qi et al. 2014 tables gaitval's statistics layer renders: ``{"table2": df, ...}``,
    on the strides :func:`~gaitval.tables.ultrasonic_params.sample_strides` draws
    (``strides_per_subject``: an int, default the paper's 10, or ``"all"``; ``seed``)."""
    gp = sample_strides(gait_params, strides_per_subject, seed)
    return {"table2": table2(gp), "table3": table3(gp),
            "table4": table4(gp), "table5": table5(gp),
            "table6": table6(gp), "table7": table7(gp),
            "table8": table8(gp), "tableC1": tableC1(gp)}


def table_settings(cfg: dict | None) -> tuple:
    """``(strides_per_subject, seed)`` from the ``ultrasonic.tables`` config section (or a
    config holding it), the defaults where absent."""
    cfg = dict(cfg or {})
    if isinstance(cfg.get("ultrasonic"), dict):
        cfg = cfg["ultrasonic"]
    t = cfg.get("tables") or {}
    return (t.get("strides_per_subject", PAPER_STRIDES_PER_SUBJECT),
            int(t.get("sample_seed", SAMPLE_SEED)))


def write_ultrasonic_tables(gait_params_df: pd.DataFrame, out_dir: str | Path,
                            cfg: dict | None = None) -> list[Path]:
    """Write ``ultrasonic_table2`` … ``ultrasonic_table8`` and ``ultrasonic_tableC1``.

    Parameters
    ----------
    gait_params_df : DataFrame
        The gait parameter table (module docstring).
    out_dir : path
        Folder for the tables (e.g. ``reports/tables``).
    cfg : dict, optional
        The ``ultrasonic`` config section (or a config holding it): its ``tables``
        keys ``strides_per_subject`` and ``sample_seed`` (:func:`table_settings`).

    Returns
    -------
    list of Path
        The CSV, Markdown and LaTeX files written (three per table).
    """
    out_dir = Path(out_dir)
    caps = _captions()
    k, seed = table_settings(cfg)
    sample_note = _sample_note(sample_strides(gait_params_df, k, seed))
    paths: list[Path] = []
    per_subject = {f"table{k}": p for k, p in TABLE_PARAMETER.items()}
    for name, table in build_ultrasonic_tables(gait_params_df, k, seed).items():
        caption, notes = caps[name]
        notes = [sample_note, *notes]
        if name in per_subject:                 # pooled vs repeated-measures limits
            notes = [*notes, agreement_note(table, per_subject[name])]
        paths += write_table(table, out_dir / f"ultrasonic_{name}", caption=caption,
                             notes=notes)
    return paths
