"""Seed 001's data figures besides Fig. 10 (Yorozu et al., Sensors 2015, MTST), from the
run's MTST evaluations and scans.

- :func:`figure6a` — like Figure 6a (observed leg positions when the participant stepped
  around a target): every foot contact of the proposed method near an assigned target,
  relative to the target's centre (along and across the walking direction), the target
  (its configured size) and the judgement region of §2.5.2 / Fig. 6c for a participant of
  ``mtst.foot.default_height_m`` (the region grows with height; each trial was judged
  with its participant's own).
- :func:`figure8` — like Figure 8 (a leg temporarily hidden; Method 1 without the FS_U
  pattern against Method 2 with it): scan snapshots around the first tracking failure of
  Method 1 in a trial Method 2 tracked successfully (:func:`pick_event`).
- :func:`figure9` — like Figure 9 (both legs close together; Method 2's large fixed
  validation region against the proposed variable one): scan snapshots around the first
  false tracking by switching of Method 2 in a trial the proposed method tracked
  successfully; each panel of the proposed method gives its gate radii at that scan (the
  evaluation's ``gates`` table), Method 2's radius is fixed (1.5 w_l).

Where the run has no such failure the snapshot falls back to the method's longest
occlusion, else to the scan where the true legs were closest, and its title says so.
Each method's observations (its detector run again on the trial, with or without FS_U)
are drawn with their patterns.  Gates are not drawn as circles: the track keeps no
predicted position to centre them on (:mod:`gaitval.report.paper_figures_scans`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import plt, save_figure
from gaitval.report.paper_figures_scans import snapshot_figure
from gaitval.report.paper_figures_tug import uo_runs

PROPOSED = "mtst_proposed"


def _ok_trials(summary: pd.DataFrame, method: str) -> set[str]:
    if summary is None or summary.empty:
        return set()
    s = summary[(summary["method"].astype(str) == method)
                & (summary["category_mocap"].astype(str) == "success")]
    return set(s["trial"].astype(str))


def pick_event(events: pd.DataFrame, summary: pd.DataFrame, method: str, other: str,
               kinds: tuple[str, ...]) -> pd.Series | None:
    """``method``'s first mocap-judged event of one of ``kinds`` (the earliest by trial and
    time), in a trial ``other`` tracked successfully when there is one; None without."""
    if events is None or events.empty:
        return None
    ev = events[(events["method"].astype(str) == method)
                & events["kind"].astype(str).isin(kinds)
                & (events["reference"].astype(str) == "mocap")].copy()
    if ev.empty:
        return None
    ok = _ok_trials(summary, other)
    ev["trial"] = ev["trial"].astype(str)
    ev["rank"] = [0 if t in ok else 1 for t in ev["trial"]]
    return ev.sort_values(["rank", "trial", "t_start_s"], kind="stable").iloc[0]


def _longest_uo(tracks: pd.DataFrame, method: str) -> pd.Series | None:
    t = tracks[tracks["method"].astype(str) == method]
    if t.empty:
        return None
    runs = uo_runs(t)
    if runs.empty:
        return None
    return runs.sort_values(["n", "trial", "k_start"], ascending=[False, True, True],
                            kind="stable").iloc[0]


def _closest_legs(tracks: pd.DataFrame, method: str, truth_of
                  ) -> tuple[str, float, float] | None:
    """(trial, time, distance) where the true legs were closest, over the trials
    ``method`` tracked (by id); None without ground truth."""
    best = None
    for trial in sorted(tracks.loc[tracks["method"].astype(str) == method, "trial"]
                        .astype(str).unique()):
        g = truth_of(trial)
        if g is None or g.empty:
            continue
        w = g.pivot_table(index="t_sensor_s", columns="side", values=["xs_m", "ys_m"])
        if w.empty or ("xs_m", "L") not in w or ("xs_m", "R") not in w:
            continue
        d = np.hypot(w[("xs_m", "L")] - w[("xs_m", "R")], w[("ys_m", "L")] - w[("ys_m", "R")])
        d = d[np.isfinite(d)]
        if len(d) and (best is None or float(d.min()) < best[2]):
            best = (trial, float(d.idxmin()), float(d.min()))
    return best


def _snapshots(tracks, events, summary, scans_of, truth_of, path, m_a, m_b, kinds,
               situation, fig_no, notes=None, obs_of=None) -> Path | None:
    ev = pick_event(events, summary, m_a, m_b, kinds)
    if ev is not None:
        trial, t0 = str(ev["trial"]), float(ev["t_start_s"])
        what = f"first {ev['kind']} of {m_a} (leg {ev['side']}, judged against mocap)"
    else:
        occ = _longest_uo(tracks, m_a)
        close = _closest_legs(tracks, m_a, truth_of) if occ is None else None
        if occ is not None:
            trial, t0 = str(occ["trial"]), float(occ["t_start_s"])
            what = (f"no {' or '.join(kinds)} of {m_a} in this run: its longest occlusion "
                    f"(leg {occ['side']}, {occ['n']} scans)")
        elif close is not None:
            trial, t0, d = close
            what = (f"no {' or '.join(kinds)} of {m_a} and no occlusion in this run: the "
                    f"scan where the true legs were closest ({100 * d:.1f} cm apart)")
        else:
            return None
    scans = scans_of(trial)
    if scans is None:
        return None
    t = tracks[tracks["trial"].astype(str) == trial]
    rows = [(m, t[t["method"].astype(str) == m]) for m in (m_a, m_b)
            if (t["method"].astype(str) == m).any()]
    dt = float(np.median(np.diff(np.unique(rows[0][1]["t_sensor_s"])))) if rows else 0.05
    times = [t0 + i * dt for i in (-6, -3, -1, 0, 3)]
    title = (f"MTST trial {trial}, {situation}: {what} — rows {', '.join(m for m, _ in rows)} "
             f"(cf. Yorozu et al. 2015, MTST, Fig. {fig_no})\nvalidation regions not "
             "drawn: the track files do not keep them")
    obs = {m: obs_of(trial, m) for m, _ in rows} if obs_of is not None else {}
    return snapshot_figure(scans, rows, times, path, title=title, truth=truth_of(trial),
                           notes=(lambda label, k: notes(label, k, trial)) if notes else None,
                           observations={m: o for m, o in obs.items() if o is not None})


def figure8(tracks, events, summary, scans_of, truth_of, path, m_a: str = "mtst_m1",
            m_b: str = "mtst_m2", obs_of=None) -> Path | None:
    """Scan snapshots of ``m_a`` (no FS_U) and ``m_b`` around ``m_a``'s first tracking
    failure (lost, or a false track other than a switch) in a trial ``m_b`` tracked."""
    return _snapshots(tracks, events, summary, scans_of, truth_of, path, m_a, m_b,
                      ("lost", "false_other"), "a leg temporarily hidden", "8",
                      obs_of=obs_of)


def figure9(tracks, events, summary, scans_of, truth_of, gates, path, m_a: str = "mtst_m2",
            m_b: str = PROPOSED, obs_of=None) -> Path | None:
    """Scan snapshots of ``m_a`` (large fixed region) and ``m_b`` (variable region)
    around ``m_a``'s first false tracking by switching the legs in a trial ``m_b``
    tracked; ``m_b``'s panels give its gate radii at the scan (``gates``: ``trial, method,
    k, side, radius_m``)."""
    g = gates if gates is not None and len(gates) else pd.DataFrame(
        columns=["trial", "method", "k", "side", "radius_m"])

    def notes(label, k, trial):
        r = g[(g["trial"].astype(str) == trial) & (g["method"].astype(str) == label)
              & (g["k"] == k)].drop_duplicates("side").sort_values("side")
        if r.empty:
            return ""
        return "gate r: " + ", ".join(f"{s} {100 * float(v):.1f} cm" for s, v in
                                      zip(r["side"].astype(str), r["radius_m"]))
    return _snapshots(tracks, events, summary, scans_of, truth_of, path, m_a, m_b,
                      ("false_swap",), "both legs close together", "9", notes=notes,
                      obs_of=obs_of)


def figure6a(contacts: pd.DataFrame, targets: pd.DataFrame, path: str | Path, s: dict,
             method: str = PROPOSED, reach_m: float = 0.35) -> Path | None:
    """Every contact of ``method`` within ``reach_m`` of an assigned target's centre,
    relative to it; ``s``: the ``mtst`` settings (target size, mat, foot model).  None
    when no contact lies near an assigned target."""
    from gaitval.evaluate.mtst_trial import heading
    from gaitval.gait.mtst import FootModel, judgement_region

    c = contacts[contacts["method"].astype(str) == method] if len(contacts) else contacts
    tg = targets[targets["assigned"].astype(bool)] if len(targets) else targets
    if c.empty or tg.empty:
        return None
    u = heading(s["mat"])
    n = np.array([-u[1], u[0]])
    rows = []
    for (trial,), cc in c.groupby(["trial"], sort=True):
        tt = tg[tg["trial"].astype(str) == str(trial)].drop_duplicates("target")
        if tt.empty:
            continue
        ctr = tt[["x_m", "y_m"]].to_numpy(float)
        for r in cc.itertuples(index=False):
            d = np.array([r.x_m, r.y_m]) - ctr
            i = int(np.argmin(np.hypot(d[:, 0], d[:, 1])))
            if np.hypot(*d[i]) <= reach_m:
                rows.append((float(d[i] @ u), float(d[i] @ n), str(r.target) != "",
                             str(r.side)))
    if not rows:
        return None
    a, lat, on, side = (np.array(v) for v in zip(*rows))
    f = s["foot"]
    h = float(f["default_height_m"])
    foot = FootModel.for_height(h, f["length_per_height"], f["width_per_height"],
                                f["heel_per_length"])
    a_min, a_max, l_half = judgement_region(foot, tuple(s["target_size_m"]))
    L_t, W_t = s["target_size_m"]
    fig, ax = plt.subplots(figsize=(6.2, 5.6))
    ax.add_patch(plt.Rectangle((-L_t / 2 * 100, -W_t / 2 * 100), L_t * 100, W_t * 100,
                               fc="0.85", ec="k", lw=1.2, label="target"))
    ax.add_patch(plt.Rectangle((a_min * 100, -l_half * 100), (a_max - a_min) * 100,
                               2 * l_half * 100, fc="none", ec="tab:green", ls="--", lw=1.3,
                               label=f"judgement region ({h:.2f} m participant)"))
    for flag, mk, lab in ((True, "o", "judged on the target (O)"),
                          (False, "x", "not judged on it")):
        sel = on == flag
        ax.plot(100 * a[sel], 100 * lat[sel], mk, ms=5, mfc="none" if flag else None,
                color="tab:blue" if flag else "tab:red", label=f"{lab}: {int(sel.sum())}")
    ax.axhline(0, color="0.7", lw=0.5)
    ax.axvline(0, color="0.7", lw=0.5)
    ax.set_xlabel("along the walking direction, from the target's centre [cm]")
    ax.set_ylabel("across the walking direction (left +) [cm]")
    ax.set_aspect("equal")
    lim = 100 * reach_m
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=2,
              frameon=False)
    ax.set_title(f"MTST: foot contacts (shin position at contact) of {method} within "
                 f"{100 * reach_m:.0f} cm of an assigned target,\n{len(a)} contacts in "
                 f"{c['trial'].nunique()} trial(s) (cf. Yorozu et al. 2015, MTST, Fig. 6a)",
                 fontsize=9)
    fig.tight_layout()
    return save_figure(fig, path)


def write_mtst_paper_figures(data: dict[str, pd.DataFrame], tracks: pd.DataFrame, scans_of,
                             truth_of, out_dir, s: dict, obs_of=None) -> list[Path]:
    """``mtst_fig6a.png``, ``mtst_fig8.png`` and ``mtst_fig9.png`` (those the run allows).

    ``data``: the pooled evaluation tables (``contacts``, ``targets``, ``events``,
    ``summary``, ``gates``); ``tracks``: the MTST tracks (sensor frame) of the trials with
    mocap; ``scans_of(trial)`` its scans (None when not ingested) and ``truth_of(trial)``
    its ground truth (``t_sensor_s, side, xs_m, ys_m``); ``obs_of(trial, method)`` the
    method's detector's observations (None: not drawn)."""
    out = Path(out_dir)
    e = pd.DataFrame()
    ev, summ = data.get("events", e), data.get("summary", e)
    paths = [figure6a(data.get("contacts", e), data.get("targets", e),
                      out / "mtst_fig6a.png", s),
             figure8(tracks, ev, summ, scans_of, truth_of, out / "mtst_fig8.png",
                     obs_of=obs_of),
             figure9(tracks, ev, summ, scans_of, truth_of, data.get("gates"),
                     out / "mtst_fig9.png", obs_of=obs_of)]
    return [p for p in paths if p is not None]
