"""Configuration helpers shared by every stage: one deep-merge for config layers.

A study's analysis configuration is built in layers (built-in defaults, the workflow's
``config/config.yaml``, the study's ``study.yaml``, per-method overrides); every layer is
merged with :func:`deep_merge`.
"""
from __future__ import annotations

import copy
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
