"""TUG leg-tracking figures: trajectories vs ground truth (seed 000 Fig. 14 style) and a
false-tracking example (Fig. 11 style), from the evaluation frames.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000).
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from gaitval.report.figures import save_figure  # noqa: E402

COLORS = {"L": "tab:blue", "R": "tab:red"}


def plot_trial_trajectories(frames: pd.DataFrame, trial: str, path: str | Path,
                            methods: list[str] | None = None) -> Path:
    """Top view of both legs' tracks (per method) against the ground truth of one trial.

    ``frames``: concatenated evaluation frames (columns of
    :data:`gaitval.evaluate.tug.FRAME_COLUMNS`).  UO steps are drawn as open circles.
    """
    f = frames[frames["trial"].astype(str) == trial]
    methods = methods or list(dict.fromkeys(f["method"].astype(str)))
    fig, axes = plt.subplots(1, len(methods), figsize=(4.6 * len(methods), 3.0),
                             squeeze=False, sharex=True, sharey=True)
    for ax, m in zip(axes[0], methods):
        d = f[f["method"].astype(str) == m]
        for side in ("L", "R"):
            s = d[d["side"].astype(str) == side]
            ax.plot(s["xs_m"], s["ys_m"], "-", color="0.6", lw=2.5,
                    label="VICON" if side == "L" else None)
            ax.plot(s["x_m"], s["y_m"], "-", color=COLORS[side], lw=0.8,
                    label=f"LRS {side}")
            uo = s[s["pattern"].astype(str) == "UO"]
            ax.plot(uo["x_m"], uo["y_m"], "o", mfc="none", ms=3, color=COLORS[side])
        ax.set_title(m)
        ax.set_xlabel("x (sensor frame) [m]")
        ax.set_aspect("equal", adjustable="box")
        ax.grid(True, lw=0.3)
    axes[0][0].set_ylabel("y (sensor frame) [m]")
    axes[0][0].legend(fontsize=7, loc="best")
    fig.suptitle(f"Leg trajectories, trial {trial} (open circles: unobservable, UO)")
    fig.tight_layout()
    return save_figure(fig, path)


def plot_false_tracking(frames: pd.DataFrame, event: pd.Series, path: str | Path,
                        pad_s: float = 1.0) -> Path:
    """x(t) and y(t) of both legs around one false-tracking event, tracks vs truth."""
    f = frames[(frames["trial"].astype(str) == str(event["trial"]))
               & (frames["method"].astype(str) == str(event["method"]))]
    t0, t1 = event["t_start_s"] - pad_s, event["t_end_s"] + pad_s
    f = f[(f["t_sensor_s"] >= t0) & (f["t_sensor_s"] <= t1)]
    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for ax, (c, ct) in zip(axes, (("x_m", "xs_m"), ("y_m", "ys_m"))):
        for side in ("L", "R"):
            s = f[f["side"].astype(str) == side]
            ax.plot(s["t_sensor_s"], s[ct], "-", color=COLORS[side], lw=2.5, alpha=0.35,
                    label=f"VICON {side}")
            ax.plot(s["t_sensor_s"], s[c], "-", color=COLORS[side], lw=0.9,
                    label=f"LRS {side}")
        ax.axvspan(event["t_start_s"], event["t_end_s"], color="0.85", zorder=0)
        ax.set_ylabel(f"{c[0]} (sensor frame) [m]")
        ax.grid(True, lw=0.3)
    axes[0].legend(fontsize=7, ncol=4)
    axes[1].set_xlabel("t (sensor clock) [s]")
    fig.suptitle(f"False tracking ({event['kind']}, {event['tug_phase']}): trial "
                 f"{event['trial']}, {event['method']}, leg {event['side']}")
    fig.tight_layout()
    return save_figure(fig, path)


def write_tug_figures(frames: pd.DataFrame, summaries: pd.DataFrame, events: pd.DataFrame,
                      out_dir: str | Path) -> list[Path]:
    """``tug_trajectories.png`` (the first trial, sorted by id, that every method tracked
    successfully, else the first trial) and ``tug_false_tracking.png`` (the first swap or
    lost event of the lowest-numbered method with any) when false tracking occurred."""
    out = Path(out_dir)
    paths = []
    s = summaries
    trials = sorted(s["trial"].astype(str).unique())
    if trials:
        ok = s.groupby("trial")["success"].all()
        good = [t for t in trials if ok.get(t, False)]
        paths.append(plot_trial_trajectories(frames, (good or trials)[0],
                                             out / "tug_trajectories.png"))
    ft = events[events["kind"].isin(["swap", "lost"])] if events is not None else None
    if ft is not None and len(ft):
        ev = ft.sort_values(["method", "trial", "t_start_s"], kind="stable").iloc[0]
        paths.append(plot_false_tracking(frames, ev, out / "tug_false_tracking.png"))
    return paths
