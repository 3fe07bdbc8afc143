"""Seed 000's example figures of a tracking situation (Yorozu et al., Sensors 2015,
Figs. 12 and 13) from the run's TUG evaluations and scans.

- :func:`figure12` — like Figure 12 (a leg hidden and the scan disturbed during the turn;
  Method 1's GNN association against Method 2's gait-phase association): scan snapshots
  (:mod:`gaitval.report.paper_figures_scans`) around the first false tracking of Method 1
  in the turning phase (:func:`pick_fig12_event`), one row per method.
- :func:`figure13` — like Figure 13 (the left leg hidden; Method 2 without interpolation
  against Method 3 with it): the hidden leg's path during the run's longest occlusion in
  the turning phase (:func:`pick_occlusion`), tracked against mocap, top view per method,
  and its position error over time.

The paper's panels also draw the gates; the track files do not keep them
(:mod:`gaitval.report.paper_figures_scans`).  The observed leg positions y_k^j are drawn
when ``obs_of`` gives them.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import plt, save_figure
from gaitval.report.paper_figures_scans import LEG_COLOURS, nearest_scan, snapshot_figure

M1, M2, M3 = "tug_m1", "tug_m2", "tug_m3"


def pick_fig12_event(events: pd.DataFrame, summaries: pd.DataFrame, m_a: str = M1,
                     m_b: str = M2) -> pd.Series | None:
    """The false tracking (swap or lost) of ``m_a`` the figure shows: in the turning phase
    of a trial ``m_b`` tracked successfully if there is one, else in the turning phase,
    else any; the earliest (trial, start time) of the best kind.  None when ``m_a`` has
    no false tracking."""
    if events is None or events.empty:
        return None
    ev = events[(events["method"].astype(str) == m_a)
                & events["kind"].astype(str).isin(["swap", "lost"])].copy()
    if ev.empty:
        return None
    ok_b = set(summaries.loc[(summaries["method"].astype(str) == m_b)
                             & summaries["success"].astype(bool), "trial"].astype(str))
    ev["rank"] = [(0 if ph == "turning" else 1) + (0 if str(tr) in ok_b else 2)
                  for ph, tr in zip(ev["tug_phase"].astype(str), ev["trial"].astype(str))]
    ev["trial"] = ev["trial"].astype(str)
    return ev.sort_values(["rank", "trial", "t_start_s"], kind="stable").iloc[0]


def uo_runs(f: pd.DataFrame) -> pd.DataFrame:
    """Runs of consecutive UO scans of each (trial, method, side): ``trial, method, side,
    k_start, k_end, n, t_start_s, t_end_s, tug_phase`` (the phase of the run's first scan;
    "" without a ``tug_phase`` column)."""
    rows = []
    for (tr, m, side), g in f.groupby(["trial", "method", "side"], sort=True):
        g = g.sort_values("k")
        uo = (g["pattern"].astype(str) == "UO").to_numpy()
        k = g["k"].to_numpy()
        i = 0
        while i < len(uo):
            if not uo[i]:
                i += 1
                continue
            j = i
            while j + 1 < len(uo) and uo[j + 1] and k[j + 1] == k[j] + 1:
                j += 1
            rows.append({"trial": str(tr), "method": str(m), "side": str(side),
                         "k_start": int(k[i]), "k_end": int(k[j]), "n": j - i + 1,
                         "t_start_s": float(g["t_sensor_s"].iloc[i]),
                         "t_end_s": float(g["t_sensor_s"].iloc[j]),
                         "tug_phase": (str(g["tug_phase"].iloc[i]) if "tug_phase" in g
                                       else "")})
            i = j + 1
    return pd.DataFrame(rows, columns=["trial", "method", "side", "k_start", "k_end", "n",
                                       "t_start_s", "t_end_s", "tug_phase"])


def pick_occlusion(frames: pd.DataFrame, method: str = M2) -> pd.Series | None:
    """``method``'s longest run of UO scans of one leg, in the turning phase if any (ties:
    the left leg, as the paper's, then trial and time); None without a UO scan."""
    f = frames[frames["method"].astype(str) == method]
    runs = uo_runs(f) if len(f) else pd.DataFrame()
    if runs.empty:
        return None
    runs["rank"] = (runs["tug_phase"] != "turning").astype(int)
    runs["right"] = (runs["side"] != "L").astype(int)
    runs = runs.sort_values(["rank", "n", "right", "trial", "k_start"],
                            ascending=[True, False, True, True, True], kind="stable")
    return runs.iloc[0]


def figure12(frames: pd.DataFrame, events: pd.DataFrame, summaries: pd.DataFrame, scans_of,
             path: str | Path, m_a: str = M1, m_b: str = M2, obs_of=None) -> Path | None:
    """Scan snapshots of ``m_a`` and ``m_b`` around :func:`pick_fig12_event`, or, when
    ``m_a`` never tracked falsely, around ``m_b``'s first false tracking, else around
    ``m_a``'s longest occlusion in the turn (the title says which).  ``scans_of(trial)`` returns the trial's ScanSeries.  None when
    the run has no frame of ``m_a``."""
    ev = pick_fig12_event(events, summaries, m_a, m_b)
    other = pick_fig12_event(events, summaries, m_b, m_a) if ev is None else None
    if ev is not None:
        trial, t0 = str(ev["trial"]), float(ev["t_start_s"])
        what = (f"first false tracking ({ev['kind']}, leg {ev['side']}, {ev['tug_phase']} "
                f"phase) of {m_a}")
    elif other is not None:
        trial, t0 = str(other["trial"]), float(other["t_start_s"])
        what = (f"no false tracking of {m_a} in this run; the first of {m_b} "
                f"({other['kind']}, leg {other['side']}, {other['tug_phase']} phase)")
    else:
        occ = pick_occlusion(frames, m_a)
        if occ is None:
            return None
        trial, t0 = str(occ["trial"]), float(occ["t_start_s"])
        what = (f"no false tracking of {m_a} in this run: its longest occlusion "
                f"(leg {occ['side']}, {occ['n']} scans, {occ['tug_phase']} phase)")
    f = frames[frames["trial"].astype(str) == trial]
    scans = scans_of(trial)
    k0 = nearest_scan(scans.t, t0)
    times = [float(scans.t[k]) for k in (k0 - 2, k0 - 1, k0, k0 + 1, k0 + 6)
             if 0 <= k < scans.n_scans]
    rows = [(m, f[f["method"].astype(str) == m]) for m in (m_a, m_b)
            if (f["method"].astype(str) == m).any()]
    title = (f"TUG trial {trial}: {what} — rows {', '.join(m for m, _ in rows)} "
             "(cf. Yorozu et al. 2015 Fig. 12)\ngates not drawn: the track files do not "
             "keep them")
    obs = {m: obs_of(trial, m) for m, _ in rows} if obs_of is not None else None
    return snapshot_figure(scans, rows, times, path, title=title,
                           observations={m: o for m, o in (obs or {}).items()
                                         if o is not None})


def figure13(frames: pd.DataFrame, path: str | Path, m_a: str = M2, m_b: str = M3,
             pad_s: float = 0.6) -> Path | None:
    """The hidden leg of :func:`pick_occlusion` (of ``m_a``) tracked by ``m_a`` and
    ``m_b`` against mocap: top views (left, middle) and the position error over time
    (right), the occlusion shaded.  None without a UO scan of ``m_a``."""
    occ = pick_occlusion(frames, m_a)
    if occ is None:
        return None
    trial, side = str(occ["trial"]), str(occ["side"])
    t0, t1 = float(occ["t_start_s"]) - pad_s, float(occ["t_end_s"]) + pad_s
    f = frames[(frames["trial"].astype(str) == trial)
               & frames["t_sensor_s"].between(t0, t1)]
    methods = [m for m in (m_a, m_b) if (f["method"].astype(str) == m).any()]
    fig, axes = plt.subplots(1, len(methods) + 1, figsize=(4.2 * (len(methods) + 1), 4.3))
    col = LEG_COLOURS.get(side, "k")
    for ax, m in zip(axes, methods):
        d = f[(f["method"].astype(str) == m) & (f["side"].astype(str) == side)]
        d = d.sort_values("k")
        ax.plot(d["xs_m"], d["ys_m"], "-", color="0.6", lw=3, label="mocap (VICON)")
        ax.plot(d["x_m"], d["y_m"], ".-", color=col, lw=0.9, ms=3,
                label=f"tracked ({m})")
        uo = d[d["pattern"].astype(str) == "UO"]
        ax.plot(uo["x_m"], uo["y_m"], "o", mfc="none", color=col, ms=6,
                label="unobservable (UO)")
        itp = d[d["interpolated"].astype(bool)] if "interpolated" in d else d.iloc[:0]
        if len(itp):
            ax.plot(itp["x_m"], itp["y_m"], "+", color="k", ms=7,
                    label="virtual observation (Catmull–Rom)")
        ax.set_title(f"{m}", fontsize=9)
        ax.set_xlabel("x (sensor frame) [m]")
        ax.set_ylabel("y (sensor frame) [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="best")
    ax = axes[-1]
    for m, ls in zip(methods, ("-", "--")):
        d = f[(f["method"].astype(str) == m) & (f["side"].astype(str) == side)]
        d = d.sort_values("k")
        err = 100.0 * np.hypot(d["x_m"] - d["xs_m"], d["y_m"] - d["ys_m"])
        ax.plot(d["t_sensor_s"], err, ls, color="k" if ls == "-" else "tab:green", lw=1.1,
                label=m)
    ax.axvspan(float(occ["t_start_s"]), float(occ["t_end_s"]), color="0.88", zorder=0,
               label=f"{m_a}'s occlusion ({occ['n']} scans)")
    ax.set_xlabel("t (sensor clock) [s]")
    ax.set_ylabel(f"{side} leg position error [cm]")
    ax.set_title("error against mocap", fontsize=9)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    fig.suptitle(f"TUG trial {trial}, leg {side} hidden for {occ['n']} scans "
                 f"({occ['tug_phase']} phase, the longest occlusion of {m_a}): {m_a} vs "
                 f"{m_b} (cf. Yorozu et al. 2015 Fig. 13)", fontsize=9.5)
    fig.tight_layout()
    return save_figure(fig, path)


def write_tug_paper_figures(frames: pd.DataFrame, events: pd.DataFrame,
                            summaries: pd.DataFrame, scans_of, out_dir, obs_of=None
                            ) -> list[Path]:
    """``tug_fig12.png`` and ``tug_fig13.png`` (those the run's methods allow)."""
    out = Path(out_dir)
    paths = [figure12(frames, events, summaries, scans_of, out / "tug_fig12.png",
                      obs_of=obs_of),
             figure13(frames, out / "tug_fig13.png")]
    return [p for p in paths if p is not None]
