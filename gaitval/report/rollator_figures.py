"""Seed 002 figure: one turning trial, both trackers' legs against the truth (cf. its Fig. 4).

Four panels as in the paper's Fig. 4: lateral and forward position of the left and the
right leg over time, in the rollator frame (origin at the centre of the four rollator
markers, x forward along the rollator, y to its left; the laser mount converts the laser
frame), truth red, KF black, PF blue; grey bands mark the scans the KF got wrong (error
frames of Table II) and ticks its re-initialisations.

The trial: ``rollator.figure_trial`` if given, else the first subject's first ``straight``
trial (Scenario 1: 3 m, a 180° turn, 3 m back).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import plt, save_figure

COLOURS = {"truth": "tab:red", "kf": "black", "pf": "tab:blue"}


def pick_trial(frames: pd.DataFrame, trial: str | None = None) -> str | None:
    """The trial to draw (module notes); None when there is none."""
    trials = frames[["trial", "subject", "scenario"]].drop_duplicates().sort_values(
        ["subject", "trial"])
    if trial and trial in set(trials["trial"]):
        return trial
    straight = trials[trials["scenario"] == "straight"]
    pool = straight if len(straight) else trials
    return str(pool["trial"].iloc[0]) if len(pool) else None


def to_rollator(x: np.ndarray, y: np.ndarray, mount) -> tuple[np.ndarray, np.ndarray]:
    """Laser-frame points → rollator frame with the mount ``{x_m, y_m, yaw_rad}``."""
    if not mount:
        return x, y
    c, s = np.cos(float(mount["yaw_rad"])), np.sin(float(mount["yaw_rad"]))
    return float(mount["x_m"]) + c * x - s * y, float(mount["y_m"]) + s * x + c * y


def _spans(mask: np.ndarray):
    """(start, end) index runs where mask is True."""
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def write_rollator_figure(frames: pd.DataFrame, figures_dir, *, kf: str, pf: str,
                          trial: str | None = None, mount=None) -> list[Path]:
    """Write ``figures/rollator_turning_trial.png`` (module notes); [] without frames."""
    if frames is None or len(frames) == 0:
        return []
    tid = pick_trial(frames, trial)
    f = frames[frames["trial"] == tid]
    kf_f = f[f["tracker"] == kf].sort_values("scan")
    pf_f = f[f["tracker"] == pf].sort_values("scan")
    if not len(kf_f) or not len(pf_f):
        return []
    t = kf_f["t_sensor_s"].to_numpy(float)
    t = t - t[0]
    fig, axes = plt.subplots(2, 2, figsize=(12, 6.5), sharex=True)
    for j, side in enumerate("LR"):
        curves = {"truth": to_rollator(kf_f[f"x_true_m_{side}"].to_numpy(),
                                       kf_f[f"y_true_m_{side}"].to_numpy(), mount),
                  "kf": to_rollator(kf_f[f"x_m_{side}"].to_numpy(),
                                    kf_f[f"y_m_{side}"].to_numpy(), mount),
                  "pf": to_rollator(pf_f[f"x_m_{side}"].to_numpy(),
                                    pf_f[f"y_m_{side}"].to_numpy(), mount)}
        for i, (axis, name) in enumerate(((1, "lateral y (m)"), (0, "forward x (m)"))):
            ax = axes[i, j]
            for a, b in _spans(kf_f["error"].to_numpy(bool)):
                ax.axvspan(t[a], t[min(b, len(t) - 1)], color="0.85", lw=0)
            for key, lw in (("truth", 2.0), ("kf", 1.0), ("pf", 1.0)):
                ax.plot(t, curves[key][axis], color=COLOURS[key], lw=lw,
                        label={"truth": "ground truth", "kf": "KF", "pf": "PF"}[key])
            for k in np.flatnonzero(kf_f["restart"].to_numpy(bool)):
                ax.axvline(t[k], color="black", lw=0.4, ls=":")
            ax.set_ylabel(name)
            ax.set_title(f"{'left' if side == 'L' else 'right'} leg, {name.split()[0]}")
            ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    frame = "rollator frame" if mount else "laser frame (no mount configured)"
    fig.suptitle(f"{tid}: leg positions in the {frame}; grey = KF error frames, "
                 "dotted = KF re-initialisations", fontsize=10)
    fig.tight_layout()
    return [save_figure(fig, Path(figures_dir) / "rollator_turning_trial.png")]
