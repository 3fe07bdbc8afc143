"""Declared parameters: each part's parameters written once, with unit and source.

A role's part (a filter, a gate, …) is a dataclass whose fields are its parameters, each
declared with :func:`param`: default, unit and where the value comes from (a paper's
equation or table, or ``"no source"`` for gaitval's own choices).  The constructor
(what :meth:`gaitval.registry.Registry.build` and the method overrides call), the
class's ``Parameters`` documentation (:func:`declared`) and the reference table of
``docs/tracking.md`` (:func:`markdown_table`, checked by ``tests/test_track_roles.py``) are
all drawn from that one declaration.

Examples
--------
>>> from dataclasses import dataclass
>>> @declared
... @dataclass(eq=False)
... class Gate:
...     '''A gate.'''
...     g: float = param(13.82, "λ²", "seed000 Table 2", "G, the gate's size")
>>> Gate().g
13.82
>>> print(Gate.__doc__.splitlines()[-1])
        G, the gate's size [λ²; default 13.82; seed000 Table 2].
"""
from __future__ import annotations

import dataclasses
import inspect
from typing import Any, NamedTuple

NO_SOURCE = "no source"


class Declared(NamedTuple):
    """One declared parameter of a part."""

    name: str
    default: Any
    unit: str
    source: str
    doc: str


def param(default, unit: str, source: str, doc: str):
    """A dataclass field declaring one parameter (``unit`` ``"-"`` for a plain number or a
    choice; ``source`` a paper's equation/table or :data:`NO_SOURCE`)."""
    return dataclasses.field(default=default, metadata={"unit": unit, "source": source,
                                                         "doc": doc})


def parameters(cls) -> list[Declared]:
    """The declared parameters of a part's class (fields made with :func:`param`), in
    constructor order; none for a class that is not a dataclass itself (e.g. one that
    derives from a declared part but has a constructor of its own)."""
    if "__dataclass_fields__" not in vars(cls):
        return []
    return [Declared(f.name, f.default, f.metadata["unit"], f.metadata["source"],
                     f.metadata["doc"])
            for f in dataclasses.fields(cls) if f.init and "unit" in f.metadata]


def param_of(cls, name: str):
    """A field declaring the parameter ``name`` exactly as ``cls`` declares it (a part that
    passes one of its parameters on to another part declares it once, there)."""
    f = next(f for f in dataclasses.fields(cls) if f.name == name)
    return dataclasses.field(default=f.default, metadata=f.metadata)


def coerce(part) -> None:
    """Convert each declared number of ``part`` to its default's type (``int``, ``float``,
    ``bool``): a configuration may write ``1`` for ``1.0`` or ``1.0`` for ``1``."""
    for f in dataclasses.fields(part):
        if type(f.default) in (int, float, bool):
            setattr(part, f.name, type(f.default)(getattr(part, f.name)))


def declared(cls):
    """Class decorator (above ``@dataclass``): appends the ``Parameters`` section, drawn
    from the declarations, to the class's docstring."""
    rows = parameters(cls)
    if rows:
        lines = ["", "", "    Parameters", "    ----------"]
        for p in rows:
            lines += [f"    {p.name}",
                      f"        {p.doc} [{p.unit}; default {p.default!r}; {p.source}]."]
        cls.__doc__ = (cls.__doc__ or "").rstrip() + "\n".join(lines)
    return cls


def _shown(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) else repr(value)


def markdown_table(registries: dict[str, Any]) -> str:
    """One Markdown table of every declared parameter of the parts of ``registries``
    (``{role key: Registry}``): role, part, parameter, default, unit, source.  A part
    without declarations gets one row saying so (its class documents its parameters)."""
    out = ["| role | part | parameter | default | unit | source |",
           "|---|---|---|---|---|---|"]
    for role, reg in registries.items():
        for name in reg.names():
            rows = parameters(reg[name])
            if not rows:
                what = ("(no parameters)" if not inspect.signature(reg[name]).parameters
                        else f"(not declared: see `{reg[name].__qualname__}`)")
                out.append(f"| `{role}` | `{name}` | {what} | | | |")
            for p in rows:
                out.append(f"| `{role}` | `{name}` | `{p.name}` | `{_shown(p.default)}` | "
                           f"{p.unit} | {p.source} |")
    return "\n".join(out) + "\n"
