"""Figures clip a diverged track at the reference's extent and say so
(gaitval.report.figures.clip_to_reference; the MTST, TUG and rollator trial figures)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from gaitval.report.figures import CLIP_MIN_M, clip_to_reference  # noqa: E402
from gaitval.report.tug_figures import _trial_row  # noqa: E402


def test_a_track_gone_to_minus_12_m_is_clipped_and_the_panel_says_so():
    fig, ax = plt.subplots()
    x = np.linspace(0.0, 5.85, 50)
    truth_y = 0.1 * np.sin(x)
    track_y = truth_y.copy()
    track_y[-5:] = np.linspace(-3.0, -12.0, 5)          # one track diverges
    ax.plot(x, track_y)
    n = clip_to_reference(ax, [x], [truth_y], [x], [track_y], what="tracked leg")
    lo, hi = ax.get_ylim()
    assert n == 5
    assert lo > -1.0 and hi < 1.0                        # not squashed by the -12 m
    assert lo <= truth_y.min() - CLIP_MIN_M + 1e-9
    (text,) = [t.get_text() for t in ax.texts]
    assert "5 point(s) beyond the plot" in text and "y = -12.0 m" in text
    plt.close(fig)


def test_nothing_clipped_leaves_no_note():
    fig, ax = plt.subplots()
    x = np.linspace(0.0, 2.0, 10)
    assert clip_to_reference(ax, [x], [x], [x + 0.01], [x]) == 0
    assert len(ax.texts) == 0
    plt.close(fig)


def test_tug_panel_clips_a_diverged_lrs_track():
    n = 40
    x = np.linspace(0.5, 3.0, n)
    rows = []
    for side, dy in (("L", 0.1), ("R", -0.1)):
        y = np.full(n, dy)
        ys = y.copy()
        if side == "R":
            y = y.copy()
            y[-3:] = -12.0
        rows.append(pd.DataFrame({"method": "m", "side": side, "xs_m": x, "ys_m": ys,
                                  "x_m": x, "y_m": y, "pattern": "SS"}))
    f = pd.concat(rows)
    fig, axes = plt.subplots(1, 1, squeeze=False)
    _trial_row(axes[0], f, "t1", ["m"], None)
    ax = axes[0][0]
    assert ax.get_ylim()[0] > -2.0
    assert any("LRS track clipped: 3 point(s)" in t.get_text() for t in ax.texts)
    plt.close(fig)
