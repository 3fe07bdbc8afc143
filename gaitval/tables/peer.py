"""Agreement table of a peer's paired results: gaitval's statistics on someone else's data.

The worked example is the published per-walk results of Single et al. (Sensors 2024,
24(4):1172), a lidar gait method (``us_*`` columns) against a pressure walkway (``gt_*``):
``realdata/peer-results/gailo_results.parquet``.  Every ``us_<name>`` / ``gt_<name>`` pair
is analysed with :func:`gaitval.stats.agreement` (every row independent: "pooled") and,
when the file says whose walk each row is (a participant column), with the
repeated-measures statistics of :mod:`gaitval.stats.repeated` (``*_rm`` columns).  The
published file has no participant column, so its ``*_rm`` columns are empty.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.parquet import read_parquet
from gaitval.stats import agreement, icc_mixed, loa_nested, proportional_bias
from gaitval.stats._refs import SINGLE2024
from gaitval.tables.render import write_table

#: Units of the peer data's columns (realdata/README.md, from the source repository):
#: lengths in cm, times in s, velocity in cm/s, cadence in steps/min.
PEER_UNITS = {"step_length": "cm", "stride_length": "cm", "step_time": "s",
              "stride_time": "s", "velocity": "cm_per_s", "cadence": "steps_per_min"}
SYSTEM_PREFIX, REFERENCE_PREFIX = "us_", "gt_"
#: statistic rows of the table, in order (see :func:`gaitval.stats.agreement`)
STATISTICS = ("n", "ref_mean", "pro_mean", "bias", "bias_sd", "bias_ci_low",
              "bias_ci_high", "loa_low", "loa_high", "loa_low_ci_low", "loa_low_ci_high",
              "loa_high_ci_low", "loa_high_ci_high", "rmse", "mad", "icc_a1",
              "icc_a1_ci_low", "icc_a1_ci_high", "icc_c1", "icc_c1_ci_low", "icc_c1_ci_high",
              "t", "df", "p")
#: repeated-measures statistics (subjects as a random effect), after the pooled ones:
#: table column -> column of :func:`gaitval.stats.loa_nested` (REML)
RM_LOA = {"bias_rm": "bias", "bias_rm_ci_low": "bias_ci_low",
          "bias_rm_ci_high": "bias_ci_high", "sd_rm": "sd_total",
          "var_between_rm": "var_between", "var_within_rm": "var_within",
          "loa_low_rm": "loa_low", "loa_high_rm": "loa_high",
          "loa_low_rm_ci_low": "loa_low_ci_low", "loa_low_rm_ci_high": "loa_low_ci_high",
          "loa_high_rm_ci_low": "loa_high_ci_low",
          "loa_high_rm_ci_high": "loa_high_ci_high"}
#: table column -> column of :func:`gaitval.stats.icc_mixed`
RM_ICC = {"icc_agreement_rm": "icc_agreement", "icc_consistency_rm": "icc_consistency"}
#: table column -> column of :func:`gaitval.stats.proportional_bias`
PROP_BIAS = {"prop_bias_slope": "slope", "prop_bias_slope_ci_low": "slope_ci_low",
             "prop_bias_slope_ci_high": "slope_ci_high", "prop_bias_p": "p"}
#: columns that name the participant of a row, looked for in this order
SUBJECT_COLUMNS = ("subject", "participant", "subject_id", "participant_id")


def _read(path_: str | Path) -> pd.DataFrame:
    """A paired-results file: Parquet, or CSV (one header line of column names)."""
    path = Path(path_)
    if not path.is_file():
        raise FileFormatError("paired results file not found", path=path)
    if path.suffix.lower() == ".csv":
        try:
            return pd.read_csv(path)
        except Exception as exc:  # noqa: BLE001 - pandas raises several types
            raise FileFormatError(f"cannot read paired results as CSV ({exc})",
                                  path=path) from None
    try:
        return read_parquet(path)
    except Exception as exc:  # pyarrow raises several types for a non-parquet file
        raise FileFormatError(f"cannot read paired results as Parquet ({exc})",
                              path=path, hint="a *.parquet or *.csv file") from None


def peer_pairs(columns, system: str = SYSTEM_PREFIX,
               reference: str = REFERENCE_PREFIX) -> list[str]:
    """Names ``x`` for which both ``<system>x`` and ``<reference>x`` are columns (file
    order; by default ``us_x`` and ``gt_x``)."""
    cols = [str(c) for c in columns]
    return [c[len(system):] for c in cols if c.startswith(system)
            and reference + c[len(system):] in cols]


def subject_column(columns) -> str | None:
    """The first of :data:`SUBJECT_COLUMNS` among ``columns``, else None."""
    cols = [str(c) for c in columns]
    return next((c for c in SUBJECT_COLUMNS if c in cols), None)


def _repeated(df: pd.DataFrame, ref: str, pro: str, subject: str | None) -> dict:
    """The ``*_rm`` and ``prop_bias_*`` cells of one parameter (NaN without subjects)."""
    nan = float("nan")
    row: dict = {"n_subjects": nan, **dict.fromkeys([*RM_LOA, "loa_width_ratio"], nan),
                 **dict.fromkeys(RM_ICC, nan)}
    pb = proportional_bias(df, ref, pro, subject=subject).iloc[0]
    row.update({col: float(pb[src]) for col, src in PROP_BIAS.items()})
    if subject is None:
        return row
    rm = loa_nested(df, ref, pro, subject).iloc[0]
    ic = icc_mixed(df, [ref, pro], subject=subject).iloc[0]
    row["n_subjects"] = int(rm["n_subjects"])
    row.update({col: float(rm[src]) for col, src in RM_LOA.items()})
    row.update({col: float(ic[src]) for col, src in RM_ICC.items()})
    return row


def peer_agreement_table(parquet_path: str | Path, subject: str | None = None, *,
                         system: str = SYSTEM_PREFIX, reference: str = REFERENCE_PREFIX,
                         units: dict | None = None) -> pd.DataFrame:
    """Agreement statistics for every ``us_*``/``gt_*`` pair of a peer results file.

    Parameters
    ----------
    parquet_path : path
        Parquet (or CSV) file with paired columns ``us_<name>`` (system) and
        ``gt_<name>`` (reference), one row per walk or stride.
    subject : str, optional
        Column naming each row's participant; by default the first of
        :data:`SUBJECT_COLUMNS` present.  Without one, the repeated-measures columns are
        NaN (the published file of Single et al. has none).
    system, reference : str
        The column prefixes of the system's and the reference's values (default ``us_``
        and ``gt_``).
    units : dict, optional
        Parameter name -> its unit, shown in the ``unit`` column (default: the peer
        data's, :data:`PEER_UNITS`).

    Returns
    -------
    DataFrame
        One row per pair (tidy): ``parameter``, ``unit`` (cm, s, cm/s, steps/min), ``n``
        (int), then

        - pooled statistics, every row independent (:data:`STATISTICS`; means, bias and
          its 95% CI, Bland–Altman limits and their 95% CIs, RMSE, MAD in ``unit``;
          ICC(A,1) and ICC(C,1) with 95% CIs, paired t-test t/df/p dimensionless);
        - repeated-measures statistics, participants as a random effect: ``n_subjects``,
          then :data:`RM_LOA` (bias with its Satterthwaite 95% CI, SD of a single
          difference and its between/within-participant variances, limits of agreement
          with MOVER 95% CIs, from :func:`gaitval.stats.loa_nested`), ``loa_width_ratio``
          (repeated-measures over pooled limit width) and :data:`RM_ICC` (from
          :func:`gaitval.stats.icc_mixed`);
        - proportional bias (slope of difference on mean with its 95% CI and p, from
          :func:`gaitval.stats.proportional_bias`; with a participant random intercept
          when participants are known).

        Differences are system − reference.

    Raises
    ------
    FileFormatError
        The file cannot be read, holds no ``us_*``/``gt_*`` pair, or lacks the named
        ``subject`` column.
    """
    df = _read(parquet_path)
    names = peer_pairs(df.columns, system, reference)
    if not names:
        raise FileFormatError(f"no paired {system}<name> / {reference}<name> columns "
                              "found", path=parquet_path,
                              hint=f"the system's columns start with {system!r}, the "
                                   f"reference's with {reference!r}; columns: "
                                   f"{[str(c) for c in df.columns][:12]}")
    for name in names:
        for col in (system + name, reference + name):
            bad = pd.to_numeric(df[col], errors="coerce").isna() & df[col].notna()
            if bad.any():
                i = int(bad.to_numpy().nonzero()[0][0])
                raise FileFormatError(f"column {col!r}, data row {i + 1}: {df[col].iloc[i]!r} "
                                      "is not a number", path=parquet_path)
    units = PEER_UNITS if units is None else dict(units)
    if subject is not None and subject not in df.columns:
        raise FileFormatError(f"participant column {subject!r} not in the file",
                              path=parquet_path,
                              hint=f"columns: {[str(c) for c in df.columns]}")
    subject = subject or subject_column(df.columns)
    rows = []
    for name in names:
        ref, pro = reference + name, system + name
        a = agreement(df, ref, pro).iloc[0]
        row = {"parameter": name,
               "unit": str(units.get(name, "")).replace("_per_", "/").replace("_", " ")}
        for st in STATISTICS:
            row[st] = int(a[st]) if st in ("n", "df") else float(a[st])
        row.update(_repeated(df, ref, pro, subject))
        row["loa_width_ratio"] = ((row["loa_high_rm"] - row["loa_low_rm"])
                                  / (row["loa_high"] - row["loa_low"]))
        rows.append(row)
    return pd.DataFrame(rows)


def write_peer_table(parquet_path: str | Path, out_stem: str | Path, *,
                     name: str | None = None, system: str = SYSTEM_PREFIX,
                     reference: str = REFERENCE_PREFIX, subject: str | None = None,
                     units: dict | None = None) -> list[Path]:
    """Render :func:`peer_agreement_table` as ``<out_stem>.csv/.md/.tex``.  Without
    ``name``: the worked example on Single et al.'s published results; with it, a
    study's own paired results (config ``agreement_files.<name>``)."""
    table = peer_agreement_table(parquet_path, subject, system=system,
                                 reference=reference, units=units)
    if name is None:
        caption = ("Agreement of the lidar gait method (us_*) with the pressure walkway "
                   "(gt_*) computed by gaitval from the published paired results of "
                   + SINGLE2024 + "; a worked example of gaitval's statistics on someone "
                   "else's results.")
    else:
        caption = (f"Agreement of {name} ({system}*) with its reference ({reference}*): "
                   f"paired results per walk or stride from {Path(parquet_path).name} "
                   "(agreement_files), analysed by gaitval's agreement statistics.")
    notes = ["Differences are system - reference. Pooled columns (bias ... p, no suffix) "
             "treat every row as an independent pair: bias CI t-based; limits of "
             "agreement bias -/+ 1.96 sd with approximate 95% CIs from SE = sqrt(3 sd^2/n) "
             "(Bland & Altman 1999); ICC(A,1)/ICC(C,1): two-way model, McGraw & Wong "
             "(1996); t/df/p: paired t-test of the bias.",
             _rm_note(table, worked_example=name is None),
             "prop_bias_*: slope of the difference on the mean of both systems (Bland & "
             "Altman 1999 sec. 3.2) with its 95% CI and p; ordinary least squares over "
             "all rows when participants are unknown, else with a participant random "
             "intercept.",
             "Means, bias, limits, sd, RMSE and MAD are in the row's unit, var_* in the "
             "unit squared; ICC, ratios, slopes, t, df and p are dimensionless."]
    return write_table(table, out_stem, caption=caption, notes=notes)


def _rm_note(table: pd.DataFrame, worked_example: bool = True) -> str:
    """Table note on the repeated-measures (``*_rm``) columns, quoting how much wider."""
    what = ("Repeated-measures columns (*_rm) treat participants as a random effect "
            "(Bland & Altman 2007; Zou 2013): bias and its 95% CI from a random-intercept "
            "model (REML, Satterthwaite df), sd_rm = sqrt(var_between_rm + var_within_rm) "
            "the SD of a single difference, limits bias_rm -/+ 1.96 sd_rm with MOVER 95% "
            "CIs; icc_*_rm from participant, walk, participant x system and residual "
            "variance components; loa_width_ratio = repeated-measures / pooled limit "
            "width.")
    ratio = table["loa_width_ratio"].dropna()
    if ratio.empty and not worked_example:
        return (what + " They are empty here: the file names no participant column ("
                + ", ".join(SUBJECT_COLUMNS) + "), so the pooled columns treat rows of one "
                "participant as independent.")
    if ratio.empty:
        return (what + " They are empty here: the published file does not say which "
                "participant each walk belongs to (its 90 walks are a subset of the 123 "
                "walks of 32 participants, 2-5 each, listed in the source's "
                "gailo-evaluation-datasets.json). The pooled columns treat correlated "
                "walks as independent, so their CIs are likely too short and their "
                "limits somewhat too narrow.")
    return (what + f" Here the repeated-measures limits are {ratio.min():.2f}-"
            f"{ratio.max():.2f} times as wide as the pooled ones.")
