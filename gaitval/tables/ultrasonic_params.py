"""Seed 003's gait parameter table as the ultrasonic tables read it: names and checks.

Input contract — the **gait parameter table** written by the ultrasonic gait-parameter step
(:func:`gaitval.evaluate.ultrasonic.gait_parameters`): one row per (trial, stride,
parameter) with columns

``study, trial, subject, speed (slow|normal|fast), stride (int), parameter, unit,
reference, system``

where ``parameter`` is one of :data:`PARAMETERS` and ``reference`` / ``system`` are the
camera-reference and ultrasonic estimates of that stride (SI units).

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of spatial-temporal gait
parameters using a low-cost ultrasonic motion analysis system. Sensors 2014, 14(8),
15434–15457 (seed 003), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

import pandas as pd

from gaitval.errors import GaitvalError

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
    bad = sorted(set(df["parameter"].astype(str).unique()) - set(PARAMETERS))
    if bad:
        raise GaitvalError(f"gait parameter table: unknown parameter(s) {bad}",
                           hint=f"use {list(PARAMETERS)}")
    speeds = df["speed"].astype(str)
    bad = sorted(set(speeds[df["speed"].notna()].unique()) - set(SPEEDS))
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


def select(df: pd.DataFrame, parameter: str, speed: str | None, what: str) -> pd.DataFrame:
    """The rows of one parameter (and speed); an error naming ``what`` when there are none."""
    sub = df[df["parameter"] == parameter]
    if speed is not None:
        sub = sub[sub["speed"] == speed]
    if sub.empty:
        raise GaitvalError(f"{what}: no rows for parameter {parameter!r}"
                           + (f" at speed {speed!r}" if speed else ""),
                           hint="check the gait parameter table of the ultrasonic trials")
    return sub


def subject_order(subjects) -> list[str]:
    """Subjects in natural order ("S2" before "S10")."""
    def key(s):
        digits = "".join(ch for ch in s if ch.isdigit())
        return (int(digits) if digits else 10 ** 9, s)
    return sorted(set(subjects), key=key)
