"""Scan snapshots: the laser points of a few consecutive scans with the tracked and the true
legs, one row per method and one column per scan — what the papers' example figures of a
tracking situation show (Yorozu et al. 2015a Fig. 12, Yorozu et al. 2015b Figs. 8 and 9, Chalvatzaki et al. 2017 Fig. 5).

What a snapshot can show is what the run keeps: the raw scan (the ingested scan log), each
method's estimate per scan and leg with its pattern (``UO``: no observation associated),
the ground truth at the scan, and the observations of the method's detector (run again on
the trial's scans by :mod:`gaitval.pipeline.paper_figures`, as the track step ran it).
The trackers' gates (validation regions) and a particle filter's particles are not
written by the tracking step, so no snapshot draws them; the callers' titles say so.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import plt, save_figure

LEG_COLOURS = {"L": "tab:blue", "R": "tab:red"}


def scan_points(scans, k: int) -> np.ndarray:
    """(n, 2) finite laser points of scan ``k`` in the sensor frame."""
    p = scans.points(int(k))
    return p[np.isfinite(p).all(axis=1)]


def nearest_scan(t: np.ndarray, t0: float) -> int:
    """Index of the scan time nearest ``t0``."""
    return int(np.argmin(np.abs(np.asarray(t, dtype=float) - float(t0))))


def snapshot_figure(scans, rows: list[tuple[str, pd.DataFrame]], times: list[float],
                    path: str | Path, *, title: str, truth: pd.DataFrame | None = None,
                    x: str = "x_m", y: str = "y_m", xt: str = "xs_m", yt: str = "ys_m",
                    half_m: float = 0.55, trail: int = 8, notes=None,
                    column_titles: list[str] | None = None,
                    observations: dict | None = None) -> Path:
    """One row per ``(label, track)`` and one column per time of ``times`` (sensor clock).

    Each ``track`` has ``k, t_sensor_s, side`` and the position columns ``x, y`` (sensor
    frame), and ``pattern`` when the tracker says whether a leg was observed; ``truth``
    (``t_sensor_s, side, xt, yt``; default: the track's own ``xt, yt`` columns) the true
    leg positions.  A panel shows the scan nearest the time: its laser points (black
    dots) in a square of ``2·half_m`` around the true legs, the true legs (large grey
    circles), each leg's estimate (×, in its colour) with its last ``trail`` scans (thin
    line); an estimate without an associated observation (``UO``) is an open square.
    ``notes(label, k)`` adds a line to a panel's title (e.g. the gate radii at scan k);
    ``column_titles`` head each column.  ``scans``, ``truth`` and each row's track may
    be lists, one per column (snapshots of different trials side by side).
    ``observations``: per row label, the method's detector's observation table
    (``t_sensor_s, x_m, y_m, pattern``; :mod:`gaitval.detect.base`) of the trial, drawn as
    green diamonds labelled with their pattern (the observations y_k^j before association).
    """
    ncol = len(times)
    fig, axes = plt.subplots(len(rows), ncol, figsize=(max(2.9 * ncol, 8.0),
                                                      2.9 * len(rows) + 1.0),
                             squeeze=False)
    for r, (label, tracks) in enumerate(rows):
        for c, t0 in enumerate(times):
            ax = axes[r][c]
            tr = _at(tracks, c)
            tru = _at(truth, c) if truth is not None else tr
            obs = (observations or {}).get(label)
            k = _panel(ax, _at(scans, c), tr, tru, float(t0), x, y, xt, yt, half_m, trail,
                       _at(obs, c) if obs is not None else None)
            extra = notes(label, k) if notes is not None and k is not None else ""
            head = f"{column_titles[c]}\n" if column_titles else ""
            ax.set_title(f"{head}{label}, t = {float(t0):.3f} s"
                         + (f"\n{extra}" if extra else ""), fontsize=7.5)
            if r == len(rows) - 1:
                ax.set_xlabel("x (sensor frame) [m]", fontsize=8)
            if c == 0:
                ax.set_ylabel("y (sensor frame) [m]", fontsize=8)
    handles = [plt.Line2D([], [], ls="none", marker=".", color="k", label="laser points"),
               plt.Line2D([], [], ls="none", marker="o", ms=11, mfc="0.85", mec="0.5",
                          label="true leg (mocap)")]
    for side in ("L", "R"):
        handles.append(plt.Line2D([], [], marker="x", color=LEG_COLOURS[side], mew=2,
                                  label=f"{side} leg estimate (line: last {trail} scans)"))
    handles.append(plt.Line2D([], [], ls="none", marker="s", mfc="none", color="0.2",
                              label="estimate with no observation (UO)"))
    if observations:
        handles.append(plt.Line2D([], [], ls="none", marker="D", mfc="none",
                                  color="tab:green", label="observed leg position (pattern)"))
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7.5, frameon=False)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0.08, 1, 0.95))
    fig.subplots_adjust(hspace=0.42)          # a row's titles clear the row above's ticks
    return save_figure(fig, path)


def _at(obj, c: int):
    """``obj[c]`` of a per-column list, else ``obj`` (the same for every column)."""
    return obj[c] if isinstance(obj, list) else obj


def _nearest_rows(df: pd.DataFrame, t0: float, tol: float = 0.06) -> pd.DataFrame:
    """Per side, the row nearest ``t0`` (within ``tol`` seconds)."""
    if df.empty:
        return df
    d = df.assign(_dt=(df["t_sensor_s"] - t0).abs())
    d = d[d["_dt"] <= tol]
    return d.sort_values("_dt", kind="stable").drop_duplicates("side").drop(columns="_dt")


def _panel(ax, scans, tr, truth, t0, x, y, xt, yt, half, trail, obs=None):
    """Draw one panel; return the track's scan index k nearest ``t0`` (None: no track)."""
    now = _nearest_rows(tr, t0)
    k = int(now["k"].iloc[0]) if len(now) else None
    tk = _nearest_rows(truth, t0)
    tk = tk[np.isfinite(tk[xt].to_numpy(float))] if len(tk) else tk
    if len(tk):
        centre = (float(tk[xt].mean()), float(tk[yt].mean()))
    elif len(now) and np.isfinite(now[x].to_numpy(float)).any():
        centre = (float(now[x].mean()), float(now[y].mean()))
    else:
        centre = (1.0, 0.0)
    pts = scan_points(scans, nearest_scan(scans.t, t0))
    near = (np.abs(pts[:, 0] - centre[0]) <= half) & (np.abs(pts[:, 1] - centre[1]) <= half)
    ax.plot(pts[near, 0], pts[near, 1], ".", color="k", ms=2.5, zorder=3)
    for row in tk.itertuples(index=False):
        ax.plot(getattr(row, xt), getattr(row, yt), "o", ms=14, mfc="0.85", mec="0.5",
                zorder=1)
    if obs is not None and len(obs):
        ts = float(scans.t[nearest_scan(scans.t, t0)])
        o = obs[(obs["t_sensor_s"] - ts).abs() < 1e-6]
        ax.plot(o["x_m"], o["y_m"], "D", ms=6, mfc="none", mec="tab:green", mew=1.3,
                zorder=6)
        for r in o.itertuples(index=False):
            ax.annotate(str(r.pattern), (r.x_m, r.y_m), textcoords="offset points",
                        xytext=(5, -9), fontsize=6, color="tab:green", zorder=7)
    for side in ("L", "R"):
        if k is None:
            break
        s = tr[(tr["side"].astype(str) == side) & (tr["k"] <= k) & (tr["k"] > k - trail)]
        s = s.sort_values("k")
        col = LEG_COLOURS[side]
        ax.plot(s[x], s[y], "-", color=col, lw=0.8, zorder=4)
        cur = s[s["k"] == k]
        if len(cur):
            uo = "pattern" in cur and str(cur["pattern"].iloc[0]) == "UO"
            ax.plot(cur[x], cur[y], "s" if uo else "x", color=col, ms=8 if uo else 9,
                    mfc="none", mew=2, zorder=5)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)
    ax.grid(True, lw=0.3)
    return k
