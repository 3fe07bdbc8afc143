"""Seed 003 (Qi et al., Sensors 2014) Tables 2–8 and C1 from a gait-parameter table.

Input contract — the **gait parameter table** written by the ultrasonic tracking step:
one row per (trial, stride, parameter) with columns

``study, trial, subject, speed (slow|normal|fast), stride (int), parameter, unit,
reference, system``

where ``parameter`` is one of :data:`PARAMETERS` and ``reference`` / ``system`` are the
camera-reference and ultrasonic estimates of that stride (SI units).

Every builder returns a tidy DataFrame (one row per cell group, units in column names or
in a ``unit`` column) with the paper's published values in ``*_published`` columns beside
the reproduced ones; :func:`write_ultrasonic_tables` renders them with
:func:`gaitval.tables.render.write_table`.  Table 1 (pendulum) is built elsewhere.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal gait
parameters using a low-cost ultrasonic motion analysis system. Sensors 2014, 14(8),
15434–15457 (seed 003), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.stats import anova_oneway, error_summary, normality, paired_ttest
from gaitval.stats.summary import summarize_errors
from gaitval.tables import _published_qi2014 as pub
from gaitval.tables.render import write_table

GAIT_PARAM_COLUMNS = ("study", "trial", "subject", "speed", "stride", "parameter", "unit",
                      "reference", "system")
PARAMETERS = ("stride_length", "stride_length_norm", "stride_duration", "stride_velocity",
              "stride_velocity_norm", "cadence", "h_symmetry", "v_symmetry")
SPEEDS = ("slow", "normal", "fast")
#: parameter -> (symbol in the paper, unit suffix for column names, unit text)
PARAM_INFO = {
    "stride_length": ("S", "_m", "m"),
    "stride_length_norm": ("NS", "_m", "m"),
    "stride_duration": ("T", "_s", "s"),
    "stride_velocity": ("V", "_mps", "m/s"),
    "stride_velocity_norm": ("NV", "_mps", "m/s"),
    "cadence": ("C", "_per_s", "stride/s"),
    "h_symmetry": ("hS", "", "-"),
    "v_symmetry": ("vS", "", "-"),
}
#: which parameter each of the paper's per-subject tables covers
TABLE_PARAMETER = {2: "stride_length", 3: "stride_duration", 4: "stride_velocity",
                   5: "h_symmetry", 6: "v_symmetry"}
SUMMARY_PARAMETERS = tuple(TABLE_PARAMETER.values())
CITATION = ("Qi et al., Sensors 2014, 14(8):15434-15457")


# ----------------------------------------------------------------------------- input
def check_gait_params(df: pd.DataFrame) -> pd.DataFrame:
    """Validate the gait parameter table and return it with numeric value columns.

    Raises
    ------
    GaitvalError
        Missing columns, unknown parameters or speeds, non-numeric values.
    """
    if not isinstance(df, pd.DataFrame):
        raise GaitvalError("gait parameter table: expected a DataFrame, got "
                           f"{type(df).__name__}")
    missing = [c for c in GAIT_PARAM_COLUMNS if c not in df.columns]
    if missing:
        raise GaitvalError(f"gait parameter table lacks column(s) {missing}",
                           hint=f"expected columns {list(GAIT_PARAM_COLUMNS)}")
    bad = sorted(set(df["parameter"].astype(str)) - set(PARAMETERS))
    if bad:
        raise GaitvalError(f"gait parameter table: unknown parameter(s) {bad}",
                           hint=f"use {list(PARAMETERS)}")
    speeds = df["speed"].astype(str)
    bad = sorted(set(speeds[df["speed"].notna()]) - set(SPEEDS))
    if bad:
        raise GaitvalError(f"gait parameter table: unknown speed(s) {bad}",
                           hint=f"use {list(SPEEDS)}")
    out = df.copy()
    for c in ("reference", "system"):
        try:
            out[c] = pd.to_numeric(out[c], errors="raise").astype(float)
        except (TypeError, ValueError):
            raise GaitvalError(f"gait parameter table: column {c!r} is not numeric",
                               hint="write values in SI units as numbers") from None
    out["subject"] = out["subject"].astype(str)
    out["speed"] = out["speed"].astype(str)
    out["parameter"] = out["parameter"].astype(str)
    return out


def _select(df: pd.DataFrame, parameter: str, speed: str | None, what: str) -> pd.DataFrame:
    sub = df[df["parameter"] == parameter]
    if speed is not None:
        sub = sub[sub["speed"] == speed]
    if sub.empty:
        raise GaitvalError(f"{what}: no rows for parameter {parameter!r}"
                           + (f" at speed {speed!r}" if speed else ""),
                           hint="check the gait parameter table of the ultrasonic trials")
    return sub


def _subject_order(subjects) -> list[str]:
    """Subjects in natural order ("S2" before "S10")."""
    def key(s):
        digits = "".join(ch for ch in s if ch.isdigit())
        return (int(digits) if digits else 10 ** 9, s)
    return sorted(set(subjects), key=key)


# ----------------------------------------------------------------------------- Tables 2–6
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
    """
    df = check_gait_params(gait_params)
    sub = _select(df, parameter, speed, f"table for {parameter}")
    u = PARAM_INFO[parameter][1]
    es = error_summary(sub, "reference", "system", by="subject").set_index("subject")
    order = _subject_order(es.index)
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
    return out


def table2(gait_params, speed="normal"):
    """Seed 003 Table 2: stride length per subject (m). See :func:`subject_table`."""
    return subject_table(gait_params, "stride_length", speed)


def table3(gait_params, speed="normal"):
    """Seed 003 Table 3: stride duration per subject (s). See :func:`subject_table`."""
    return subject_table(gait_params, "stride_duration", speed)


def table4(gait_params, speed="normal"):
    """Seed 003 Table 4: stride velocity per subject (m/s). See :func:`subject_table`."""
    return subject_table(gait_params, "stride_velocity", speed)


def table5(gait_params, speed="normal"):
    """Seed 003 Table 5: horizontal stride symmetry hS per subject. See :func:`subject_table`."""
    return subject_table(gait_params, "h_symmetry", speed)


def table6(gait_params, speed="normal"):
    """Seed 003 Table 6: vertical stride symmetry vS per subject. See :func:`subject_table`."""
    return subject_table(gait_params, "v_symmetry", speed)


# ----------------------------------------------------------------------------- Table 7
def table7(gait_params: pd.DataFrame, speed: str = "normal", column: str = "system",
           method: str = "lilliefors") -> pd.DataFrame:
    """Normality of each gait parameter (seed 003 Table 7), done as a normality test.

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
        ``ci95_high_published``.

    Notes
    -----
    The paper's Table 7 reports H = 0 and p = 1.000 for a null hypothesis of "mean is
    zero" (§4.4.2); that is not a normality test and its p-values cannot be reproduced.
    gaitval tests normality itself (Lilliefors by default, MATLAB ``lillietest``'s test).
    """
    if column not in ("system", "reference"):
        raise GaitvalError(f"table7: column must be 'system' or 'reference', not {column!r}")
    df = check_gait_params(gait_params)
    parts = [_select(df, p, None if speed == "all" else speed, "table7")
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
    return nt


# ----------------------------------------------------------------------------- Table 8
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
        ``quantity``, ``slow_mean``, ``slow_std``, ``slow_p``, ``slow_significant``,
        ``normal_mean``, ``normal_std``, ``fast_mean``, ``fast_std``, ``fast_p``,
        ``fast_significant``, ``n_subjects``, and ``*_published`` beside each numeric
        column the paper prints.  ``p`` is NaN when all paired differences are equal
        (the paper prints "NaN" for cadence RMSE).

    Notes
    -----
    The paper's §4.2 says "two-sample t-tests" while §4.4.3 and the caption say paired
    t-tests; gaitval pairs by subject (every subject walked at every speed).
    """
    df = check_gait_params(gait_params)
    present = [p for p in PARAMETERS if p in set(df["parameter"])]
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
    order = ["parameter", "symbol", "unit", "quantity", "slow_mean", "slow_std", "slow_p",
             "slow_significant", "normal_mean", "normal_std", "fast_mean", "fast_std",
             "fast_p", "fast_significant", "n_subjects"]
    out = pd.DataFrame(rows)
    return out[order + [c for c in out.columns if c.endswith("_published")]]


# ----------------------------------------------------------------------------- Table C1
def tableC1(gait_params: pd.DataFrame, speed: str = "normal", column: str = "system",
            max_strides_per_subject: int | None = None) -> pd.DataFrame:
    """One-way ANOVA across subjects for S, T, V, hS, vS (seed 003 Table C1).

    Parameters
    ----------
    gait_params : DataFrame
        The gait parameter table.
    speed : str
        Speed analysed (the paper's tables are at normal speed).
    column : {"system", "reference"}
        Which system's estimates are analysed.
    max_strides_per_subject : int, optional
        Use only the first ``m`` strides (by ``stride`` number) of each subject; the
        paper's Table C1 has 100 observations (10 subjects × 10 strides).

    Returns
    -------
    DataFrame
        One row per (parameter, source) with ``source`` in ``between``, ``within``,
        ``total``: ``parameter``, ``symbol``, ``source``, ``SS``, ``df``, ``MS``, ``F``,
        ``p`` (from :func:`gaitval.stats.anova_oneway` with ``group="subject"``), and
        ``SS_published``, ``df_published``, ``MS_published``, ``F_published``,
        ``p_published``.
    """
    if column not in ("system", "reference"):
        raise GaitvalError(f"tableC1: column must be 'system' or 'reference', not {column!r}")
    df = check_gait_params(gait_params)
    frames = []
    for param in SUMMARY_PARAMETERS:
        sub = _select(df, param, speed, "tableC1")
        if max_strides_per_subject is not None:
            sub = (sub.sort_values(["subject", "trial", "stride"])
                   .groupby("subject", sort=True).head(max_strides_per_subject))
        try:
            a = anova_oneway(sub, column, "subject").reset_index()
        except GaitvalError:
            # fewer than two subjects with data: the ANOVA is undefined, say so by NaN
            a = pd.DataFrame({"source": ["between", "within", "total"],
                              **{c: np.nan for c in ("SS", "df", "MS", "F", "p")}})
        a.insert(0, "parameter", param)
        a.insert(1, "symbol", PARAM_INFO[param][0])
        published = pub.TABLE_C1[param] if speed == "normal" else None
        for i, c in enumerate(["SS", "df", "MS", "F", "p"]):
            a[c + "_published"] = [published[s][i] if published else np.nan
                                   for s in a["source"]]
        frames.append(a)
    return pd.concat(frames, ignore_index=True)


# ----------------------------------------------------------------------------- writing
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
         "paper prints NaN for cadence RMSE."])
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
    for name, table in build_ultrasonic_tables(gait_params_df).items():
        caption, notes = caps[name]
        paths += write_table(table, out_dir / f"ultrasonic_{name}", caption=caption,
                             notes=notes, digits=5 if name == "tableC1" else 3)
    return paths
