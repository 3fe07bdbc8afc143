"""TUG leg-tracking figures: tracked vs true trajectories of a successful and a failed trial
(Yorozu et al. 2015a Fig. 14 style) and a false-tracking example (Fig. 11 style), from the evaluation
frames.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (Yorozu et al. 2015a).
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from gaitval.report.figures import (clip_to_reference, save_figure,  # noqa: E402
                                    statement_figure)

COLORS = {"L": "tab:blue", "R": "tab:red"}


def main_methods(methods) -> list[str]:
    """The methods without their reading variants (``<m>_<reading>`` beside ``<m>``)."""
    ms = list(dict.fromkeys(map(str, methods)))
    return [m for m in ms if not any(m != o and m.startswith(o + "_") for o in ms)]


def pick_trials(summaries: pd.DataFrame) -> tuple[str | None, str | None]:
    """(successful, failed) trial for the trajectory figure, judged on the main methods
    (:func:`main_methods`): the trial the most methods tracked successfully and the one
    the most failed (ties by id), two different trials when the run has two; None where
    no method succeeded, or none failed."""
    s = summaries.assign(trial=summaries["trial"].astype(str),
                         method=summaries["method"].astype(str))
    s = s[s["method"].isin(main_methods(s["method"]))]
    if s.empty:
        return None, None
    ok = s["success"].astype(bool)
    n_ok = ok.groupby(s["trial"]).sum()
    n_bad = (~ok).groupby(s["trial"]).sum()
    good = sorted((t for t in n_ok.index if n_ok[t]), key=lambda t: (-n_ok[t], t))
    bad = sorted((t for t in n_bad.index if n_bad[t]), key=lambda t: (-n_bad[t], t))
    g = good[0] if good else None
    b = next((t for t in bad if t != g), bad[0] if bad and g is None else None)
    return g, b


def plot_trial_trajectories(frames: pd.DataFrame, trial: str | list[str], path: str | Path,
                            methods: list[str] | None = None,
                            summaries: pd.DataFrame | None = None) -> Path:
    """Top view of both legs' tracks (per method, columns) against the ground truth of one
    or more trials (rows); with ``summaries`` each panel says whether the method tracked
    the trial successfully.

    ``frames``: concatenated evaluation frames (columns of
    :data:`gaitval.evaluate.tug.FRAME_COLUMNS`).  UO steps are drawn as open circles.
    """
    rows = [trial] if isinstance(trial, str) else list(trial)
    sel = frames[frames["trial"].astype(str).isin(rows)]
    methods = methods or list(dict.fromkeys(sel["method"].astype(str)))
    fig, axes = plt.subplots(len(rows), len(methods),
                             figsize=(4.6 * len(methods), 3.0 * len(rows)), squeeze=False)
    for r, tr in enumerate(rows):
        _trial_row(axes[r], frames[frames["trial"].astype(str) == tr], tr, methods,
                   summaries)
    axes[0][0].legend(fontsize=7, loc="best")
    what = ("a successful and a failed trial" if len(rows) == 2 else f"trial {rows[0]}")
    fig.suptitle(f"Leg trajectories, tracked (LRS) vs true (VICON): {what} "
                 "(open circles: unobservable, UO)")
    fig.tight_layout(h_pad=2.0)          # room for a row's x label above the next titles
    return save_figure(fig, path)


def _outcome(summaries: pd.DataFrame | None, trial: str, method: str) -> str:
    if summaries is None:
        return ""
    s = summaries[(summaries["trial"].astype(str) == trial)
                  & (summaries["method"].astype(str) == method)]
    if s.empty:
        return ""
    return ": success" if bool(s["success"].iloc[0]) else ": FAILED"


def _trial_row(axes, f: pd.DataFrame, trial: str, methods, summaries) -> None:
    for ax, m in zip(axes, methods):
        d = f[f["method"].astype(str) == m]
        for side in ("L", "R"):
            s = d[d["side"].astype(str) == side]
            ax.plot(s["xs_m"], s["ys_m"], "-", color="0.6", lw=2.5,
                    label="VICON" if side == "L" else None)
            ax.plot(s["x_m"], s["y_m"], "-", color=COLORS[side], lw=0.8,
                    label=f"LRS {side}")
            uo = s[s["pattern"].astype(str) == "UO"]
            ax.plot(uo["x_m"], uo["y_m"], "o", mfc="none", ms=3, color=COLORS[side])
        ax.set_title(f"{trial}, {m}{_outcome(summaries, trial, m)}", fontsize=9)
        ax.set_xlabel("x (sensor frame) [m]")
        ax.set_aspect("equal", adjustable="box")
        # the VICON legs set the limits; a diverged track is clipped, and the panel says so
        clip_to_reference(ax, [d["xs_m"]], [d["ys_m"]], [d["x_m"]], [d["y_m"]],
                          what="LRS track")
        ax.grid(True, lw=0.3)
    axes[0].set_ylabel("y (sensor frame) [m]")


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
    """``tug_trajectories.png``: a successful and a failed trial (:func:`pick_trials`; one
    row each, one column per method, each panel saying success or FAILED; the first trial
    alone when the run has neither kind) and ``tug_false_tracking.png`` (the first swap or
    lost event of the lowest-numbered method with any) when false tracking occurred."""
    out = Path(out_dir)
    paths = []
    trials = sorted(summaries["trial"].astype(str).unique())
    if trials:
        good, bad = pick_trials(summaries)
        rows = [t for t in (good, bad) if t is not None] or trials[:1]
        paths.append(plot_trial_trajectories(frames, rows, out / "tug_trajectories.png",
                                             methods=main_methods(summaries["method"]),
                                             summaries=summaries))
    else:
        paths.append(statement_figure(out / "tug_trajectories.png", "tug_trajectories: not "
                                      "drawn — no TUG trial was analysed (every trial was "
                                      "refused at registration; the report's top box says "
                                      "why)"))
    ft = events[events["kind"].isin(["swap", "lost"])] if events is not None else None
    if ft is not None and len(ft):
        ev = ft.sort_values(["method", "trial", "t_start_s"], kind="stable").iloc[0]
        paths.append(plot_false_tracking(frames, ev, out / "tug_false_tracking.png"))
    return paths
