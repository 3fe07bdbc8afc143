"""Registries: one per tracker role, so a new part is one class plus one registry line.

A *role* is a slot of a tracker (detector, filter, motion model, gate, associator,
occlusion handler).  Each role has a small base class and a :class:`Registry` mapping a
config name to an implementation.  A method (``gaitval.methods``) names one part per role
and its parameters; :meth:`Registry.build` turns such a spec into an object.

Examples
--------
>>> from gaitval.registry import Registry
>>> SHAPES = Registry("shape")
>>> @SHAPES.register("square")
... class Square:
...     def __init__(self, side=1.0):
...         self.side = side
>>> SHAPES.build({"name": "square", "side": 2.0}).side
2.0
"""
from __future__ import annotations

from typing import Any, Callable

from gaitval.errors import ConfigError


class Registry:
    """Name → implementation table of one role.

    Parameters
    ----------
    role : str
        The role's name, used in error messages (e.g. ``"associator"``).
    """

    def __init__(self, role: str):
        self.role = role
        self._items: dict[str, type] = {}

    def register(self, name: str) -> Callable[[type], type]:
        """Class decorator that lists the class under ``name``."""
        def deco(cls: type) -> type:
            if name in self._items:
                raise ValueError(f"{self.role} {name!r} registered twice")
            self._items[name] = cls
            cls.registry_name = name
            return cls
        return deco

    def names(self) -> list[str]:
        return sorted(self._items)

    def __contains__(self, name: str) -> bool:
        return name in self._items

    def __getitem__(self, name: str) -> type:
        try:
            return self._items[name]
        except KeyError:
            raise ConfigError(
                f"unknown {self.role} {name!r}",
                hint=f"choose one of: {', '.join(self.names())}") from None

    def build(self, spec: str | dict[str, Any] | Any) -> Any:
        """Build an implementation from ``"name"`` or ``{"name": ..., **params}``.

        An object that is already built (not a str or dict) is returned unchanged, so a
        caller may pass ready parts.
        """
        if isinstance(spec, str):
            spec = {"name": spec}
        if not isinstance(spec, dict):
            return spec
        params = dict(spec)
        try:
            name = params.pop("name")
        except KeyError:
            raise ConfigError(f"{self.role} spec {spec!r} has no 'name'",
                              hint=f"add name: one of {', '.join(self.names())}") from None
        cls = self[name]
        try:
            return cls(**params)
        except TypeError as exc:
            raise ConfigError(f"bad parameters for {self.role} {name!r}: {exc}",
                              hint="check the method's parameter names") from None
