"""Qi et al. 2014 Table 1: errors of the pendulum experiment in 3-D against motion capture.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.config import deep_merge
from gaitval.evaluate.pendulum import pendulum_errors
from gaitval.evaluate.ultrasonic_config import resolve_cfg
from gaitval.stats.noise import identify_noise, noise_to_config
from gaitval.stats.summary import rmse
from gaitval.tables.render import write_table

#: Qi et al. 2014 Table 1 (mm), transcribed: mean, std, RMSE, Net RMSE per axis.  The paper's
#: Net RMSE column is cumulative: X alone, then sqrt(X^2 + Y^2), then all three axes.
PUBLISHED_MM = {"X": (0.02, 4.08, 4.08, 4.08), "Y": (0.03, 0.72, 0.72, 4.14),
                "Z": (0.09, 1.08, 1.08, 4.28)}
AXIS_NAMES = {"X": "horizontal (progression)", "Y": "vertical", "Z": "lateral"}


def table1(errors: pd.DataFrame) -> pd.DataFrame:
    """Mean, std, RMSE and cumulative net RMSE per axis of the pendulum errors.

    Parameters
    ----------
    errors : DataFrame
        Output of :func:`gaitval.evaluate.pendulum.pendulum_errors`: ``ex_m, ey_m, ez_m``
        (UKF estimate minus camera, ultrasonic frame) pooled over the pendulum trials.

    Returns
    -------
    DataFrame
        One row per axis ``X, Y, Z`` with ``direction``, ``n_samples``, ``mean_mm``,
        ``std_mm`` (sample std, ddof = 1), ``rmse_mm``, ``net_rmse_mm`` (cumulative,
        ``sqrt(sum of RMSE^2 of this and the axes above)``, as the paper's column) and the
        published ``*_published`` values beside each.
    """
    rows = []
    acc = 0.0
    for axis, col in (("X", "ex_m"), ("Y", "ey_m"), ("Z", "ez_m")):
        e = errors[col].to_numpy(dtype=float)
        e = e[np.isfinite(e)] * 1000.0                         # m -> mm for the display
        e_rms = rmse(e)
        acc += e_rms ** 2
        pub = PUBLISHED_MM[axis]
        rows.append({"axis": axis, "direction": AXIS_NAMES[axis], "n_samples": int(e.size),
                     "mean_mm": float(e.mean()), "mean_mm_published": pub[0],
                     "std_mm": float(e.std(ddof=1)), "std_mm_published": pub[1],
                     "rmse_mm": e_rms, "rmse_mm_published": pub[2],
                     "net_rmse_mm": float(np.sqrt(acc)), "net_rmse_mm_published": pub[3]})
    return pd.DataFrame(rows)


def write_ultrasonic_table1(errors: pd.DataFrame, stem: str | Path,
                            noise: dict | None = None) -> list[Path]:
    """Render Table 1 to ``<stem>.csv/.md/.tex`` (stem e.g. ``reports/tables/ultrasonic_table1``).

    ``noise`` (the dict of :func:`gaitval.stats.noise.identify_noise`) adds the identified V
    and W to the notes.
    """
    df = table1(errors)
    notes = ["Errors are UKF estimate minus camera reference (marker TX brought into the "
             "ultrasonic frame by a rigid fit of the receiver markers), both low-passed "
             "(2nd-order Butterworth, 10 Hz, zero phase: Qi et al. 2014 §4.1, 'All data were "
             "low-pass filtered'), pooled over all pendulum trials, in mm; the first "
             "noise_id.skip_start_s of each trial (filter start-up) is left out.",
             "Net RMSE is cumulative down the rows, as in the paper's table "
             "(X; sqrt(X^2+Y^2); sqrt(X^2+Y^2+Z^2)).",
             "Axes follow the paper: X progression, Y vertical, Z lateral."]
    if noise is not None:
        V = ", ".join(f"{v * 1e6:.2f}" for v in noise["V_m2"])
        W = ", ".join(f"{w:g}" for w in noise["W_sigma_mps2"])
        notes.append(f"Identified V = diag({V}) mm^2 (paper: diag(11, 9.3, 9, 9)); "
                     f"W sigmas = ({W}) m/s^2 by the minimum-RMSE search on the low-passed "
                     "errors (paper: 30, 25, 10, "
                     "stated in mm/s).")
    caption = ("Errors of the pendulum experiment in 3D space compared with the motion "
               "capture system (Qi et al. 2014 Table 1), reproduced beside the published values.")
    return write_table(df, stem, caption=caption, notes=notes)


def build_ultrasonic_table1(trials, stem: str | Path, cfg: dict | None = None, *,
                            names: list[str] | None = None) -> tuple[list[Path], dict]:
    """Identify V and W from the pendulum trials, then render Table 1 with them.

    Parameters
    ----------
    trials : list of (UltrasonicLog, MocapTrial)
        The pendulum trials.
    stem : path without suffix, e.g. ``reports/tables/ultrasonic_table1``.
    cfg : dict
        The ``ultrasonic`` configuration
        (see :data:`gaitval.evaluate.ultrasonic_config.DEFAULT_CFG`).

    Returns
    -------
    paths : list of Path
        The CSV, Markdown and LaTeX files.
    noise : dict
        :func:`gaitval.stats.noise.noise_to_config` of the identification (plain numbers).
    """
    res = identify_noise(trials, cfg, names=names)
    ucfg = deep_merge(resolve_cfg(cfg), {"ukf": {"W_sigma_mps2": res["W_sigma_mps2"],
                                               "V_m2": res["V_m2"]}})
    err = pendulum_errors(trials, ucfg, names=names, aligned=res["_aligned"])
    return write_ultrasonic_table1(err, stem, res), noise_to_config(res)
