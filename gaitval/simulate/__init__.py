"""The embedded default study: a simulated replica of the four validation protocols.

``generate_study(out_dir, preset="default", seed=None)`` writes a study folder in the raw
formats a lab hands over (C3D, scan logs, rater annotations, trial sheet, subject table)
plus ``truth/`` for tests.  See ``docs/simulator.md`` for the physical reasoning.
"""
from __future__ import annotations

from pathlib import Path


def generate_study(out_dir: Path, preset: str | dict = "default", seed: int | None = None
                   ) -> Path:
    """Write a simulated study into ``out_dir``; returns the trial sheet's path.

    See :func:`gaitval.simulate.study.generate_study`.
    """
    from gaitval.simulate.study import generate_study as _gen
    return _gen(out_dir, preset, seed)


__all__ = ["generate_study"]
