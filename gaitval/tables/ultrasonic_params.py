"""Qi et al. 2014's gait parameter table as the ultrasonic tables read it: names and checks.

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
15434–15457 (Qi et al. 2014), §4.4 and Tables 2–8, C1.
"""
from __future__ import annotations

import zlib

import numpy as np
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
#: Parameters measured per stride (one stride index) and per symmetry window (another).
PER_STRIDE = ("stride_length", "stride_length_norm", "stride_duration", "stride_velocity",
              "stride_velocity_norm", "cadence")
PER_WINDOW = ("h_symmetry", "v_symmetry")
#: The paper's sample: 10 strides per subject (Table C1: 10 subjects, df total 99).
PAPER_STRIDES_PER_SUBJECT = 10
#: Default seed of the stride draw (config ``ultrasonic.tables.sample_seed``).
SAMPLE_SEED = 2014



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


def strides_setting(value) -> int | None:
    """``ultrasonic.tables.strides_per_subject`` as a count, or None for ``"all"``."""
    if isinstance(value, str) and value.strip().lower() == "all":
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise GaitvalError(f"ultrasonic.tables.strides_per_subject must be a positive "
                           f"integer or 'all', not {value!r}",
                           hint="the paper's Tables 2-8 and C1 use 10 per subject")
    return int(value)


def sample_strides(gait_params: pd.DataFrame, strides_per_subject=PAPER_STRIDES_PER_SUBJECT,
                   seed: int = SAMPLE_SEED) -> pd.DataFrame:
    """The strides the Qi et al. 2014 tables are computed on: a seeded draw per subject and speed.

    Parameters
    ----------
    gait_params : DataFrame
        The gait parameter table (module notes).
    strides_per_subject : int or "all"
        How many strides of each subject at each speed (the paper: 10, from Table C1's
        100 observations of 10 subjects; its Tables 2–6 are consistent with it).  A
        subject with fewer strides keeps all of them.  ``"all"``: every matched stride.
    seed : int
        Seed of the draw.  Each (subject, speed) and each of the two families — per-stride
        parameters (S, NS, T, V, NV, C share a stride) and per-window symmetries (hS, vS
        share a window) — draws from its own stream ``default_rng([seed, crc32(key)])``,
        so adding a subject or a speed does not change another's draw.

    Returns
    -------
    DataFrame
        The rows of the drawn strides and windows (a simple random sample without
        replacement, kept in time order), with an extra column ``stride_index``: the
        position (0-based) of the stride (window) in its subject's sample at that speed,
        the "stride index" grouping of Table C1.  NS and NV are recomputed from S and V
        with ``n`` = the number of strides drawn for the subject at that speed
        (seed003 eq. (18), (21): "normalized by the number of strides n"); with
        ``"all"`` and one trial per subject and speed this is the gait table's own n.
        ``attrs["strides_per_subject"]`` holds the setting, ``attrs["sample_seed"]`` the
        seed.

    Notes
    -----
    The paper does not say which 10 strides it analysed; a random draw rather than the
    first 10 avoids the start of a trial, where the filter and the walker settle.
    """
    k = strides_setting(strides_per_subject)
    df = check_gait_params(gait_params)
    parts = []
    keys = ["study", "trial", "stride"]
    for (subject, speed), d in df.groupby(["subject", "speed"], sort=True):
        for family in (PER_STRIDE, PER_WINDOW):
            f = d[d["parameter"].isin(family)]
            if f.empty:
                continue
            units = f[keys].drop_duplicates().sort_values(keys, kind="stable")
            if k is not None and k < len(units):
                tag = f"{subject}|{speed}|{family[0]}".encode()
                rng = np.random.default_rng([int(seed), zlib.crc32(tag)])
                units = units.iloc[np.sort(rng.choice(len(units), size=k, replace=False))]
            units = units.assign(stride_index=np.arange(len(units), dtype=np.int64))
            parts.append(f.merge(units, on=keys, how="inner"))
    if not parts:
        out = df.assign(stride_index=pd.Series(dtype=np.int64))
    else:
        out = pd.concat(parts, ignore_index=True)
        out = _renormalise(out)
    out.attrs.update(strides_per_subject="all" if k is None else k, sample_seed=int(seed))
    return out


def _renormalise(df: pd.DataFrame) -> pd.DataFrame:
    """NS = S / n and NV = V / n with n the strides of the subject's sample at that speed
    (seed003 eq. (18), (21))."""
    out = df.copy()
    keys = ["study", "trial", "stride"]
    for norm, base in (("stride_length_norm", "stride_length"),
                       ("stride_velocity_norm", "stride_velocity")):
        b = out[out["parameter"] == base]
        if b.empty:
            continue
        n = b.groupby(["subject", "speed"])["stride"].size().rename("n_norm")
        vals = b.set_index(keys)[["reference", "system"]]
        rows = out.index[out["parameter"] == norm]
        sel = out.loc[rows]
        idx = pd.MultiIndex.from_frame(sel[keys])
        nn = n.reindex(pd.MultiIndex.from_frame(sel[["subject", "speed"]])).to_numpy(float)
        for c in ("reference", "system"):
            out.loc[rows, c] = vals[c].reindex(idx).to_numpy(float) / nn  # seed003 eq. (18), (21)
    return out


def strides_per_subject_of(df: pd.DataFrame, speed: str) -> np.ndarray:
    """The number of strides (S rows) of each subject at ``speed``: NS's and NV's n."""
    b = df[(df["parameter"] == "stride_length") & (df["speed"] == speed)]
    return b.groupby("subject")["stride"].size().to_numpy(int)


def n_text(counts: np.ndarray) -> str:
    """``"10"`` when every subject has the same n, ``"231-264"`` otherwise, ``""`` none."""
    if len(counts) == 0:
        return ""
    lo, hi = int(np.min(counts)), int(np.max(counts))
    return str(lo) if lo == hi else f"{lo}-{hi}"
