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
