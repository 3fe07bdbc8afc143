"""The keys of ``tracking.overrides`` checked against the methods' parts (:mod:`gaitval.methods`):
each ``<role>__<param>`` must name a role of its method and a parameter of the part that
role builds, so a typo fails at the start of a run, naming the key and the nearest valid
one (docs/tracking.md).
"""
from __future__ import annotations

import difflib
import inspect
from typing import Any

from gaitval.configcheck import Problem
from gaitval.detect import DETECTORS
from gaitval.errors import ConfigError
from gaitval.methods import ROLES, get_method
from gaitval.track.associate import ASSOCIATORS
from gaitval.track.gate import GATES
from gaitval.track.init import INITIALISERS
from gaitval.track.kalman import FILTERS
from gaitval.track.kinds import TRACKER_KINDS
from gaitval.track.motion import MOTION_MODELS
from gaitval.track.occlusion import OCCLUSION_HANDLERS
from gaitval.track.phase import PHASE_MODELS
from gaitval.track.tracker import Tracker


#: role -> the registry its ``name`` is looked up in (``tracker`` is the loop itself)
ROLE_REGISTRIES = {"detector": DETECTORS, "filter": FILTERS, "motion": MOTION_MODELS,
                   "phase": PHASE_MODELS, "gate": GATES, "associator": ASSOCIATORS,
                   "occlusion": OCCLUSION_HANDLERS, "init": INITIALISERS,
                   "kind": TRACKER_KINDS}


def _parameters(cls) -> list[str] | None:
    """The keyword parameters of ``cls(...)``; None when it takes any (``**kwargs``)."""
    params = inspect.signature(cls).parameters.values()
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return None
    return [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def _did_you_mean(word: str, choices, fmt=str) -> str:
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f" — did you mean {fmt(close[0])}?" if close else ""


def override_problems(overrides: dict[str, Any] | None,
                      definitions: dict[str, Any]) -> list[Problem]:
    """Every key of ``tracking.overrides`` that names no method, role or parameter.

    ``definitions`` maps each method that may be overridden to its definition (a
    built-in name or a dict).  An override ``<role>__<param>`` must name a role of the
    method and a parameter of the part that role builds (after a ``<role>__name``
    override, of the new part), so a typo fails at the start of a run, naming the key and
    the nearest valid one, instead of failing inside the tracking jobs.
    """
    out = []
    for method, ov in (overrides or {}).items():
        path = ("tracking", "overrides", method)
        if method not in definitions:
            out.append(Problem(path, f"tracking.overrides.{method}: no method {method!r}"
                               + _did_you_mean(method, definitions,
                                               lambda m: f"tracking.overrides.{m}")
                               + f" (methods: {', '.join(sorted(definitions))})"))
            continue
        if not isinstance(ov, dict):
            continue                                  # the schema says what is wrong
        try:
            m = get_method(definitions[method])
        except ConfigError as exc:
            out.append(Problem(path, f"tracking.overrides.{method}: {exc}"))
            continue
        roles = [r for r in m if isinstance(m[r], (dict, str)) and
                 (r in ROLE_REGISTRIES or r == "tracker")]
        for key in ov:
            problem = _key_problem(method, m, ov, str(key), roles, path + (key,))
            if problem is not None:
                out.append(problem)
    return out


def _key_problem(method: str, m: dict, ov: dict, key: str, roles: list[str],
                 kpath: tuple) -> Problem | None:
    """The problem of one override key ``<role>__<param>`` of ``method`` (definition
    ``m``, its overrides ``ov``; :func:`override_problems`), None when it names a role and
    a parameter of the part that role builds."""
    role, sep, param = key.partition("__")
    where = f"tracking.overrides.{method}.{key}"
    if not sep:
        return None                           # the schema's pattern says it
    if role not in roles:
        return Problem(kpath, f"{where}: {method} has no role {role!r}"
                       + _did_you_mean(role, roles, lambda r: f"{r}__{param}")
                       + f" (roles: {', '.join(roles)})")
    spec = m[role] if isinstance(m[role], dict) else {"name": m[role]}
    if role == "tracker":
        cls, what = Tracker, "the tracker loop"
        valid = [p for p in _parameters(Tracker) or [] if p not in ROLES]
    else:
        registry = ROLE_REGISTRIES[role]
        name = ov.get(f"{role}__name", spec.get("name"))
        if param == "name":
            if name not in registry:
                return Problem(kpath, f"{where}: no {registry.role} "
                               f"{name!r}" + _did_you_mean(str(name), registry.names())
                               + f" (choose one of: {', '.join(registry.names())})")
            return None
        if name not in registry:
            return None                       # reported on its name key
        cls, what = registry[name], f"the {registry.role} {name!r}"
        valid = _parameters(cls)
    if valid is None or param in valid:
        return None
    return Problem(kpath, f"{where}: {what} of {method} has no parameter {param!r}"
                   + _did_you_mean(param, valid, lambda p: f"{role}__{p}")
                   + f" (its parameters: {', '.join(valid) or 'none'})")

def check_overrides(overrides: dict[str, Any] | None, definitions: dict[str, Any]) -> None:
    """Raise :class:`ConfigError` for the first of :func:`override_problems`."""
    from gaitval.configcheck import raise_problems

    raise_problems(override_problems(overrides, definitions))
