"""Registries: one per tracker role, so a new part is one class plus one registry line.

A *role* is a slot of a tracker (detector, filter, motion model, gate, associator,
occlusion handler).  Each role has a small base class and a :class:`Registry` mapping a
config name to an implementation.  A method (``gaitval.methods``) names one part per role
and its parameters; :meth:`Registry.build` turns such a spec into an object.

A registry is filled either by the ``register`` decorator on each class, or from a
*table module* named when it is made (``Registry("filter", table="gaitval.track.roles")``):
the module that lists every part of the role and adds each with :meth:`Registry.add`,
imported the first time the registry is read, so the registry is complete whatever was
imported before.

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

import importlib
from typing import Any, Callable

from gaitval.errors import ConfigError


class Registry:
    """Name → implementation table of one role.

    Parameters
    ----------
    role : str
        The role's name, used in error messages (e.g. ``"associator"``).
    table : str or None
        The module that adds the role's parts (imported when the registry is first read).
    """

    def __init__(self, role: str, table: str | None = None):
        self.role = role
        self._items: dict[str, type] = {}
        self._table = table

    def _load(self) -> None:
        if self._table is not None:
            table, self._table = self._table, None
            importlib.import_module(table)

    def add(self, name: str, cls: type) -> type:
        """List ``cls`` under ``name``."""
        if name in self._items:
            raise ValueError(f"{self.role} {name!r} registered twice")
        self._items[name] = cls
        cls.registry_name = name
        return cls

    def register(self, name: str) -> Callable[[type], type]:
        """Class decorator that lists the class under ``name``."""
        return lambda cls: self.add(name, cls)

    def names(self) -> list[str]:
        self._load()
        return sorted(self._items)

    def __contains__(self, name: str) -> bool:
        self._load()
        return name in self._items

    def __getitem__(self, name: str) -> type:
        self._load()
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
