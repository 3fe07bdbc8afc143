"""Seed 003's autocorrelation figures (Qi et al., Sensors 2014, Figs. 2–4) from the run's
own ultrasonic tracks.

- :func:`figure2_autocorrelation` — like Figure 2: the heel's horizontal displacement of
  a normal-speed trial, its biased (eq. 15) and unbiased (eq. 16) autocorrelation.
- :func:`figure_symmetry_autocorrelation` — like Figures 3 and 4: the normalised unbiased
  autocorrelation of the horizontal and vertical displacement over one symmetry window
  (``ultrasonic.symmetry.window_strides`` strides, as the gait table's hS and vS), the
  first and second stride peaks R1 and R2 marked
  (:func:`gaitval.gait.strides.autocorr_symmetry`, the function the tables use).

Figure 3 is the paper's normal gait, Figure 4 an abnormal (asymmetric) gait.  The twin
simulates healthy walkers only, so :func:`write_ultrasonic_paper_figures` draws for
Figure 4 the run's *least symmetric* normal-speed trial (the largest mean |1 − hS| of the
system in the gait table) and its title says that it is not an abnormal gait; Figures 2
and 3 show the most symmetric one (:func:`symmetry_order`).

The signal is the system's (UKF) heel track in the ultrasonic frame (X progression, Y
vertical), mean removed, at the log's own rate; the tables' hS and vS are computed on the
track aligned with and low-passed like the reference (:mod:`gaitval.evaluate.ultrasonic`),
so a peak here can differ from the table's value in the third decimal.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.gait.strides import autocorr_symmetry, autocorr_unbiased, dominant_period
from gaitval.report.figures import plt, save_figure

#: Columns of the UKF track a figure reads (gaitval.track.ukf.TRACK_COLUMNS).
_AXES = {"horizontal": "x_m", "vertical": "y_m"}


def _signal(track: pd.DataFrame, trial: str) -> tuple[np.ndarray, np.ndarray, float]:
    """(t, (n, 2) horizontal and vertical displacement, fs) of a UKF track."""
    missing = [c for c in ("t_s", *_AXES.values()) if c not in track]
    if missing:
        raise GaitvalError(f"the ultrasonic track lacks column(s) {', '.join(missing)}",
                           trial=trial)
    t = track["t_s"].to_numpy(float)
    xy = track[list(_AXES.values())].to_numpy(float)
    ok = np.isfinite(t) & np.isfinite(xy).all(axis=1)
    t, xy = t[ok], xy[ok]
    if t.size < 4:
        raise GaitvalError(f"the ultrasonic track has {t.size} finite samples, too few for "
                           "an autocorrelation", trial=trial)
    fs = 1.0 / float(np.median(np.diff(t)))
    return t, xy, fs


def _window(t, xy, fs, period_s: float, n_strides: int) -> tuple[np.ndarray, np.ndarray]:
    """The first ``n_strides`` stride periods of the signal (all of it when shorter)."""
    n = int(round(n_strides * period_s * fs)) if np.isfinite(period_s) else t.size
    n = max(4, min(n, t.size))
    return t[:n], xy[:n]


def autocorr_biased(a: np.ndarray, max_lag: int | None = None,
                    normalise: bool = False) -> np.ndarray:
    """Biased autocorrelation ``(1/N) Σ_{i=1}^{N-m} a_i a_{i+m}``: the unbiased one of
    :func:`~gaitval.gait.strides.autocorr_unbiased` times ``(N − m)/N``."""
    a = np.asarray(a, dtype=float)
    A = autocorr_unbiased(a, max_lag)
    A = A * (a.size - np.arange(A.size)) / max(a.size, 1)     # seed003 eq. (15)
    if normalise and A.size and A[0] != 0:
        A = A / A[0]
    return A


def figure2_autocorrelation(track: pd.DataFrame, trial: str, path: str | Path, *,
                            n_strides: int = 10, min_period_s: float = 0.6,
                            max_period_s: float = 2.5) -> Path:
    """Horizontal heel displacement (top), its biased (middle) and unbiased (bottom)
    normalised autocorrelation over every lag of a window of ``n_strides`` strides."""
    t, xy, fs = _signal(track, trial)
    T = dominant_period(xy[:, 0], fs, min_period_s, max_period_s)
    tw, w = _window(t, xy, fs, T, n_strides)
    h = w[:, 0] - w[:, 0].mean()
    lags = np.arange(h.size) / fs
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 7.0))
    axes[0].plot(tw - tw[0], 100.0 * h, color="k", lw=0.9)
    axes[0].set_xlabel("time from the window's start (s)")
    axes[0].set_ylabel("horizontal displacement,\nmean removed (cm)")
    axes[0].set_title(f"{trial}: heel's horizontal displacement (ultrasonic system, UKF), "
                      f"{len(h) / fs:.1f} s", fontsize=9)
    for ax, (name, A) in zip(axes[1:], (("biased, eq. (15)", autocorr_biased(h, None, True)),
                                        ("unbiased, eq. (16)",
                                         autocorr_unbiased(h, None, True)))):
        ax.plot(lags, A, color="k", lw=0.9)
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_xlabel("time lag (s)")
        ax.set_ylabel("autocorrelation\n(normalised, A(0) = 1)")
        ax.set_title(f"{name} autocorrelation", fontsize=9)
        ax.grid(True, lw=0.3)
    period = f"stride period {T:.2f} s" if np.isfinite(T) else "no stride period found"
    fig.suptitle(f"Horizontal displacement and its biased and unbiased autocorrelation "
                 f"({period}; cf. Qi et al. 2014 Fig. 2)", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def figure_symmetry_autocorrelation(track: pd.DataFrame, trial: str, path: str | Path, *,
                                    figure: str, what: str, n_strides: int = 5,
                                    min_period_s: float = 0.6,
                                    max_period_s: float = 2.5) -> Path:
    """Normalised unbiased autocorrelation of the horizontal (top) and vertical (bottom)
    displacement over the first ``n_strides`` strides, R1 and R2 marked with their ratio
    (the symmetry hS / vS, seed 003 §3.3.2); ``figure`` ("3", "4") and ``what`` (which
    gait this is) go into the title."""
    t, xy, fs = _signal(track, trial)
    T = dominant_period(xy[:, 0], fs, min_period_s, max_period_s)
    _, w = _window(t, xy, fs, T, n_strides)
    fig, axes = plt.subplots(2, 1, figsize=(7.5, 5.6), sharex=True)
    for ax, (i, name, sym) in zip(axes, ((0, "horizontal", "hS"), (1, "vertical", "vS"))):
        a = w[:, i] - w[:, i].mean()
        A = autocorr_unbiased(a, None, normalise=True)
        ax.plot(np.arange(A.size) / fs, A, color="k", lw=0.9)
        ax.axhline(0.0, color="0.6", lw=0.6)
        s = autocorr_symmetry(w[:, i], fs, T)
        if np.isfinite(s["R1"]):
            ax.plot([s["lag1_s"], s["lag2_s"]], [s["R1"], s["R2"]], "o", mfc="none",
                    color="tab:red", ms=8, mew=1.5)
            for k in (1, 2):
                ax.annotate(f"R{k} = {s[f'R{k}']:.3f}", (s[f"lag{k}_s"], s[f"R{k}"]),
                            textcoords="offset points", xytext=(6, 6), fontsize=8,
                            color="tab:red")
            txt = f"{sym} = R2/R1 = {s['symmetry']:.3f}"
        else:
            txt = f"{sym}: window shorter than three stride periods"
        ax.set_title(f"{name} displacement: {txt}", fontsize=9)
        ax.set_ylabel("unbiased autocorrelation\n(normalised, A(0) = 1)")
        ax.margins(y=0.18)
        ax.grid(True, lw=0.3)
    axes[-1].set_xlabel("time lag (s)")
    fig.suptitle(f"Horizontal and vertical unbiased autocorrelation over {n_strides} strides "
                 f"(cf. Qi et al. 2014 Fig. {figure})\n{trial}: {what}", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def symmetry_order(gait_params: pd.DataFrame, speed: str = "normal") -> list[str]:
    """The trials at ``speed`` from the most to the least symmetric: by the mean |1 − hS|
    of the system over the trial's windows (ties by id); [] without an hS row."""
    g = gait_params[(gait_params["parameter"] == "h_symmetry")
                    & (gait_params["speed"].astype(str) == speed)]
    g = g[np.isfinite(pd.to_numeric(g["system"], errors="coerce"))]
    if g.empty:
        return []
    dev = (1.0 - g["system"].astype(float)).abs().groupby(g["trial"].astype(str)).mean()
    return sorted(dev.index, key=lambda tr: (dev[tr], tr))


def write_ultrasonic_paper_figures(tracks: dict[str, pd.DataFrame],
                                   gait_params: pd.DataFrame, out_dir: str | Path,
                                   cfg: dict | None = None) -> list[Path]:
    """``ultrasonic_fig2.png``, ``ultrasonic_fig3.png`` (the most symmetric normal-speed
    trial) and ``ultrasonic_fig4.png`` (the least symmetric one, module notes);
    ``tracks``: trial → UKF track; ``cfg``: the ``ultrasonic`` section (strides' period
    limits, ``symmetry.window_strides``).  [] without a normal-speed trial."""
    from gaitval.evaluate.ultrasonic_config import resolve_cfg

    c = resolve_cfg(cfg)
    kw = {"min_period_s": float(c["strides"]["min_period_s"]),
          "max_period_s": float(c["strides"]["max_period_s"])}
    K = int(c["symmetry"]["window_strides"])
    out = Path(out_dir)
    order = [t for t in symmetry_order(gait_params) if t in tracks]
    if not order:
        return []
    normal, worst = order[0], order[-1]

    def hs(trial):
        v = gait_params[(gait_params["parameter"] == "h_symmetry")
                        & (gait_params["trial"].astype(str) == trial)]["system"].astype(float)
        return f"system's mean |1 − hS| {(1.0 - v).abs().mean():.3f} over {len(v)} windows"
    return [figure2_autocorrelation(tracks[normal], normal, out / "ultrasonic_fig2.png",
                                    **kw),
            figure_symmetry_autocorrelation(
                tracks[normal], normal, out / "ultrasonic_fig3.png", figure="3",
                what=f"normal gait, the run's most symmetric normal-speed trial ({hs(normal)})",
                n_strides=K, **kw),
            figure_symmetry_autocorrelation(
                tracks[worst], worst, out / "ultrasonic_fig4.png", figure="4",
                what=f"the run's least symmetric normal-speed trial ({hs(worst)}); no "
                     "abnormal gait simulated", n_strides=K, **kw)]
