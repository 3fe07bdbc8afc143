"""Swings of a simulated study read back from its truth (``truth/<trial>/legs.parquet``,
``events.csv``) for the physical checks (:mod:`gaitval.simulate.physics`): the lowest
forward speed of the shin point in each swing, and the first swing from standing.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd


def swings(ev: pd.DataFrame, side: str) -> list[tuple[float, float]]:
    """(foot off, next contact) of one side from a truth ``events.csv``."""
    offs = np.sort(ev.loc[(ev["event"] == "foot_off") & (ev["side"] == side), "t_s"].to_numpy())
    cons = np.sort(ev.loc[(ev["event"] == "foot_contact") & (ev["side"] == side),
                          "t_s"].to_numpy())
    out = []
    for to in offs:
        nxt = cons[cons > to]
        if len(nxt):
            out.append((float(to), float(nxt[0])))
    return out


def lrs_trials(study_dir: Path) -> pd.DataFrame:
    """The study's LRS trials that have a truth ``legs.parquet``."""
    tr = pd.read_csv(study_dir / "trials.csv")
    tr = tr[tr["sensor_kind"] == "lrs"]
    return tr[[(study_dir / "truth" / t / "legs.parquet").is_file() for t in tr["trial"]]]


def first_swing(study_dir: Path, trial: str) -> tuple[float, float]:
    """The first swing from standing (the trial's earliest lift-off): the lowest forward
    speed of its shin point (m/s) and its duration ÷ the trial's median swing."""
    return _first(*_truth(study_dir, trial))


def swing_stats(study_dir: Path, trial: str) -> tuple[np.ndarray, tuple[float, float]]:
    """Per complete swing of a trial the lowest forward speed of the shin point (m/s), and
    :func:`first_swing`, its truth read once: one task per trial of the physical checks
    (the simulation's worker pool maps it)."""
    legs, ev = _truth(study_dir, trial)
    return _minima(legs, ev), _first(legs, ev)


def _truth(study_dir: Path, trial: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    d = Path(study_dir) / "truth" / trial
    return pd.read_parquet(d / "legs.parquet"), pd.read_csv(d / "events.csv")


def _minima(legs: pd.DataFrame, ev: pd.DataFrame) -> np.ndarray:
    from gaitval.simulate.shin import point_profile

    out = []
    for side, g in legs.groupby("side", sort=True):
        t = g["t_s"].to_numpy(float)
        rate = 1.0 / float(np.median(np.diff(t)))
        prof = point_profile(t, g[["x_m", "y_m"]].to_numpy(float), swings(ev, side), rate)
        out.append(prof["fwd_min"])
    return np.concatenate(out) if out else np.array([])


def _first(legs: pd.DataFrame, ev: pd.DataFrame) -> tuple[float, float]:
    from gaitval.simulate.shin import point_profile

    sw = {s: swings(ev, s) for s in ("L", "R")}
    side = min((s for s in sw if sw[s]), key=lambda s: sw[s][0][0])
    (a, b), g = sw[side][0], legs[legs["side"] == side]
    t = g["t_s"].to_numpy(float)
    prof = point_profile(t, g[["x_m", "y_m"]].to_numpy(float), [(a, b)],
                         1.0 / float(np.median(np.diff(t))))
    # a first step whose shin point travels < 5 cm (a shuffle) has no direction: NaN
    fmin = float(prof["fwd_min"][0]) if len(prof["fwd_min"]) else np.nan
    return fmin, (b - a) / float(np.median(
        [y - x for v in sw.values() for x, y in v]))
