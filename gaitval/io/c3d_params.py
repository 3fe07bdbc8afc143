"""The C3D parameter section, parsed and checked in pure Python before ezc3d sees it.

Part of :mod:`gaitval.io.c3d` (see :mod:`gaitval.io.c3d_format` for the header and data
checks).  ezc3d 1.7.2 [1]_ trusts the section: a parameter whose type byte is wrong
(``0xFF`` makes POINT:USED a character parameter), a control byte in a text, or a pointer
out of the file crashes the interpreter (segmentation fault) or makes it
loop.  :func:`parse_parameters` walks the section's linked list once and raises
:class:`ParameterProblem` naming the group, parameter and field for anything ezc3d could
trip on; :class:`Parameters` then gives typed values of the parameters gaitval and ezc3d
read.  Text (values and descriptions) is UTF-8 or, failing that, CP-1252 or Latin-1
(:func:`text_encoding`): real files written on Windows hold "mm/s\u00b2" as byte 0xB2.

C3D User Guide [2]_, parameter section: a 4-byte header (byte 3 = number of parameter
blocks, byte 4 = processor type 83 + n), then records ``name length (int8, negative =
locked), id (int8, negative = group, positive = the group a parameter belongs to), name,
offset to the next record (int16, from the offset field; 0 = last)``; a group then has
``description length (uint8), description``, a parameter ``type (int8: -1 char, 1 byte,
2 int16, 4 float), number of dimensions (uint8), dimensions (uint8 each), data,
description length (uint8), description``.

References
----------
.. [1] Michaud, B., & Begon, M. (2021). ezc3d: An easy C3D file I/O cross-platform
   solution for C++, Python and MATLAB. Journal of Open Source Software, 6(58), 2911.
.. [2] Motion Lab Systems (2008). The C3D File Format User Guide. https://www.c3d.org
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass

TYPES = {-1: "char", 1: "byte", 2: "int16", 4: "float"}
_NAME_BYTES = frozenset(range(0x20, 0x7F))      # printable ASCII (Vicon: "Marker Diameter")
_TEXT_CONTROL = frozenset(range(0x20)) - {0x00, 0x09, 0x0A, 0x0D}

#: parameters ezc3d or gaitval read as numbers (anything else there crashes ezc3d)
NUMERIC = {("POINT", "USED"), ("POINT", "RATE"), ("POINT", "SCALE"), ("POINT", "FRAMES"),
           ("POINT", "DATA_START"), ("ANALOG", "USED"), ("ANALOG", "RATE"),
           ("ANALOG", "SCALE"), ("ANALOG", "GEN_SCALE"), ("ANALOG", "OFFSET"),
           ("ANALOG", "BITS"), ("FORCE_PLATFORM", "USED"), ("FORCE_PLATFORM", "TYPE"),
           ("FORCE_PLATFORM", "ZERO"), ("FORCE_PLATFORM", "CORNERS"),
           ("FORCE_PLATFORM", "ORIGIN"), ("FORCE_PLATFORM", "CHANNEL"),
           ("FORCE_PLATFORM", "CAL_MATRIX"), ("TRIAL", "CAMERA_RATE"),
           ("TRIAL", "ACTUAL_START_FIELD"), ("TRIAL", "ACTUAL_END_FIELD"),
           ("EVENT", "USED"), ("EVENT", "TIMES"), ("ROTATION", "USED"),
           ("ROTATION", "RATE"), ("ROTATION", "DATA_START"), ("SUBJECTS", "USED")}
#: of those, the ones ezc3d reads a first value of (an empty one crashes it)
SCALAR = {("POINT", "USED"), ("POINT", "RATE"), ("POINT", "SCALE"), ("POINT", "FRAMES"),
          ("POINT", "DATA_START"), ("ANALOG", "USED"), ("ANALOG", "RATE"),
          ("ANALOG", "GEN_SCALE"), ("FORCE_PLATFORM", "USED"), ("TRIAL", "CAMERA_RATE"),
          ("ROTATION", "USED"), ("ROTATION", "RATE"), ("ROTATION", "DATA_START"),
          ("EVENT", "USED"), ("SUBJECTS", "USED")}
#: parameters read as text
TEXT = {("POINT", "UNITS"), ("POINT", "LABELS"), ("POINT", "DESCRIPTIONS"),
        ("ANALOG", "LABELS"), ("ANALOG", "UNITS"), ("ANALOG", "FORMAT"),
        ("EVENT", "LABELS"), ("EVENT", "CONTEXTS"), ("EVENT", "DESCRIPTIONS"),
        ("MANUFACTURER", "COMPANY"), ("MANUFACTURER", "SOFTWARE"), ("SUBJECTS", "NAMES")}


class ParameterProblem(Exception):
    """A structural problem of the parameter section (message names group/parameter)."""


@dataclass
class Param:
    """One parameter: its type code, dimensions and raw data bytes."""

    group: str
    name: str
    type: int
    dims: tuple[int, ...]
    data: bytes
    #: where ``data`` starts in the file (bytes from the file's start; -1 when unknown)
    offset: int = -1

    @property
    def label(self) -> str:
        return f"{self.group}:{self.name}"

    @property
    def encoding(self) -> str | None:
        """The text encoding of a character parameter (:func:`text_encoding`), else None."""
        return text_encoding(self.data) if self.type == -1 else None

    @property
    def count(self) -> int:
        return math.prod(self.dims) // (self.dims[0] if self.type == -1 and self.dims else 1)


#: text encodings tried in turn (C3D text written on Windows is often CP-1252 or Latin-1;
#: Latin-1 decodes any byte, so it is the last resort)
ENCODINGS = ("utf-8", "cp1252", "latin-1")


def text_encoding(raw: bytes) -> str:
    """The first of :data:`ENCODINGS` that decodes ``raw``."""
    for enc in ENCODINGS[:-1]:
        try:
            raw.decode(enc)
            return enc
        except UnicodeDecodeError:
            pass
    return ENCODINGS[-1]


def decode_text(raw: bytes) -> str:
    """``raw`` decoded with :func:`text_encoding` (never fails)."""
    return raw.decode(text_encoding(raw))


def _text_problem(raw: bytes) -> str | None:
    """Why ``raw`` is not safe text for ezc3d (no control characters), or None.  Bytes
    that are not UTF-8 are read as CP-1252/Latin-1 (:func:`text_encoding`); ezc3d passes
    them through (as surrogates), and the reader decodes them the same way."""
    bad = next((c for c in raw if c in _TEXT_CONTROL), None)
    return None if bad is None else f"control byte 0x{bad:02X}"


def parse_parameters(b: bytes, start: int, end: int) -> dict[tuple[str, str], Param]:
    """Every parameter of the section ``b[start:end]`` (``start`` at the section's header).

    Raises
    ------
    ParameterProblem
        A record that leaves the section, an unreadable name, an unknown type, data that
        overruns its record, a description or text value with control bytes, a parameter
        of an unknown group, or a chain that does not end.
    """
    groups: dict[int, str] = {}
    raw: list[tuple[int, str, int, tuple[int, ...], bytes, int]] = []
    i, last = start + 4, "the section start"
    for _ in range(100_000):
        if i + 2 > end:
            raise ParameterProblem(f"the record after {last} lies beyond the section")
        nch, gid = struct.unpack_from("<bb", b, i)
        if nch == 0 or gid == 0:
            break                                              # end of the section
        name_b = b[i + 2:i + 2 + abs(nch)]
        if len(name_b) < abs(nch) or not set(name_b) <= _NAME_BYTES:
            raise ParameterProblem(f"the record after {last} has an unreadable name "
                                   f"{name_b!r}")
        name, p = name_b.decode("ascii").upper(), i + 2 + abs(nch)
        if p + 2 > end:
            raise ParameterProblem(f"record {name} is cut off by the end of the section")
        nxt = struct.unpack_from("<h", b, p)[0]
        rec_end = p + nxt if nxt > 0 else end
        if nxt < 0 or rec_end > end:
            raise ParameterProblem(f"record {name} points to its successor at offset {nxt}, "
                                   "outside the parameter section")
        if gid < 0:
            _group_record(b, p + 2, rec_end, name, groups, -gid)
            last = f"group {name}"
        else:
            raw.append((gid, name, *_param_record(b, p + 2, rec_end, name)))
            last = f"parameter {name}"
        if nxt == 0:
            break
        i = rec_end
    else:
        raise ParameterProblem("the parameter section does not end")
    return _assemble(groups, raw)


def _group_record(b: bytes, q: int, rec_end: int, name: str, groups: dict, gid: int
                  ) -> None:
    if gid in groups:
        raise ParameterProblem(f"group id {gid} is used by both {groups[gid]} and {name}")
    if q >= rec_end:
        raise ParameterProblem(f"group {name} has no description length byte")
    desc = b[q + 1:q + 1 + b[q]]
    if q + 1 + b[q] > rec_end:
        raise ParameterProblem(f"the description of group {name} overruns its record")
    why = _text_problem(desc)
    if why:
        raise ParameterProblem(f"the description of group {name} is unreadable: {why}")
    groups[gid] = name


def _param_record(b: bytes, q: int, rec_end: int, name: str
                  ) -> tuple[int, tuple[int, ...], bytes, int]:
    if q + 2 > rec_end:
        raise ParameterProblem(f"parameter {name} is cut off before its type")
    ptype, nd = struct.unpack_from("<bB", b, q)
    if ptype not in TYPES:
        raise ParameterProblem(f"parameter {name} has type {ptype} (byte 0x{ptype & 0xFF:02X}"
                               "); a C3D type is -1 char, 1 byte, 2 int16 or 4 float")
    if nd > 7:
        raise ParameterProblem(f"parameter {name} has {nd} dimensions (at most 7)")
    dims = tuple(b[q + 2:q + 2 + nd])
    size = abs(ptype) * math.prod(dims)
    d0 = q + 2 + nd
    if d0 + size + 1 > rec_end:
        raise ParameterProblem(f"parameter {name} holds {size} bytes of data, more than its "
                               "record has room for (bad parameter offset or dimensions)")
    dlen = b[d0 + size]
    if d0 + size + 1 + dlen > rec_end:
        raise ParameterProblem(f"the description of parameter {name} overruns its record")
    why = _text_problem(b[d0 + size + 1:d0 + size + 1 + dlen])
    if why:
        raise ParameterProblem(f"the description of parameter {name} is unreadable: {why}")
    return ptype, dims, bytes(b[d0:d0 + size]), d0


def _assemble(groups: dict[int, str], raw: list) -> dict[tuple[str, str], Param]:
    params: dict[tuple[str, str], Param] = {}
    for gid, name, ptype, dims, data, offset in raw:
        if gid not in groups:
            raise ParameterProblem(f"parameter {name} belongs to group id {gid}, which the "
                                   "section does not define")
        key = (groups[gid], name)
        p = Param(key[0], name, ptype, dims, data, offset)
        if key in NUMERIC and ptype == -1:
            raise ParameterProblem(f"{p.label} must be a number but is stored as text "
                                   "(type -1)")
        if key in TEXT and ptype != -1:
            raise ParameterProblem(f"{p.label} must be text but is stored as "
                                   f"{TYPES[ptype]} (type {ptype})")
        if ptype == -1 and not dims:
            raise ParameterProblem(f"text parameter {p.label} has no dimensions")
        if key in SCALAR and not data:
            raise ParameterProblem(f"{p.label} holds no value (a dimension is 0)")
        if ptype == -1:
            why = _text_problem(data.replace(b"\x00", b" "))
            if why:
                raise ParameterProblem(f"the text of {p.label} is unreadable: {why}")
        params.setdefault(key, p)      # Nexus writes some twice (PROCESSING:BODYMASS)
    return params


class Parameters:
    """Typed access to parsed parameters (``dec``: floats in DEC (VAX) format)."""

    def __init__(self, params: dict[tuple[str, str], Param], dec: bool):
        self.params, self.dec = params, dec

    def __contains__(self, key: tuple[str, str]) -> bool:
        return key in self.params

    def numbers(self, group: str, name: str) -> list[float] | None:
        """All values of a numeric parameter as floats (None when absent)."""
        p = self.params.get((group, name))
        if p is None or p.type == -1:
            return None
        if p.type == 1:
            return [float(v) for v in struct.unpack(f"<{len(p.data)}b", p.data)]
        if p.type == 2:
            return [float(v) for v in struct.unpack(f"<{len(p.data) // 2}h", p.data)]
        return [float_at(p.data, 4 * k, self.dec) for k in range(len(p.data) // 4)]

    def first(self, group: str, name: str) -> float | None:
        vals = self.numbers(group, name)
        return vals[0] if vals else None

    def count(self, group: str, name: str) -> float | None:
        """The first value of a count (``USED``, ``FRAMES``): integers are unsigned in C3D
        (a 40,000-frame capture stores POINT:FRAMES as int16 -25,536)."""
        v = self.first(group, name)
        p = self.params.get((group, name))
        if v is not None and p is not None and p.type in (1, 2) and v < 0:
            v += 256.0 if p.type == 1 else 65536.0
        return v


def float_at(b: bytes, i: int, dec: bool) -> float:
    """The 4-byte float at ``b[i]``: IEEE little-endian, or DEC (VAX F) for processor 85."""
    if not dec:
        return struct.unpack_from("<f", b, i)[0]
    swapped = bytes((b[i + 2], b[i + 3], b[i], b[i + 1]))    # DEC: 16-bit words swapped,
    return struct.unpack("<f", swapped)[0] / 4.0              # exponent bias 2 higher
