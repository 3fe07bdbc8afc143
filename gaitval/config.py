"""Configuration helpers shared by every stage: one deep-merge for config layers, one way
to pick a stage's section, one way to read an optional number from a trial-sheet cell.

A study's analysis configuration is built in layers (built-in defaults, the workflow's
``config/config.yaml``, the study's ``study.yaml``, per-method overrides); every layer is
merged with :func:`deep_merge`.  A stage takes the whole config or its own section
(:func:`section`); empty trial-sheet and subject-table cells are "not given"
(:func:`as_float`).
"""
from __future__ import annotations

import copy
import math
from typing import Any


def deep_merge(base: dict[str, Any], over: dict[str, Any] | None) -> dict[str, Any]:
    """A new dict: ``base`` with ``over`` merged in, recursively for nested dicts.

    Neither argument is modified (values are deep-copied), so a merged config never
    aliases a default.

    >>> deep_merge({"a": {"b": 1, "c": 2}}, {"a": {"c": 3}, "d": 4})
    {'a': {'b': 1, 'c': 3}, 'd': 4}
    """
    out = copy.deepcopy(base)
    for k, v in (over or {}).items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def section(cfg: dict[str, Any] | None, name: str) -> dict[str, Any]:
    """The ``name:`` section of a config dict, or the dict itself when it has no such key.

    Every stage accepts either the whole analysis config or its own section alone, so
    ``section({"registration": {"a": 1}}, "registration")`` and
    ``section({"a": 1}, "registration")`` are both ``{"a": 1}`` (a shallow copy).

    >>> section({"registration": {"a": 1}, "groundtruth": {}}, "registration")
    {'a': 1}
    >>> section(None, "groundtruth")
    {}
    """
    cfg = cfg or {}
    sub = cfg.get(name)
    return dict(sub) if isinstance(sub, dict) else dict(cfg)


def as_float(v: Any) -> float | None:
    """A trial-sheet / subject-table cell as float, or None when empty, NaN or unparseable.

    Optional numeric columns (``sensor_height_m``, ``clock_offset_s``, ``leg_width_m``,
    joint widths) are read with this one rule: an empty cell means "not given".

    >>> as_float(" 0.27 "), as_float(""), as_float(None), as_float("nan"), as_float("n/a")
    (0.27, None, None, None, None)
    """
    if v is None:
        return None
    if isinstance(v, str) and not v.strip():
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None
