"""The row format of ``physics.csv`` shared by :mod:`gaitval.simulate.physics` and its
per-protocol modules (:mod:`~gaitval.simulate.physics_tug`,
:mod:`~gaitval.simulate.physics_ultrasonic`)."""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

GROUP_OF = {"tug": "young", "mtst": "elderly", "rollator": "patient"}
COLUMNS = ["check", "protocol", "group", "phase", "value", "reference", "lower", "upper",
           "unit", "tolerance", "source", "passed", "note"]


def _row(check, protocol, value, reference, lower, upper, unit, tolerance, source,
         group="", phase="", note="") -> dict:
    ok = (np.nan if not np.isfinite(value) or (lower is None and upper is None)
          else bool((lower is None or value >= lower) and (upper is None or value <= upper)))
    return {"check": check, "protocol": protocol, "group": group, "phase": phase,
            "value": float(value), "reference": float(reference),
            "lower": np.nan if lower is None else float(lower),
            "upper": np.nan if upper is None else float(upper), "unit": unit,
            "tolerance": tolerance, "source": source, "passed": ok, "note": note}


def poisson_ci(k: int, level: float = 0.95) -> tuple[float, float]:
    """Exact (Garwood) confidence interval of a Poisson count ``k``."""
    a = (1 - level) / 2
    lo = 0.0 if k == 0 else stats.chi2.ppf(a, 2 * k) / 2
    return float(lo), float(stats.chi2.ppf(1 - a, 2 * k + 2) / 2)


def _straight_steps(ev: pd.DataFrame, protocol: str) -> tuple[np.ndarray, np.ndarray]:
    """Step lengths (m) and step times (s) of a trial's steady straight steps.

    TUG: contacts on the outbound line after the first two (gait initiation); MTST and
    rollator: all contacts but the first two and the closing one.  A step's length is the
    advance along the landing foot's stride.
    """
    c = ev[ev["event"] == "foot_contact"].sort_values("t_s").reset_index(drop=True)
    idx = np.arange(len(c))
    if protocol == "tug":
        use = (c["label"].astype(str) == "forward").to_numpy() & (idx >= 2)
    else:
        use = (idx >= 2) & (idx < len(c) - 1)
    p, t = c[["x_m", "y_m"]].to_numpy(float), c["t_s"].to_numpy(float)
    L, T = [], []
    for i in np.flatnonzero(use):
        stride = p[i] - p[i - 2]
        n = np.hypot(*stride)
        if n < 1e-6:
            continue
        L.append(float((p[i] - p[i - 1]) @ (stride / n)))
        T.append(float(t[i] - t[i - 1]))
    return np.array(L), np.array(T)
