"""Deterministic figure output.

:func:`save_figure` writes a Matplotlib figure as PNG atomically with the metadata that
would change between runs (software version, creation time) stripped, so the same data
gives the same bytes.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from gaitval.io.atomic import atomic_path  # noqa: E402


def save_figure(fig, path: str | Path, dpi: int = 120) -> Path:
    """Save ``fig`` to ``path`` (PNG) atomically and close it."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, metadata={"Software": None},
                    bbox_inches="tight")
    plt.close(fig)
    return path


#: How far beyond the reference (mocap truth, the mat) a figure shows, as a fraction of
#: the reference's extent, at least this many metres: a track that diverges further is
#: clipped at the edge and the panel says so (one diverged track must not squash the rest).
CLIP_MARGIN = 0.1
CLIP_MIN_M = 0.3


def _extent(values) -> tuple[float, float] | None:
    import numpy as np

    v = np.concatenate([np.asarray(a, dtype=float).ravel() for a in values]) \
        if len(values) else np.array([])
    v = v[np.isfinite(v)]
    if not len(v):
        return None
    return float(v.min()), float(v.max())


def clip_to_reference(ax, ref_x, ref_y, shown_x, shown_y, *, what: str = "track") -> int:
    """Limit ``ax`` to the reference data (``ref_x``/``ref_y``: lists of arrays, e.g. the
    mocap legs and the mat; ``ref_x`` None: only the y axis) plus a margin
    (:data:`CLIP_MARGIN`, :data:`CLIP_MIN_M`), and write on the panel how many plotted
    points of ``shown_x``/``shown_y`` (the tracks) lie outside and how far they went.
    Returns that count (0: nothing clipped, the panel is unchanged but for its limits)."""
    import numpy as np

    limits = {}
    for axis, ref, shown in (("x", ref_x, shown_x), ("y", ref_y, shown_y)):
        if ref is None:
            continue
        e = _extent(ref)
        if e is None:
            continue
        pad = max(CLIP_MARGIN * (e[1] - e[0]), CLIP_MIN_M)
        limits[axis] = (e[0] - pad, e[1] + pad)
    if not limits:
        return 0
    outside, worst = 0, None
    sx = [np.asarray(a, dtype=float).ravel() for a in shown_x] if shown_x is not None else []
    sy = [np.asarray(a, dtype=float).ravel() for a in shown_y] if shown_y is not None else []
    for axis, arrays in (("x", sx), ("y", sy)):
        if axis not in limits:
            continue
        lo, hi = limits[axis]
        for a in arrays:
            a = a[np.isfinite(a)]
            out = a[(a < lo) | (a > hi)]
            outside += len(out)
            if len(out):
                far = out[np.argmax(np.maximum(lo - out, out - hi))]
                if worst is None or max(lo - far, far - hi) > max(lo - worst[1], worst[1] - hi):
                    worst = (axis, float(far))
    if "x" in limits:
        ax.set_xlim(*limits["x"])
    if "y" in limits:
        ax.set_ylim(*limits["y"])
    if outside:
        axis, far = worst
        ax.text(0.99, 0.02, f"{what} clipped: {outside} point(s) beyond the plot "
                f"(diverged to {axis} = {far:.1f} m)", transform=ax.transAxes, ha="right",
                va="bottom", fontsize=7, color="tab:red",
                bbox={"facecolor": "white", "alpha": 0.8, "lw": 0, "pad": 1})
    return outside


def statement_figure(path, text: str):
    """A PNG that states why a declared figure has nothing to draw (the workflow declares
    every figure, so a figure without data is a statement, not a missing file)."""
    fig, ax = plt.subplots(figsize=(6, 1.6))
    ax.axis("off")
    ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=9, wrap=True)
    return save_figure(fig, path)
