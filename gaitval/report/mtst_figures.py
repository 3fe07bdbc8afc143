"""MTST figure (Yorozu et al. 2015b Fig. 10 style): a successful and a failed trial on the mat, one
row each — both tracked legs (thin) against the mocap legs (thick, where the study has
mocap), the foot contacts, the targets, the target steps judged ("O") and the cross steps
detected ("+"); each row says its tracking verdict (Yorozu et al. 2015b Table 3: success, lost,
false_swap, false_other).

References
----------
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (Yorozu et al. 2015b), Figure 10, Table 3.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from gaitval.report.figures import clip_to_reference, save_figure  # noqa: E402

LEG_COLORS = {"L": "tab:blue", "R": "tab:red"}
TARGET_COLORS = {"red": "#d62728", "blue": "#1f77b4", "white": "#ffffff"}
METHOD = "mtst_proposed"


def categories(summary: pd.DataFrame) -> pd.Series:
    """Each summary row's tracking verdict: ``category_mocap`` where the trial has mocap,
    else ``category_annotations`` ("" when neither reference judged it)."""
    if summary.empty:
        return pd.Series([], dtype=str)
    return pd.Series(np.where(summary["has_mocap"].astype(bool),
                              summary["category_mocap"].astype(str),
                              summary["category_annotations"].astype(str)),
                     index=summary.index).fillna("")


def pick_trial(summary: pd.DataFrame, contacts: pd.DataFrame, method: str = METHOD
               ) -> str | None:
    """The successful trial: the first (by id) the method tracked successfully that has a
    detected cross step, else the first successful one; None when the method tracked none
    successfully."""
    s = summary[summary["method"] == method] if len(summary) else summary
    if s.empty:
        return None
    ok = s[categories(s) == "success"]
    c = contacts[(contacts["method"] == method) & contacts["cross"].astype(bool)] \
        if len(contacts) else contacts
    for pool in (sorted(set(ok["trial"]) & set(c.get("trial", []))), sorted(ok["trial"])):
        if pool:
            return str(pool[0])
    return None


def pick_trials(summary: pd.DataFrame, contacts: pd.DataFrame, methods=None,
                method: str = METHOD
                ) -> tuple[tuple[str, str] | None, tuple[str, str] | None]:
    """((trial, method) tracked successfully, (trial, method) that failed) for the figure.

    Success: :func:`pick_trial` of ``method`` (the proposed one), else of the first of
    ``methods`` with a successful trial.  Failure: of ``method`` if it failed any trial,
    else of the method with the most failed trials (ties: order of ``methods``, the
    summary's order after them); its first failed trial (by id) other than the
    successful one, else the successful trial itself (another method on it).  None where
    no method succeeded, or none failed."""
    if summary.empty:
        return None, None
    s = summary.assign(trial=summary["trial"].astype(str), method=summary["method"].astype(str),
                       category=categories(summary))
    order = list(dict.fromkeys([method, *(methods or []), *s["method"]]))
    good = None
    for m in order:
        t = pick_trial(s, contacts, m)
        if t is not None:
            good = (t, m)
            break
    bad = s[~s["category"].isin(["success", ""])]
    if bad.empty:
        return good, None
    n_bad = bad.groupby("method").size()
    fm = method if method in n_bad else sorted(
        n_bad.index, key=lambda m: (-n_bad[m], order.index(m)))[0]
    trials = sorted(bad.loc[bad["method"] == fm, "trial"])
    other = [t for t in trials if good is None or t != good[0]]
    return good, ((other or trials)[0], fm)

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


def plot_mtst_trial(data: dict[str, pd.DataFrame], trial, path: str | Path,
                    method: str = METHOD) -> Path:
    """Top view in the field frame of one trial or of several rows (module notes).

    ``trial``: a trial id (drawn for ``method``) or a list of ``(trial, method)`` rows."""
    rows = [(trial, method)] if isinstance(trial, str) else [tuple(r) for r in trial]
    summary = data.get("summary", pd.DataFrame())
    fig, axes = plt.subplots(len(rows), 1, figsize=(11, 2.5 * len(rows) + 0.9),
                             squeeze=False)
    for ax, (tr, m) in zip(axes[:, 0], rows):
        _trial_panel(ax, data, str(tr), str(m), _outcome(summary, str(tr), str(m)))
    axes[-1, 0].set_xlabel("x along the mat (m, field frame)")
    axes[-1, 0].legend(loc="upper left", fontsize=7, ncol=4, frameon=False,
                       bbox_to_anchor=(0.0, -0.25))
    what = ("a successful and a failed trial" if len(rows) == 2 else
            f"trial {rows[0][0]}")
    mocap = "has_mocap" in summary and summary["has_mocap"].astype(bool).any()
    legs = ("tracked legs (thin) vs mocap (thick)" if mocap else
            "tracked legs (mocap truth: not available)")
    fig.suptitle(f"MTST, {what}: {legs}, foot contacts (dots), assigned targets "
                 "(bold outline)", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def _outcome(summary: pd.DataFrame, trial: str, method: str) -> str:
    """"success", "FAILED (<category>)" or "" (no verdict) of one (trial, method)."""
    if summary is None or summary.empty:
        return ""
    s = summary[(summary["trial"].astype(str) == trial)
                & (summary["method"].astype(str) == method)]
    if s.empty:
        return ""
    cat = str(categories(s).iloc[0])
    ref = "mocap" if bool(s["has_mocap"].iloc[0]) else "rater"
    if not cat:
        return ""
    return f"success ({ref})" if cat == "success" else f"FAILED: {cat} ({ref})"


def _trial_panel(ax, data: dict[str, pd.DataFrame], trial: str, method: str,
                 outcome: str) -> None:
    def sel(name):
        d = data.get(name, pd.DataFrame())
        if d.empty:
            return d
        d = d[d["trial"].astype(str) == trial]
        return d[d["method"] == method] if "method" in d else d

    tr, c, tg = sel("track_field"), sel("contacts"), sel("targets")
    if len(tg):
        _mat(ax, tg.drop_duplicates("target"))
    has_truth = False
    for side in ("L", "R"):
        s = tr[tr["side"] == side] if len(tr) else tr
        if len(s) and "x_true_m" in s and s["x_true_m"].notna().any():
            has_truth = True
            ax.plot(s["x_true_m"], s["y_true_m"], "-", color=LEG_COLORS[side], lw=3.2,
                    alpha=0.35, solid_capstyle="round", label=f"{side} leg (mocap)")
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
    ax.set_ylabel("y (m)")
    # the mocap legs and the mat set the limits; a diverged track is clipped, and said so
    ref_x = [tr["x_true_m"]] if has_truth else []
    ref_y = [tr["y_true_m"]] if has_truth else []
    if len(tg) and {"x_m", "y_m"} <= set(tg.columns):
        ref_x.append(tg["x_m"])
        ref_y.append(tg["y_m"])
    if len(tr) and ref_x:
        clip_to_reference(ax, ref_x, ref_y, [tr["x_m"]], [tr["y_m"]], what="tracked leg")
    note = "" if has_truth else " — no mocap"
    ax.set_title(f"{trial}, {method}: {outcome or 'no verdict'}{note}", fontsize=9,
                 color="tab:red" if outcome.startswith("FAILED") else "black")


def write_mtst_figure(data: dict[str, pd.DataFrame], figures_dir, *, trial: str | None = None,
                      methods=None) -> list[Path]:
    """``mtst_trial.png``: a successful and a failed trial (:func:`pick_trials`), one row
    each; ``trial`` (``mtst.figure_trial``) takes the place of the automatic pick of its
    own outcome (with the proposed method); one row when the run has only one kind, the
    first trial when it has neither; [] without trials."""
    summary = data.get("summary", pd.DataFrame())
    good, bad = pick_trials(summary, data.get("contacts", pd.DataFrame()), methods)
    if trial is not None:
        if _outcome(summary, str(trial), METHOD).startswith("FAILED"):
            bad = (str(trial), METHOD)
        else:
            good = (str(trial), METHOD)
    rows = [r for r in (good, bad) if r is not None]
    if not rows and len(summary):
        first = summary.sort_values(["trial", "method"]).iloc[0]
        rows = [(str(first["trial"]), str(first["method"]))]
    if not rows:
        return []
    return [plot_mtst_trial(data, rows, Path(figures_dir) / "mtst_trial.png")]
