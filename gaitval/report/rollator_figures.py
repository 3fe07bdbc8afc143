"""Chalvatzaki et al. 2017 figure: a successful and a failed trial, both trackers' legs against the truth
(cf. its Fig. 4).

Per trial the paper's Fig. 4 panels: lateral and forward position of the left and the
right leg over time, in the rollator frame (origin at the centre of the four rollator
markers, x forward along the rollator, y to its left; the laser mount converts the laser
frame), truth red (thick), KF black, PF blue; grey bands mark the scans the KF got wrong
(error frames of Table II) and dotted lines its re-initialisations.

Success and failure are judged on the KF (the baseline the paper's Table II counts error
frames and re-initialisations of): a trial *failed* when the KF was in error at any
evaluated scan or was re-initialised.  The failed row is the trial with the largest share
of KF error frames (ties: more re-initialisations, then subject, trial); the successful
row the trial with the smallest share (ties: fewer re-initialisations, a ``straight``
trial — Scenario 1, 3 m, a 180° turn, 3 m back, the paper's turning trial — then subject,
trial), a different trial from the failed one; when every trial failed it is drawn as the
best trial and says so.  ``rollator.figure_trial`` takes the place of the automatic pick
of its own outcome.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import clip_to_reference, plt, save_figure

COLOURS = {"truth": "tab:red", "kf": "black", "pf": "tab:blue"}


def trial_outcomes(frames: pd.DataFrame, tracker: str) -> pd.DataFrame:
    """Per trial of ``tracker``: ``trial, subject, scenario, n_evaluated, n_error,
    error_pct, restarts, failed`` (from the evaluation frames, as Table II counts them)."""
    f = frames[frames["tracker"] == tracker]
    cols = ["trial", "subject", "scenario", "n_evaluated", "n_error", "error_pct",
            "restarts", "failed"]
    if f.empty:
        return pd.DataFrame(columns=cols)
    g = f.assign(ev=f["status"] == "evaluated", err=f["error"].astype(bool),
                 rs=f["restart"].astype(bool)).groupby("trial", sort=True)
    out = pd.DataFrame({"subject": g["subject"].first().astype(str),
                        "scenario": g["scenario"].first().astype(str),
                        "n_evaluated": g["ev"].sum().astype(int),
                        "n_error": g["err"].sum().astype(int),
                        "restarts": g["rs"].sum().astype(int)}).reset_index()
    out["error_pct"] = np.where(out["n_evaluated"] > 0,
                                100.0 * out["n_error"] / out["n_evaluated"].clip(lower=1),
                                np.nan)
    out["failed"] = (out["n_error"] > 0) | (out["restarts"] > 0)
    return out[cols]


def pick_trials(frames: pd.DataFrame, kf: str, trial: str | None = None
                ) -> tuple[str | None, str | None]:
    """(successful, failed) trial of the figure (module notes); None where there is none."""
    o = trial_outcomes(frames, kf)
    if o.empty:
        return None, None
    o = o.assign(pct=o["error_pct"].fillna(np.inf), turn=o["scenario"] != "straight")
    bad = o[o["failed"]].sort_values(["pct", "restarts", "subject", "trial"],
                                     ascending=[False, False, True, True])
    b = str(bad["trial"].iloc[0]) if len(bad) else None
    good = o[o["trial"] != b].sort_values(["pct", "restarts", "turn", "subject", "trial"])
    g = str(good["trial"].iloc[0]) if len(good) else None
    if trial and trial in set(o["trial"]):
        if bool(o.loc[o["trial"] == trial, "failed"].iloc[0]):
            b, g = trial, (g if g != trial else None)
        else:
            g, b = trial, (b if b != trial else None)
    return g, b


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


def _verdict(kf_o: pd.DataFrame, pf_o: pd.DataFrame, tid: str, best: bool) -> str:
    """"success" / "FAILED" (``best``: the best trial, failed too) with the KF's error
    frames and re-initialisations and the PF's error frames."""
    k, p = kf_o[kf_o["trial"] == tid], pf_o[pf_o["trial"] == tid]
    if k.empty:
        return ""
    k = k.iloc[0]
    word = ("best trial, still FAILED" if best else "FAILED") if k["failed"] else "success"
    pf_txt = f"; PF {p['error_pct'].iloc[0]:.1f} %" if len(p) else ""
    n = int(k["restarts"])
    return (f"{word}: KF {k['error_pct']:.1f} % error frames, {n} "
            f"re-initialisation{'' if n == 1 else 's'}{pf_txt}")


def _trial_rows(axes, f: pd.DataFrame, tid: str, kf: str, pf: str, mount, verdict: str
                ) -> bool:
    """The four panels of one trial on two rows of ``axes``; False without both tracks."""
    kf_f = f[f["tracker"] == kf].sort_values("scan")
    pf_f = f[f["tracker"] == pf].sort_values("scan")
    if not len(kf_f) or not len(pf_f):
        return False
    t = kf_f["t_sensor_s"].to_numpy(float)
    t = t - t[0]
    for j, side in enumerate("LR"):
        curves = {"truth": to_rollator(kf_f[f"x_true_m_{side}"].to_numpy(),
                                       kf_f[f"y_true_m_{side}"].to_numpy(), mount),
                  "kf": to_rollator(kf_f[f"x_m_{side}"].to_numpy(),
                                    kf_f[f"y_m_{side}"].to_numpy(), mount),
                  "pf": to_rollator(pf_f[f"x_m_{side}"].to_numpy(),
                                    pf_f[f"y_m_{side}"].to_numpy(), mount)}
        for i, (axis, name) in enumerate(((1, "lateral y (m)"), (0, "forward x (m)"))):
            ax = axes[i][j]
            for a, b in _spans(kf_f["error"].to_numpy(bool)):
                ax.axvspan(t[a], t[min(b, len(t) - 1)], color="0.85", lw=0)
            for key, lw in (("truth", 2.0), ("kf", 1.0), ("pf", 1.0)):
                ax.plot(t, curves[key][axis], color=COLOURS[key], lw=lw,
                        label={"truth": "ground truth", "kf": "KF", "pf": "PF"}[key])
            for k in np.flatnonzero(kf_f["restart"].to_numpy(bool)):
                ax.axvline(t[k], color="black", lw=0.4, ls=":")
            ax.set_ylabel(name)
            # the ground truth sets the limits; a diverged KF/PF track is clipped (said so)
            clip_to_reference(ax, None, [curves["truth"][axis]], None,
                              [curves["kf"][axis], curves["pf"][axis]], what="track")
            title = f"{'left' if side == 'L' else 'right'} leg, {name.split()[0]}"
            if i == 0:
                title = f"{tid}: {verdict}\n{title}" if verdict else f"{tid}\n{title}"
            ax.set_title(title, fontsize=9,
                         color="tab:red" if i == 0 and "FAILED" in verdict else "black")
            ax.grid(alpha=0.3)
        axes[1][j].set_xlabel("time (s)")
    return True


def write_rollator_figure(frames: pd.DataFrame, figures_dir, *, kf: str, pf: str,
                          trial: str | None = None, mount=None) -> list[Path]:
    """Write ``figures/rollator_turning_trial.png``: a successful and a failed trial
    (:func:`pick_trials`), two rows of panels each; one trial when the run has only one
    kind; [] without frames."""
    if frames is None or len(frames) == 0:
        return []
    good, bad = pick_trials(frames, kf, trial)
    rows = [t for t in (good, bad) if t is not None]
    rows = [t for t in rows
            if {kf, pf} <= set(frames.loc[frames["trial"] == t, "tracker"])]
    if not rows:
        return []
    kf_o, pf_o = trial_outcomes(frames, kf), trial_outcomes(frames, pf)
    verdicts = [_verdict(kf_o, pf_o, tid, tid == good) for tid in rows]
    fig, axes = plt.subplots(2 * len(rows), 2, figsize=(12, 3.4 * 2 * len(rows)),
                             squeeze=False)
    for r, (tid, v) in enumerate(zip(rows, verdicts)):
        _trial_rows(axes[2 * r:2 * r + 2], frames[frames["trial"] == tid], tid, kf, pf,
                    mount, v)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    frame = "rollator frame" if mount else "laser frame (no mount configured)"
    if len(rows) == 1:      # one kind only: no trial failed, or every trial did
        what = (f"{rows[0]}, no trial failed" if bad is None else
                f"{rows[0]}, every trial failed" if good is None else rows[0])
    else:
        what = ("the best and the worst trial" if all("FAILED" in v for v in verdicts)
                else "a successful and a failed trial")
    fig.suptitle(f"{what} (a trial fails on any KF error frame or re-initialisation): leg "
                 f"positions in the {frame}\ntruth thick red, KF black, PF blue; grey = KF "
                 "error frames, dotted = KF re-initialisations", fontsize=10)
    fig.tight_layout()
    return [save_figure(fig, Path(figures_dir) / "rollator_turning_trial.png")]
