"""The C3D format's own facts, and the structural checks made before ezc3d opens a file.

Part of :mod:`gaitval.io.c3d` (the conventions are in its notes): units and event columns
shared by the reader and the writer, the processor types, the header and parameter-section
checks that turn a bad file into a :class:`~gaitval.errors.FileFormatError` instead of a
crash or a minute-long stall inside ezc3d [1]_, and opening a file with ezc3d.

References
----------
.. [1] Michaud, B., & Begon, M. (2021). ezc3d: An easy C3D file I/O cross-platform
   solution for C++, Python and MATLAB. Journal of Open Source Software, 6(58), 2911.
.. [2] Motion Lab Systems (2008). The C3D File Format User Guide. https://www.c3d.org
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from gaitval.errors import FileFormatError

#: metres per file unit
UNIT_SCALE = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
EVENT_COLUMNS = ["context", "label", "t_s"]
_PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS (SGI)"}


def _precheck(path: Path, trial: str | None) -> dict[str, Any]:
    """Check the file exists and looks like a C3D file before ezc3d sees it.

    Returns the processor type and the header's first/last frame words (Intel files).  Raises FileFormatError for a missing file, a file that is
    not C3D, or a processor type ezc3d cannot read (MIPS/SGI big-endian files).
    """
    if not path.is_file():
        raise FileFormatError("C3D file not found", path=path, trial=trial)
    with open(path, "rb") as fh:
        head = fh.read(512)
        if len(head) < 512 or head[1] != 0x50:
            raise FileFormatError("not a C3D file (the header's second byte is not 0x50)",
                                  path=path, trial=trial)
        param_block = head[0]
        fh.seek(max(param_block - 1, 0) * 512)
        phead = fh.read(4)
    if len(phead) < 4:
        raise FileFormatError(f"C3D file is truncated: the parameter section (block "
                              f"{param_block}) lies beyond the end of the file",
                              path=path, trial=trial)
    proc = _PROCESSORS.get(phead[3])
    if proc is None:
        raise FileFormatError(f"unknown C3D processor type {phead[3]} (expected 84 Intel, "
                              "85 DEC or 86 MIPS)", path=path, trial=trial)
    if proc.startswith("MIPS"):
        raise FileFormatError("C3D file uses the MIPS (SGI) big-endian processor format, "
                              "which ezc3d cannot read", path=path, trial=trial,
                              hint="convert it to Intel format, e.g. by opening and saving "
                                   "it in Mokka or Vicon Nexus")
    problem = _walk_parameters(path)
    if problem:
        raise FileFormatError(f"the C3D parameter section is corrupt: {problem}",
                              path=path, trial=trial,
                              hint="re-export the file from the capture software")
    # header words 4 and 5 (1-based, 16-bit): first and last frame of the 3-D data
    first_w, last_w = (int.from_bytes(head[i:i + 2], "little") for i in (6, 8))
    return {"processor": proc, "first_frame_word": first_w, "last_frame_word": last_w}


def _walk_parameters(path: Path) -> str | None:
    """Walk the parameter section's linked list; return the first structural problem.

    C3D User Guide: each group/parameter record is ``name length (int8, negative = locked),
    id (int8, negative = group), name, offset to the next record (int16)``; a parameter
    then has ``type (int8), n_dims (uint8), dims, data``.  ezc3d 1.7.2 spends tens of
    seconds (or crashes) on some corrupt sections, so gaitval checks the chain first:
    printable names, pointers that stay inside the file, data that fits before the next
    record.  Little-endian (Intel/DEC) files only; returns None when the chain is sound.
    """
    b = path.read_bytes()
    i = (b[0] - 1) * 512 + 4
    last = "the section start"
    groups: dict[int, str] = {}
    for _ in range(100_000):
        if i + 2 > len(b):
            return f"the record after {last} lies beyond the end of the file"
        nch = int.from_bytes(b[i:i + 1], "little", signed=True)
        gid = int.from_bytes(b[i + 1:i + 2], "little", signed=True)
        if nch == 0 or gid == 0:
            return None                                   # end of the parameter section
        name = b[i + 2:i + 2 + abs(nch)]
        if len(name) < abs(nch) or not all(0x20 <= c <= 0x7E for c in name):
            return f"the record after {last} has an unreadable name {name!r}"
        p = i + 2 + abs(nch)
        nxt = int.from_bytes(b[p:p + 2], "little", signed=True)
        label = name.decode("ascii")
        if gid < 0:
            groups[-gid] = label
        else:
            label = f"{groups.get(gid, f'group {gid}')}:{label}"
            t = int.from_bytes(b[p + 2:p + 3], "little", signed=True)
            nd = b[p + 3] if p + 3 < len(b) else 0
            size = abs(t)
            for d in b[p + 4:p + 4 + nd]:
                size *= d
            end = p + 4 + nd + size
            if nxt > 0 and end > p + nxt:
                return (f"parameter {label} holds {size} bytes of data, "
                        f"more than the {nxt - 4 - nd} bytes before the next record "
                        "(bad parameter offset)")
        if nxt == 0:
            return None                                   # last record
        if nxt < 0 or p + nxt >= len(b):
            return f"record {label} points to the next record at offset {nxt}, outside the file"
        last = f"{'group' if gid < 0 else 'parameter'} {label}"
        i = p + nxt
    return "the parameter section does not end"


def _ezc3d_reason(exc: Exception) -> str:
    """Turn an ezc3d exception into one sentence a user can act on."""
    msg = str(exc).replace(": iostream error", "").strip()
    low = msg.lower()
    if "format is not standard" in low:
        return ("the parameter section does not follow the C3D standard (ezc3d: non-standard "
                "format); re-export the file from the capture software")
    if "offset parameter is not an int" in low:
        return ("the ANALOG:OFFSET parameter is not of type INT, as the C3D standard requires "
                "(ezc3d: OFFSET parameter is not an INT)")
    if "processor type not supported" in low:
        return f"unsupported processor type (ezc3d: {msg})"
    if "valid c3d" in low:
        return "not a valid C3D file (ezc3d cannot parse the header)"
    return f"ezc3d cannot read it: {type(exc).__name__}: {msg}"


def _open_ezc3d(path: Path, trial: str | None):
    """ezc3d.c3d(path) with every failure turned into one FileFormatError.

    ``ignore_bad_formatting`` is deliberately never used: with ezc3d 1.7.2 it crashes the
    interpreter (segmentation fault) on ``c3dorg_sample18_bad_parameter_section.c3d``.
    """
    import ezc3d

    try:
        return ezc3d.c3d(str(path))
    except Exception as exc:  # ezc3d raises OSError, RuntimeError, ValueError, IndexError
        raise FileFormatError(_ezc3d_reason(exc), path=path, trial=trial) from None
