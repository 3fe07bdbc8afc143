"""Agreement table of a peer's paired results: gaitval's statistics on someone else's data.

The worked example is the published per-walk results of Single et al. (Sensors 2024,
24(4):1172), a lidar gait method (``us_*`` columns) against a pressure walkway (``gt_*``):
``realdata/peer-results/gailo_results.parquet``.  Every ``us_<name>`` / ``gt_<name>`` pair
is analysed with :func:`gaitval.stats.agreement`.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.stats import agreement
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


def _read(parquet_path: str | Path) -> pd.DataFrame:
    path = Path(parquet_path)
    try:
        return pd.read_parquet(path)
    except FileNotFoundError:
        raise FileFormatError("peer results file not found", path=path) from None
    except Exception as exc:  # pyarrow raises several types for a non-parquet file
        raise FileFormatError(f"cannot read peer results as Parquet ({exc})",
                              path=path) from None


def peer_pairs(columns) -> list[str]:
    """Names ``x`` for which both ``us_x`` and ``gt_x`` are columns (file order)."""
    cols = [str(c) for c in columns]
    return [c[len(SYSTEM_PREFIX):] for c in cols if c.startswith(SYSTEM_PREFIX)
            and REFERENCE_PREFIX + c[len(SYSTEM_PREFIX):] in cols]


def peer_agreement_table(parquet_path: str | Path) -> pd.DataFrame:
    """Agreement statistics for every ``us_*``/``gt_*`` pair of a peer results file.

    Parameters
    ----------
    parquet_path : path
        Parquet file with paired columns ``us_<name>`` (system) and ``gt_<name>``
        (reference), one row per walk.

    Returns
    -------
    DataFrame
        One row per pair (tidy): ``parameter``, ``unit`` (cm, s, cm/s, steps/min), ``n``
        (int), then the statistics of :data:`STATISTICS` (means, bias and its 95% CI,
        Bland–Altman limits and their 95% CIs, RMSE, MAD in ``unit``; ICC(A,1) and
        ICC(C,1) with 95% CIs, paired t-test t/df/p dimensionless).  Differences are
        system − reference.

    Raises
    ------
    FileFormatError
        The file cannot be read or holds no ``us_*``/``gt_*`` pair.
    """
    df = _read(parquet_path)
    names = peer_pairs(df.columns)
    if not names:
        raise FileFormatError("no paired us_<name> / gt_<name> columns found",
                              path=parquet_path,
                              hint="the system's columns start with 'us_', the "
                                   "reference's with 'gt_'")
    rows = []
    for name in names:
        a = agreement(df, REFERENCE_PREFIX + name, SYSTEM_PREFIX + name).iloc[0]
        row = {"parameter": name,
               "unit": PEER_UNITS.get(name, "").replace("_per_", "/").replace("_", " ")}
        for st in STATISTICS:
            row[st] = int(a[st]) if st in ("n", "df") else float(a[st])
        rows.append(row)
    return pd.DataFrame(rows)


def write_peer_table(parquet_path: str | Path, out_stem: str | Path) -> list[Path]:
    """Render :func:`peer_agreement_table` as ``<out_stem>.csv/.md/.tex``."""
    table = peer_agreement_table(parquet_path)
    caption = ("Agreement of the lidar gait method (us_*) with the pressure walkway (gt_*) "
               "computed by gaitval from the published paired results of " + SINGLE2024
               + "; a worked example of gaitval's statistics on someone else's results.")
    notes = ["Differences are system - reference. Bias CI: t-based; limits of agreement "
             "bias -/+ 1.96 sd with approximate 95% CIs from SE = sqrt(3 sd^2/n) (Bland & "
             "Altman 1999); ICC(A,1)/ICC(C,1): two-way model, McGraw & Wong (1996); "
             "t/df/p: paired t-test of the bias.",
             "Means, bias, limits, RMSE and MAD are in the row's unit; ICC, t, df and p "
             "are dimensionless."]
    return write_table(table, out_stem, caption=caption, notes=notes, digits=4)
