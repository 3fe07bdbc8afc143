"""Seed 003 Tables 2–6: per-subject reference and ultrasonic means, stds and RMSE.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal gait
parameters using a low-cost ultrasonic motion analysis system. Sensors 2014, 14(8),
15434–15457 (seed 003), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.stats import error_summary
from gaitval.tables import _published_qi2014 as pub
from gaitval.tables.ultrasonic_params import (PARAM_INFO, check_gait_params, select,
                                              subject_order)


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
