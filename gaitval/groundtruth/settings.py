"""The ``groundtruth:`` configuration section: its keys, their defaults, and one reader.

Every module of the ground truth reads its settings through :func:`gt_cfg`, which accepts
the whole analysis config or the section alone and ignores the keys of other stages.
"""
from __future__ import annotations

from gaitval.config import section
from gaitval.groundtruth.gaps import MAX_GAP_S

#: Defaults of the ``groundtruth:`` config keys.
DEFAULTS = {
    "max_gap_s": MAX_GAP_S,
    "lowpass_hz": 10.0,
    "lowpass_order": 2,
    "filter_positions": False,
    "leg_point": "auto",            # auto | axis | cylinder
    "cylinder_marker_offset_m": 0.009,
    "tibia_markers": ["TB1", "TB2", "TB3", "TB4"],   # prefixed with L/R
    "tx_marker": "TX",
    "anchor_markers": ["ANC1", "ANC2", "ANC3", "ANC4"],
}


def gt_cfg(cfg: dict | None) -> dict:
    """The ``groundtruth:`` section (or ``cfg`` itself when it has none) restricted to the
    keys of :data:`DEFAULTS`, defaults filled in."""
    c = dict(DEFAULTS)
    c.update({k: v for k, v in section(cfg, "groundtruth").items() if k in DEFAULTS})
    return c
