"""Figure of annotated recordings: tracked vs annotated person over time.

One row per method, two panels (x forward, y left of the laser, m): the hand-annotated
person (black), and the tracker's person (leg midpoint) for each initialisation; scans
the CLEAR-MOT counted as a miss are marked below the curves.  The axes show the laser's
reach (x -1..6 m, y -3..3 m): a tracker that lost the legs and keeps predicting runs far
outside it (off-scale).  The figure is drawn for
the first trial (trials sorted by name).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import plt, save_figure

COLOURS = {"own": "tab:orange", "annotation": "tab:blue"}


def write_legbench_figure(frames: dict, summary: pd.DataFrame, path, methods=None,
                          inits=None) -> Path:
    """``frames``: (trial, method, init) -> frames.parquet table of the evaluation."""
    trial = sorted({k[0] for k in frames})[0]
    methods = [m for m in (methods or sorted({k[1] for k in frames}))
               if any(k[:2] == (trial, m) for k in frames)]
    inits = list(inits or sorted({k[2] for k in frames}))
    fig, axes = plt.subplots(len(methods), 2, figsize=(13, 1.9 * len(methods) + 0.6),
                             sharex=True, squeeze=False)
    for row, m in enumerate(methods):
        first = True
        for i in inits:
            f = frames.get((trial, m, i))
            if f is None:
                continue
            s = summary[(summary["trial"] == trial) & (summary["method"] == m)
                        & (summary["init"] == i)].iloc[0]
            for col, q in enumerate("xy"):
                ax = axes[row, col]
                if first:
                    ax.plot(f["t_s"], f[f"gt_{q}_m"], ".", color="black", ms=1.5,
                            label="annotated person")
                ax.plot(f["t_s"], f[f"hyp_{q}_m"], "-", color=COLOURS.get(i, "tab:green"),
                        lw=0.7, label=f"{i} init: MOTA {s['mota']:.2f}, IDF1 {s['idf1']:.2f}")
                miss = f["event"].to_numpy() == "MISS"
                lo = -0.4 if q == "y" else 0.0
                off = inits.index(i) * 0.15
                ax.plot(f["t_s"].to_numpy()[miss], np.full(miss.sum(), lo - 0.3 - off), "|",
                        color=COLOURS.get(i, "tab:green"), ms=3)
            first = False
        for col, lim in enumerate(((-1.0, 6.0), (-3.0, 3.0))):
            axes[row, col].set_ylim(*lim)     # the laser's reach (5.6 m); beyond: off-scale
        axes[row, 0].set_ylabel(f"{m}\nx (m)")
        axes[row, 1].set_ylabel("y (m)")
        axes[row, 1].legend(loc="upper right", fontsize=6, markerscale=4)
    for ax in axes[-1]:
        ax.set_xlabel("time from the first scan (s)")
    fig.suptitle(f"{trial}: tracked (leg midpoint) vs annotated person; ticks below: "
                 "misses; estimates beyond the laser's reach are off-scale", fontsize=9)
    return save_figure(fig, path)
