"""Agreement with the camera reference, one row per system: gaitval's UKF and external ones.

Issue 37.  Qi et al. 2014's Tables 2–6 describe one system, the ultrasonic UKF.  A study team
validating its own foot-tracking system (a ``*.foot.csv`` per treadmill trial,
:mod:`gaitval.io.foot`) wants the same statistics for it, beside gaitval's: this table
stacks, per system, the pooled and repeated-measures agreement of every parameter at every
speed (:func:`gaitval.tables.ultrasonic_agreement.agreement_table`: bias and Bland–Altman
limits with their confidence intervals, ICC(A,1); the mixed-model bias, limits and ICC with
subjects as a random effect; proportional bias), each on the strides that Qi et al. 2014's tables
use (:func:`gaitval.tables.ultrasonic_params.sample_strides`: ``ultrasonic.tables``, by
default 10 per subject and speed, drawn with the same seed from that system's matched
strides).  Differences are system − reference.  No paper gives these rows: no verdicts.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.tables.render import write_table
from gaitval.tables.ultrasonic_agreement import agreement_table
from gaitval.tables.ultrasonic_params import sample_strides

#: the columns shown, in order (the CSV has these too; every statistic is in
#: :func:`agreement_table`)
COLUMNS = ("method", "parameter", "symbol", "unit", "speed", "n_strides", "n_subjects",
           "bias", "bias_ci_low", "bias_ci_high", "loa_low", "loa_high", "icc_a1",
           "bias_rm", "loa_low_rm", "loa_high_rm", "icc_agreement_rm", "prop_bias_slope",
           "prop_bias_p")


def method_agreement_table(gait_by_method: dict[str, pd.DataFrame],
                           cfg: dict | None = None) -> pd.DataFrame:
    """One block of :func:`agreement_table` rows per system (``method`` first).

    Parameters
    ----------
    gait_by_method : dict
        System name -> its gait parameter table (the rows of
        :func:`gaitval.evaluate.ultrasonic.gait_parameters`; a ``method`` column, if
        there, is ignored).
    cfg : dict, optional
        The ``ultrasonic`` config section: ``tables.strides_per_subject`` and
        ``tables.sample_seed`` choose the strides (:func:`sample_strides`).
    """
    from gaitval.tables.ultrasonic import table_settings

    k, seed = table_settings(cfg)
    parts = []
    for method, gp in gait_by_method.items():
        gp = gp.drop(columns=["method"], errors="ignore")
        t = agreement_table(sample_strides(gp, k, seed))
        if t.empty:
            continue
        t.insert(0, "method", method)
        parts.append(t)
    if not parts:
        return pd.DataFrame(columns=list(COLUMNS))
    return pd.concat(parts, ignore_index=True)[list(COLUMNS)]


def write_method_agreement(gait_by_method: dict[str, pd.DataFrame], out_stem: str | Path,
                           cfg: dict | None = None) -> list[Path]:
    """Write :func:`method_agreement_table` as ``<out_stem>.csv/.md/.tex``."""
    from gaitval.tables.ultrasonic import table_settings

    table = method_agreement_table(gait_by_method, cfg)
    k, seed = table_settings(cfg)
    caption = ("Agreement of each foot-tracking system with the camera reference on the "
               "treadmill trials: gaitval's ultrasonic UKF (Qi et al. 2014) and the external "
               "systems declared for the study, one block of rows per system; "
               "differences system − reference.")
    notes = [
        f"Strides: {k} per subject and speed (ultrasonic.tables), drawn with seed {seed} "
        "from each system's own matched strides, as Qi et al. 2014's Tables 2–6 are; a system "
        "that matches other strides is compared on other strides.",
        "Pooled columns treat every stride as independent (Bland & Altman 1999); *_rm "
        "columns take subjects as a random effect (Bland & Altman 2007; Zou 2013); ICC(A,1) "
        "is absolute agreement.  No paper reports these rows: no published value, no "
        "verdict.",
    ]
    return write_table(table, Path(out_stem), caption=caption, notes=notes)
