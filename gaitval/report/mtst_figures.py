"""MTST figure (seed 001 Fig. 10 style): one trial on the mat — both tracked legs, the foot
contacts, the targets, the target steps judged ("O") and the cross steps detected ("+").

References
----------
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (seed 001), Figure 10.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from gaitval.report.figures import save_figure  # noqa: E402

LEG_COLORS = {"L": "tab:blue", "R": "tab:red"}
TARGET_COLORS = {"red": "#d62728", "blue": "#1f77b4", "white": "#ffffff"}
METHOD = "mtst_proposed"


def pick_trial(summary: pd.DataFrame, contacts: pd.DataFrame, method: str = METHOD
               ) -> str | None:
    """The figure's trial: the first (by id) the method tracked successfully that has a
    detected cross step, else the first successful one, else the first."""
    s = summary[summary["method"] == method] if len(summary) else summary
    if s.empty:
        return None
    ok = s[np.where(s["has_mocap"].astype(bool), s["category_mocap"] == "success",
                    s["category_annotations"] == "success")]
    c = contacts[(contacts["method"] == method) & contacts["cross"].astype(bool)] \
        if len(contacts) else contacts
    for pool in (sorted(set(ok["trial"]) & set(c.get("trial", []))), sorted(ok["trial"]),
                 sorted(s["trial"])):
        if pool:
            return str(pool[0])
    return None


def _mat(ax, targets: pd.DataFrame, size=(0.165, 0.160), mat=None) -> None:
    mat = mat or {"start_m": [0.0, 0.0], "goal_m": [5.85, 0.0], "width_m": 1.15}
    (x0, y0), (x1, _) = mat["start_m"], mat["goal_m"]
    w = mat["width_m"]
    ax.add_patch(Rectangle((x0, y0 - w / 2), x1 - x0, w, fc="0.93", ec="0.6", lw=0.8,
                           zorder=0))
    for t in targets.itertuples(index=False):
        ax.add_patch(Rectangle((t.x_m - size[0] / 2, t.y_m - size[1] / 2), size[0], size[1],
                               fc=TARGET_COLORS.get(str(t.color), "0.8"),
                               ec="k" if t.assigned else "0.5",
                               lw=1.6 if t.assigned else 0.5, zorder=1))


def plot_mtst_trial(data: dict[str, pd.DataFrame], trial: str, path: str | Path,
                    method: str = METHOD) -> Path:
    """Top view of one trial in the field frame (see the module docstring)."""
    def sel(name):
        d = data.get(name, pd.DataFrame())
        if d.empty:
            return d
        d = d[d["trial"].astype(str) == trial]
        return d[d["method"] == method] if "method" in d else d

    tr, c, tg = sel("track_field"), sel("contacts"), sel("targets")
    fig, ax = plt.subplots(figsize=(11, 3.2))
    if len(tg):
        _mat(ax, tg.drop_duplicates("target"))
    for side in ("L", "R"):
        s = tr[tr["side"] == side] if len(tr) else tr
        if len(s):
            ax.plot(s["x_m"], s["y_m"], "-", color=LEG_COLORS[side], lw=0.8,
                    label=f"{side} leg (tracked)")
        cs = c[c["side"] == side] if len(c) else c
        if len(cs):
            ax.plot(cs["x_m"], cs["y_m"], "o", ms=3.5, color=LEG_COLORS[side])
            on = cs[cs["target"].astype(str) != ""]
            ax.plot(on["x_m"], on["y_m"], "o", ms=14, mfc="none", mec="k", mew=1.4,
                    label="target step judged (O)" if side == "L" else None)
            cr = cs[cs["cross"].astype(bool)]
            ax.plot(cr["x_m"], cr["y_m"], "+", ms=16, mew=2.0, color="k",
                    label="cross step detected (+)" if side == "L" else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the mat (m, field frame)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"{trial}, {method}: tracked legs, foot contacts (dots), assigned targets "
                 "(bold outline)", fontsize=9)
    ax.legend(loc="upper left", fontsize=7, ncol=4, frameon=False,
              bbox_to_anchor=(0.0, -0.25))
    return save_figure(fig, path)


def write_mtst_figure(data: dict[str, pd.DataFrame], figures_dir, *, trial: str | None = None
                      ) -> list[Path]:
    """``mtst_trial.png`` of ``trial`` (default :func:`pick_trial`); [] without trials."""
    trial = trial or pick_trial(data.get("summary", pd.DataFrame()),
                                data.get("contacts", pd.DataFrame()))
    if trial is None:
        return []
    return [plot_mtst_trial(data, trial, Path(figures_dir) / "mtst_trial.png")]
