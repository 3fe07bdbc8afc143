"""Statistics figures of Qi et al. 2014 (Qi et al., Sensors 2014) and Bland–Altman plots.

- :func:`figure_a1_histograms` — like Figure A1: histograms (here of the differences
  system − reference, per parameter).
- :func:`figure_b1_boxplots` — like Figure B1: per-subject boxplots of each parameter.
- :func:`figure5_speed_effects` — like Figure 5: mean ± std at slow / normal / fast speed
  for reference and system, ``*`` where a paired t-test against normal speed gives
  p < 0.05 (from :func:`gaitval.tables.ultrasonic.table8`).
- :func:`bland_altman_figure` — one Bland–Altman plot: points coloured by subject (more
  transparent the more there are), the paper's mean difference where it gives one (Qi et
  al. publish no limits of agreement; the title says so), the pooled bias and limits (every stride independent, :func:`gaitval.stats.agreement`) and
  the repeated-measures ones (subjects as a random effect, :func:`gaitval.stats.loa_nested`)
  with their 95% CIs, as :mod:`gaitval.tables.ultrasonic_agreement` tabulates them.

Every figure is written with :func:`gaitval.report.figures.save_figure` (deterministic
PNG).  The figures take the tidy tables; they never recompute a statistic the tables hold.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.figures import plt, save_figure
from gaitval.tables.numbers import fixed
from gaitval.stats import agreement, loa_nested
from gaitval.tables.ultrasonic import (PARAM_INFO, PARAMETERS, SPEEDS, SUMMARY_PARAMETERS,
                                       _subject_order, check_gait_params, table8)
from gaitval.tables.ultrasonic_agreement import POOLED, REPEATED, agreement_table


#: Display unit of a Bland–Altman plot per CSV unit: (unit, factor, decimals) — the size of
#: the differences in a unit the papers use (mm for lengths, ms for durations).
BA_UNITS = {"m": ("mm", 1000.0, 1), "s": ("ms", 1000.0, 1), "m/s": ("cm/s", 100.0, 2),
            "stride/s": ("stride/min", 60.0, 2), "-": ("-", 1.0, 4), "": ("", 1.0, 3)}


def ba_unit(unit: str) -> tuple[str, float, int]:
    """(display unit, factor from ``unit``, decimals) of a Bland–Altman plot."""
    return BA_UNITS.get(unit, (unit, 1.0, 3))


def _label(param: str) -> str:
    sym, _, unit = PARAM_INFO[param]
    return f"{param.replace('_', ' ')} {sym}" + (f" ({unit})" if unit != "-" else "")


def _grid(n: int, width: float = 4.0, height: float = 3.0):
    cols = min(n, 3)
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows),
                             squeeze=False)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    return fig, axes.ravel()


def figure_a1_histograms(gait_params: pd.DataFrame, path: str | Path,
                         speed: str = "normal", bins: int = 20) -> Path:
    """Histograms of the differences system − reference per parameter (Figure A1-like)."""
    df = check_gait_params(gait_params)
    df = df[df["speed"] == speed]
    params = [p for p in SUMMARY_PARAMETERS if p in set(df["parameter"].unique())]
    fig, axes = _grid(max(len(params), 1))
    for ax, p in zip(axes, params):
        sub = df[df["parameter"] == p]
        d = (sub["system"] - sub["reference"]).to_numpy(dtype=float)
        d = d[np.isfinite(d)]
        ax.hist(d, bins=bins, color="0.6", edgecolor="k")
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_xlabel(f"difference, {_label(p)}")
        ax.set_ylabel("strides")
    fig.suptitle(f"Differences system - reference ({speed} speed; cf. Qi et al. 2014 Fig. A1)")
    fig.tight_layout()
    return save_figure(fig, path)


def figure_b1_boxplots(gait_params: pd.DataFrame, path: str | Path, speed: str = "normal",
                       column: str = "system") -> Path:
    """Per-subject boxplots of each parameter (Figure B1-like)."""
    df = check_gait_params(gait_params)
    df = df[df["speed"] == speed]
    params = [p for p in SUMMARY_PARAMETERS if p in set(df["parameter"].unique())]
    fig, axes = _grid(max(len(params), 1), width=5.0)
    for ax, p in zip(axes, params):
        sub = df[df["parameter"] == p]
        subjects = _subject_order(sub["subject"])
        data = [sub.loc[sub["subject"] == s, column].dropna().to_numpy(dtype=float)
                for s in subjects]
        ax.boxplot(data)
        ax.set_xticks(range(1, len(subjects) + 1), subjects, rotation=90, fontsize=7)
        ax.set_ylabel(_label(p))
    fig.suptitle(f"{column} estimates per subject ({speed} speed; cf. Qi et al. 2014 Fig. B1)")
    fig.tight_layout()
    return save_figure(fig, path)


def figure5_speed_effects(table8_df: pd.DataFrame, path: str | Path) -> Path:
    """Mean ± std of Ref and Pro per speed with ``*`` for p < 0.05 vs normal (Figure 5-like).

    Parameters
    ----------
    table8_df : DataFrame
        Output of :func:`gaitval.tables.ultrasonic.table8`.
    """
    params = [p for p in PARAMETERS if p in set(table8_df["parameter"].unique())]
    fig, axes = _grid(max(len(params), 1), width=3.6)
    x = np.arange(len(SPEEDS))
    for ax, p in zip(axes, params):
        for off, q, color in ((-0.15, "ref", "0.3"), (0.15, "pro", "0.7")):
            row = table8_df[(table8_df["parameter"] == p) & (table8_df["quantity"] == q)]
            if row.empty:
                continue
            row = row.iloc[0]
            m = [row[f"{s}_mean"] for s in SPEEDS]
            e = [row[f"{s}_std"] for s in SPEEDS]
            ax.bar(x + off, m, width=0.3, yerr=e, color=color, edgecolor="k",
                   label={"ref": "reference", "pro": "system"}[q], capsize=3)
            for i, s in enumerate(SPEEDS):
                if s != "normal" and bool(row.get(f"{s}_significant", False)):
                    top = m[i] + (e[i] if np.isfinite(e[i]) else 0.0)
                    ax.text(x[i] + off, top, "*", ha="center", va="bottom")
        ax.set_xticks(x, SPEEDS)
        ax.set_ylabel(_label(p))
        ax.margins(y=0.12)
    axes[0].legend(fontsize=7)
    fig.suptitle("Effect of walking speed (* p < 0.05 vs normal; cf. Qi et al. 2014 Fig. 5)")
    fig.tight_layout()
    return save_figure(fig, path)


def _limits(df: pd.DataFrame, ref: str, pro: str, subject: str | None) -> dict:
    """Pooled (and, with subjects, repeated-measures) limits named as the agreement table."""
    a = agreement(df, ref, pro).iloc[0]
    out = {c: float(a[src]) for c, src in POOLED.items()}
    if subject is not None:
        rm = loa_nested(df, ref, pro, subject).iloc[0]
        out.update({c: float(rm[src]) for c, src in REPEATED.items()})
    return out


def point_alpha(n: int) -> float:
    """Marker opacity for ``n`` points: opaque for a few, down to 0.2 for thousands
    (2,483 strides of the default study are a cloud, not a blot)."""
    return float(np.clip(150.0 / max(n, 1), 0.2, 0.9))


def published_bias(param: str) -> dict:
    """What Qi et al. (2014) publish that a Bland–Altman plot of ``param`` can show: the
    mean difference Pro − Ref of the subject averages of Tables 2–6 (normal speed).  The
    paper gives no limits of agreement, so none are returned."""
    from gaitval.tables._published_qi2014 import TABLES_2_6

    t = TABLES_2_6.get(param)
    if not t:
        return {}
    i = 10                                            # the "average" column
    table = 2 + list(TABLES_2_6).index(param)
    return {"bias": t["pro_mean"][i] - t["ref_mean"][i],
            "label": f"published mean difference (Table {table} averages, Pro - Ref)"}


def bland_altman_figure(df: pd.DataFrame, ref: str, pro: str, path: str | Path,
                        title: str = "", unit: str = "", subject: str | None = None,
                        limits=None, published: dict | None = None) -> Path:
    """Bland–Altman plot: difference vs mean, pooled and repeated-measures limits.

    Parameters
    ----------
    df : DataFrame
        One row per pair.
    ref, pro : str
        Reference and system columns; the plot shows ``pro − ref`` against their mean.
    path : path
        PNG to write.
    title, unit : str
        Title (default: the limits) and unit of the axes.
    subject : str, optional
        Subject column: points are coloured by subject and the repeated-measures bias and
        limits (subjects as a random effect) are drawn beside the pooled ones.
    limits : mapping, optional
        The row of :func:`gaitval.tables.ultrasonic_agreement.agreement_table` for these
        pairs (``bias``, ``loa_low`` … and the ``*_rm`` columns); computed when omitted.
    published : mapping, optional
        The paper's values, drawn in green dash-dot: ``bias`` and/or ``loa_low`` /
        ``loa_high``, and a ``label`` saying where they come from.  Without published
        limits the title says so.

    Notes
    -----
    Values in the quantity's display unit (:data:`BA_UNITS`: mm, ms, cm/s for the CSV's
    m, s, m/s), printed with fixed decimals.  Legends below the plot (lines, then subjects).
    Pooled (every pair independent): grey, dotted bias and dashed limits drawn on top,
    grey bands for the 95% CIs.
    Repeated measures: black, thick solid limits underneath (both visible where they
    coincide), 95% CIs as bars at the right edge (with few
    subjects they can be far wider than the points, so they are not drawn as bands).
    """
    lim = dict(limits) if limits is not None else _limits(df, ref, pro, subject)
    unit, k, dec = ba_unit(unit)
    lim = {key: (float(v) * k if ("bias" in key or "loa" in key) else v)
           for key, v in lim.items()}
    r = pd.to_numeric(df[ref], errors="coerce").to_numpy(dtype=float) * k
    p = pd.to_numeric(df[pro], errors="coerce").to_numpy(dtype=float) * k
    ok = np.isfinite(r) & np.isfinite(p)
    mean, diff = (r[ok] + p[ok]) / 2, p[ok] - r[ok]
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    if subject is not None:
        subs = df[subject].astype(str).to_numpy()[ok]
        order = _subject_order(subs)
        cmap = plt.get_cmap("tab10" if len(order) <= 10 else "tab20")
        alpha = point_alpha(len(mean))
        for i, s in enumerate(order):
            sel = subs == s
            ax.scatter(mean[sel], diff[sel], s=9, color=cmap(i % cmap.N), label=s,
                       alpha=alpha, linewidths=0)
    else:
        ax.scatter(mean, diff, s=9, color="k", alpha=point_alpha(len(mean)), linewidths=0)
    _pooled_lines(ax, lim)
    pub = {key: (float(v) * k if key != "label" else v)
           for key, v in dict(published or {}).items()}
    for key, style in (("bias", "-."), ("loa_low", "-."), ("loa_high", "-.")):
        if np.isfinite(pub.get(key, np.nan)):
            ax.axhline(pub[key], color="tab:green", ls=style, lw=1.2,
                       label=pub.get("label", "published") if key == "bias"
                       or "bias" not in pub else None)
    has_rm = subject is not None and np.isfinite(lim.get("loa_low_rm", np.nan))
    if has_rm:
        _repeated_lines(ax, lim, mean)
    un = f" ({unit})" if unit and unit != "-" else ""
    ax.set_xlabel(f"mean of reference and system{un}")
    ax.set_ylabel(f"system - reference{un}")
    u = f" {unit}" if unit and unit != "-" else ""

    def f(x):
        return fixed(float(x), dec)
    text = f"pooled: bias {f(lim['bias'])}{u}, LoA [{f(lim['loa_low'])}, {f(lim['loa_high'])}]{u}"
    if has_rm:
        text += (f"\nrepeated measures: bias {f(lim['bias_rm'])}{u}, LoA "
                 f"[{f(lim['loa_low_rm'])}, {f(lim['loa_high_rm'])}]{u}")
    if not np.isfinite(pub.get("loa_low", np.nan)):
        text += "\nno published limits of agreement"
    ax.set_title((title + "\n" if title else "") + text, fontsize=8)
    # two legends below the plot, full width: the lines, then the subjects
    handles, labels = ax.get_legend_handles_labels()
    subj = set(_subject_order(df[subject].astype(str))) if subject is not None else set()
    lines = [(h, lb) for h, lb in zip(handles, labels) if lb not in subj]
    points = [(h, lb) for h, lb in zip(handles, labels) if lb in subj]
    leg1 = ax.legend([h for h, _ in lines], [lb for _, lb in lines], fontsize=6.5,
                     loc="upper left", bbox_to_anchor=(0.0, -0.16), ncol=2, frameon=False)
    if points:
        ax.add_artist(leg1)
        leg2 = ax.legend([h for h, _ in points], [lb for _, lb in points], fontsize=6.5,
                         loc="upper left", bbox_to_anchor=(0.0, -0.40),
                         ncol=min(len(points), 10), frameon=False, title="subjects",
                         title_fontsize=6.5, handletextpad=0.2, columnspacing=0.8)
        for h in getattr(leg2, "legend_handles", []):
            h.set_alpha(1.0)                         # subjects legible in the legend
    fig.tight_layout()
    return save_figure(fig, path)


def _pooled_lines(ax, lim: dict) -> None:
    """Pooled bias (thin) and limits (dashed) in grey, their 95% CIs as grey bands."""
    for key, style, label in (("bias", ":", "pooled bias (strides independent)"),
                              ("loa_low", "--", "pooled limits (strides independent)"),
                              ("loa_high", "--", None)):
        if np.isfinite(lim.get(key, np.nan)):
            ax.axhline(lim[key], color="0.45", ls=style, lw=1.3, label=label, zorder=3)
    for lo, hi in (("bias_ci_low", "bias_ci_high"), ("loa_low_ci_low", "loa_low_ci_high"),
                   ("loa_high_ci_low", "loa_high_ci_high")):
        if np.isfinite(lim.get(lo, np.nan)) and np.isfinite(lim.get(hi, np.nan)):
            ax.axhspan(lim[lo], lim[hi], color="0.9", zorder=0)


def _repeated_lines(ax, lim: dict, mean: np.ndarray) -> None:
    """Repeated-measures bias and limits in black; 95% CIs as capped bars at the right.

    The bars stand beside the points (bias, lower limit, upper limit from left to right)
    and are cut by the axes when, with few subjects, they are far wider than the data.
    """
    # solid black under the grey dashed pooled lines: where both coincide, both show
    ax.axhline(lim["bias_rm"], color="k", lw=1.0, label="repeated-measures bias", zorder=2)
    ax.axhline(lim["loa_low_rm"], color="k", lw=2.2, alpha=0.8, zorder=2,
               label="repeated-measures limits (subjects random)")
    ax.axhline(lim["loa_high_rm"], color="k", lw=2.2, alpha=0.8, zorder=2)
    ylo, yhi = ax.get_ylim()
    ylo, yhi = min(ylo, lim["loa_low_rm"]), max(yhi, lim["loa_high_rm"])
    span = float(np.ptp(mean)) if mean.size > 1 and np.ptp(mean) > 0 else 1.0
    x0 = (float(np.max(mean)) if mean.size else 0.0) + 0.05 * span
    for i, key in enumerate(("bias_rm", "loa_low_rm", "loa_high_rm")):
        lo, hi = lim.get(f"{key}_ci_low", np.nan), lim.get(f"{key}_ci_high", np.nan)
        if np.isfinite(lo) and np.isfinite(hi):
            ax.errorbar([x0 + 0.04 * span * i], [lim[key]], yerr=[[lim[key] - lo],
                        [hi - lim[key]]], fmt="none", ecolor="k", elinewidth=0.8,
                        capsize=2, label="95% CIs, repeated measures" if i == 0 else None)
    ax.set_ylim(ylo, yhi)


def write_ultrasonic_figures(gait_params: pd.DataFrame, out_dir: str | Path,
                             speed: str = "normal") -> list[Path]:
    """Write Figure A1-, B1- and 5-like figures and one Bland–Altman plot per parameter.

    Files: ``ultrasonic_figA1.png``, ``ultrasonic_figB1.png``, ``ultrasonic_fig5.png``,
    ``ultrasonic_bland_altman_<parameter>.png`` (strides at ``speed``, coloured by subject,
    pooled and repeated-measures limits from
    :func:`gaitval.tables.ultrasonic_agreement.agreement_table`).
    """
    out_dir = Path(out_dir)
    df = check_gait_params(gait_params)
    paths = [figure_a1_histograms(df, out_dir / "ultrasonic_figA1.png", speed),
             figure_b1_boxplots(df, out_dir / "ultrasonic_figB1.png", speed),
             figure5_speed_effects(table8(df), out_dir / "ultrasonic_fig5.png")]
    limits = agreement_table(df, parameters=PARAMETERS, speeds=[speed])
    for p in PARAMETERS:
        sub = df[(df["parameter"] == p) & (df["speed"] == speed)]
        if sub.empty:
            continue
        paths.append(bland_altman_figure(
            sub, "reference", "system", out_dir / f"ultrasonic_bland_altman_{p}.png",
            title=f"Bland-Altman: {p.replace('_', ' ')} {PARAM_INFO[p][0]}, {speed} speed",
            unit=PARAM_INFO[p][2],
            subject="subject", limits=limits[limits["parameter"] == p].iloc[0],
            published=published_bias(p) if speed == "normal" else None))
    return paths
