"""Role base and registry of leg detectors (scan series → leg observations).

Every detector returns the same observation table, one row per observed leg position:

==============  =======  ===============================================================
column          dtype    meaning
==============  =======  ===============================================================
``k``           int64    scan index in the ScanSeries (0-based)
``t_sensor_s``  float64  the scan's timestamp on the sensor clock (s)
``j``           int64    observation number within the scan (0-based, right to left)
``x_m, y_m``    float64  leg centre in the sensor frame (x forward, y left), metres
``pattern``     str      SL, LT, FS_O or FS_U (seed 001 §2.3); UO is what a *track* gets
                         when no observation is associated, never a detector row
``width_m``     float64  the edge-to-edge width w_e the pattern was judged on
``i_first``     int64    first beam of the segment
``i_last``      int64    last beam of the segment
==============  =======  ===============================================================
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.registry import Registry
from gaitval.types import ScanSeries

DETECTORS = Registry("detector")

OBS_COLUMNS = ("k", "t_sensor_s", "j", "x_m", "y_m", "pattern", "width_m",
               "i_first", "i_last")


def empty_observations() -> pd.DataFrame:
    return pd.DataFrame({
        "k": np.zeros(0, np.int64), "t_sensor_s": np.zeros(0), "j": np.zeros(0, np.int64),
        "x_m": np.zeros(0), "y_m": np.zeros(0), "pattern": pd.Series([], dtype=object),
        "width_m": np.zeros(0), "i_first": np.zeros(0, np.int64),
        "i_last": np.zeros(0, np.int64)})


class Detector:
    """Role base: ``detect(scans, leg_width_m) -> observation table`` (module docstring)."""

    windowed = False

    def detect(self, scans: ScanSeries, leg_width_m: float) -> pd.DataFrame:
        raise NotImplementedError


class WindowedDetector(Detector):
    """Role base of a detector that looks only where the tracker predicts the legs.

    Seed 002 §II places a rectangular observation window from the predicted legs (its
    size predefined at the start, then from their uncertainty) before grouping the points.
    The tracker calls ``observe`` scan by scan instead of ``detect`` once per trial.

    ``observe(scans, k, predicted, leg_width_m) -> (xy, patterns)``: ``predicted`` is None
    (no track yet: look everywhere) or one ``((x, y), S)`` per leg, the predicted position
    and its 2×2 innovation covariance (sensor frame); ``xy`` is a ``(J, 2)`` array of
    observed leg centres and ``patterns`` a list of J labels.
    """

    windowed = True

    def observe(self, scans: ScanSeries, k: int, predicted, leg_width_m: float):
        raise NotImplementedError

    def detect(self, scans: ScanSeries, leg_width_m: float) -> pd.DataFrame:
        """All scans without a prediction (the observation table of the module notes)."""
        rows = []
        for k in range(scans.n_scans):
            xy, pats = self.observe(scans, k, None, leg_width_m)
            for j, ((x, y), p) in enumerate(zip(np.asarray(xy).reshape(-1, 2), pats)):
                rows.append((k, float(scans.t[k]), j, float(x), float(y), p))
        if not rows:
            return empty_observations()
        df = pd.DataFrame(rows, columns=["k", "t_sensor_s", "j", "x_m", "y_m", "pattern"])
        df["width_m"], df["i_first"], df["i_last"] = np.nan, -1, -1
        return df[list(OBS_COLUMNS)]


def split_observations(obs: pd.DataFrame, n_scans: int
                       ) -> tuple[list[np.ndarray], list[list[str]]]:
    """Observation table → per-scan ``(J, 2)`` arrays and pattern lists (tracker input)."""
    xy: list[np.ndarray] = [np.zeros((0, 2))] * n_scans
    pats: list[list[str]] = [[] for _ in range(n_scans)]
    if len(obs) == 0:
        return list(xy), pats
    o = obs.sort_values(["k", "j"], kind="stable")
    k = o["k"].to_numpy()
    pts = o[["x_m", "y_m"]].to_numpy(dtype=float)
    pat = o["pattern"].astype(object).to_numpy()
    cuts = np.flatnonzero(np.diff(k)) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [len(k)]])
    xy = list(xy)
    for s, e in zip(starts, ends):
        kk = int(k[s])
        if 0 <= kk < n_scans:
            xy[kk] = pts[s:e]
            pats[kk] = list(pat[s:e])
    return xy, pats
