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

import math
import struct
from pathlib import Path
from typing import Any

from gaitval.errors import FileFormatError
from gaitval.io.c3d_params import ParameterProblem, Parameters, float_at, parse_parameters

#: metres per file unit
UNIT_SCALE = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
EVENT_COLUMNS = ["context", "label", "t_s"]
_PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS (SGI)"}
#: highest point or analog rate accepted (Hz): motion capture runs at up to a few kHz and
#: force plates at up to ~20 kHz; a rate above this is a corrupt parameter
MAX_RATE_HZ = 100_000.0
#: largest data section (bytes, as stored) gaitval hands to ezc3d, which needs ~10 times
#: as much memory to hold it (a 60,000-frame, 100-marker capture with analogs is ~150 MB)
MAX_DATA_BYTES = 512 * 2 ** 20
#: address space the ezc3d child may add to its parent's: a fixed allowance plus this
#: many bytes per stored byte (measured: ezc3d 1.7.2 holds 1.6 MB of data in ~16 MB, and
#: the child copies the points to numpy and pickles them)
EZC3D_MEMORY_BASE = 768 * 2 ** 20
EZC3D_MEMORY_PER_BYTE = 32
#: numeric parameters that must be finite and >= 0 (True) or > 0 (False) wherever present
_FINITE = ((("POINT", "RATE"), False), (("POINT", "FRAMES"), True),
           (("ANALOG", "RATE"), True), (("TRIAL", "CAMERA_RATE"), True),
           (("EVENT", "USED"), True), (("POINT", "USED"), True), (("ANALOG", "USED"), True))


def _precheck(path: Path, trial: str | None) -> dict[str, Any]:
    """Check the header, the parameter section and the data's size before ezc3d sees them.

    Returns the processor type, the header's first/last frame words and the frame count
    the file announces.  Raises FileFormatError for a missing file, a file that is not
    C3D, a processor type ezc3d cannot read (MIPS/SGI), a corrupt parameter section
    (:func:`gaitval.io.c3d_params.parse_parameters`), values that are not finite or
    contradict each other (header vs parameters), and a data section shorter than the
    frames it announces — for every processor type.
    """
    if not path.is_file():
        raise FileFormatError("C3D file not found", path=path, trial=trial)
    size = path.stat().st_size
    with open(path, "rb") as fh:
        head = fh.read(512)
        if len(head) < 512 or head[1] != 0x50:
            raise FileFormatError("not a C3D file (the header's second byte is not 0x50)",
                                  path=path, trial=trial)
        ps = (max(head[0], 1) - 1) * 512                    # parameter section offset
        fh.seek(ps)
        phead = fh.read(4)
        if len(phead) < 4:
            raise FileFormatError(f"C3D file is truncated: the parameter section (block "
                                  f"{head[0]}) lies beyond the end of the file ({size} "
                                  "bytes)", path=path, trial=trial)
        proc = _processor(phead[3], path, trial)
        hdr = _header(head)
        ds = (hdr["data_start"] - 1) * 512                  # data section offset
        if ds >= size:
            raise FileFormatError(f"C3D file is truncated: the data section (block "
                                  f"{hdr['data_start']}) lies beyond the end of the file "
                                  f"({size} bytes)", path=path, trial=trial)
        if head[0] < 2 or ds <= ps:
            raise FileFormatError(f"the C3D header is corrupt: parameters at block {head[0]}"
                                  f", data at block {hdr['data_start']}", path=path,
                                  trial=trial, hint="re-export the file from the capture "
                                                    "software")
        fh.seek(0)
        section = fh.read(ds)
    try:
        params = Parameters(parse_parameters(section, ps, ds), dec=proc == "DEC")
    except ParameterProblem as exc:
        raise FileFormatError(f"the C3D parameter section is corrupt: {exc}", path=path,
                              trial=trial, hint="re-export the file from the capture "
                                                "software") from None
    if proc == "DEC":                                      # header floats in DEC format
        hdr.update(scale=float_at(head, 12, True), rate=float_at(head, 20, True))
    expected, data_bytes = _check_layout(hdr, params, size, path, trial)
    return {"processor": proc, "first_frame_word": hdr["first"],
            "last_frame_word": hdr["last"], "frames_expected": expected,
            "data_bytes": data_bytes,
            "encodings": {p.label: p.encoding for p in params.params.values()
                          if p.type == -1 and p.encoding != "utf-8"},
            "frames_only": _frames_only_layout(hdr, params, proc, expected)}


def _frames_only_layout(hdr: dict, params: Parameters, proc: str, n_frames: int
                        ) -> dict[str, int] | None:
    """Where the frames of a file that holds nothing else lie, for :func:`_open_ezc3d`'s
    fast path: Intel floats, no analog samples, no rotations, 1 to 65,535 frames that fit
    the file.  None for any other file (ezc3d reads all of it)."""
    frames_p = params.params.get(("POINT", "FRAMES"))
    rot_used = params.count("ROTATION", "USED") or 0
    if (proc != "Intel" or not hdr["scale"] < 0 or hdr["n_analog"] or hdr["analog_per_frame"]
            or rot_used or not hdr["n_points"] or frames_p is None or frames_p.type != 2
            or not 1 <= n_frames <= 0xFFFF or hdr["last"] - hdr["first"] + 1 != n_frames):
        return None
    return {"data_start": hdr["data_start"], "n_points": hdr["n_points"],
            "n_frames": n_frames, "first": hdr["first"],
            "point_frames_offset": frames_p.offset}


def _header(head: bytes) -> dict[str, Any]:
    """The header words gaitval checks (C3D User Guide: 16-bit words 2-5, 9, 10; floats
    at words 7-8 and 11-12, IEEE here and re-read for DEC files)."""
    w = struct.unpack_from("<11H", head, 2)                 # words 2..12
    return {"n_points": w[0], "n_analog": w[1], "first": w[2], "last": w[3],
            "data_start": w[7], "analog_per_frame": w[8],
            "scale": float_at(head, 12, False), "rate": float_at(head, 20, False)}


def _processor(code: int, path: Path, trial: str | None) -> str:
    proc = _PROCESSORS.get(code)
    if proc is None:
        raise FileFormatError(f"unknown C3D processor type {code} (expected 84 Intel, "
                              "85 DEC or 86 MIPS)", path=path, trial=trial)
    if proc.startswith("MIPS"):
        raise FileFormatError("C3D file uses the MIPS (SGI) big-endian processor format, "
                              "which ezc3d cannot read", path=path, trial=trial,
                              hint="convert it to Intel format, e.g. by opening and saving "
                                   "it in Mokka or Vicon Nexus")
    return proc


def _check_layout(hdr: dict, params: Parameters, size: int, path: Path,
                  trial: str | None) -> tuple[int, int]:
    """Finite, consistent header and parameters; a data section that holds every frame.

    Returns the number of frames the file announces and the bytes its data section holds
    by the header (:func:`_check_size`).
    """
    def refuse(problem: str):
        raise FileFormatError(problem, path=path, trial=trial,
                              hint="re-export the file from the capture software")

    for (group, name), allow_zero in _FINITE:
        values = params.numbers(group, name) or []
        if values and name in ("USED", "FRAMES"):           # counts: unsigned integers
            values[0] = params.count(group, name)
        for v in values:
            if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
                refuse(f"{group}:{name} is {v!r}; it must be a finite number "
                       f"{'>= 0' if allow_zero else '> 0'}")
    if not math.isfinite(hdr["scale"]):
        refuse(f"the header's scale factor is {hdr['scale']!r}")
    _check_rates_and_counts(hdr, params, refuse)
    for (group, name), want in ((("POINT", "USED"), hdr["n_points"]),
                                (("POINT", "DATA_START"), hdr["data_start"])):
        got = params.count(group, name) if name == "USED" else params.first(group, name)
        if got and int(got) & 0xFFFF != want:     # 0: not filled in (c3d.org's Dance)
            refuse(f"{group}:{name} is {got:g} but the header says {want}")
    if hdr["n_analog"]:                       # ezc3d reads these for every analog channel
        used = params.count("ANALOG", "USED") or 0
        for name in ("USED", "SCALE", "OFFSET", "GEN_SCALE"):
            n = len(params.numbers("ANALOG", name) or [])
            if n == 0 or (name in ("SCALE", "OFFSET") and n < used):
                refuse(f"the header announces analog samples but ANALOG:{name} "
                       f"{'is missing' if n == 0 else f'holds {n} values for {used:g} channels'}")
    p_scale = params.first("POINT", "SCALE")
    if p_scale is not None and (p_scale < 0) != (hdr["scale"] < 0):
        refuse(f"POINT:SCALE ({p_scale:g}) and the header's scale factor ({hdr['scale']:g}) "
               "disagree on whether the points are floats")
    if params.first("POINT", "RATE") is None and not hdr["rate"] > 0:
        refuse(f"the point rate is {hdr['rate']!r} and POINT:RATE is absent")
    if hdr["last"] < hdr["first"] and hdr["n_points"] + hdr["n_analog"] and \
            not params.first("POINT", "FRAMES"):
        refuse(f"the header's last frame ({hdr['last']}) is before its first "
               f"({hdr['first']})")
    return _check_size(hdr, params, size, path, trial)


def _check_rates_and_counts(hdr: dict, params: Parameters, refuse) -> None:
    """Rates within (0, :data:`MAX_RATE_HZ`], at least one marker, and analog parameters
    that agree with the header's analog words (ezc3d sizes its analog buffers from
    ANALOG:RATE / POINT:RATE: a rate of 3e9 asked it for 15 GB)."""
    p_rate = params.first("POINT", "RATE")
    rate, field = (p_rate, "POINT:RATE") if p_rate is not None else \
        (hdr["rate"], "the header's frame rate")
    if not (math.isfinite(rate) and 0 < rate <= MAX_RATE_HZ):
        refuse(f"{field} is {rate!r} Hz; it must be above 0 and at most "
               f"{MAX_RATE_HZ:,.0f} Hz")
    used = params.count("POINT", "USED")
    if used == 0 or hdr["n_points"] == 0:
        refuse("the file holds no markers (" + ("POINT:USED is 0" if used == 0 else
                                                 "the header's point count is 0") + ")")
    a_rate = params.first("ANALOG", "RATE")
    if a_rate is not None and not (math.isfinite(a_rate) and 0 <= a_rate <= MAX_RATE_HZ):
        refuse(f"ANALOG:RATE is {a_rate!r} Hz; it must be at most {MAX_RATE_HZ:,.0f} Hz")
    a_used = params.count("ANALOG", "USED") or 0
    if not (hdr["n_analog"] or a_used):
        return
    if not a_rate:
        refuse(f"ANALOG:USED is {a_used:g} (header: {hdr['n_analog']} analog samples per "
               f"frame) but ANALOG:RATE is {a_rate!r}")
    per_frame = a_rate / rate                                      # samples per frame
    if abs(per_frame - round(per_frame)) > 1e-3 or round(per_frame) < 1:
        refuse(f"ANALOG:RATE ({a_rate:g} Hz) / {field} ({rate:g} Hz) = {per_frame:g} "
               "analog samples per point frame, not a whole number")
    per_frame = round(per_frame)
    if hdr["n_analog"] and per_frame != hdr["analog_per_frame"]:
        refuse(f"ANALOG:RATE / {field} = {a_rate:g} / {rate:g} Hz = {per_frame} analog "
               f"samples per frame, but the header says {hdr['analog_per_frame']}")
    if a_used * per_frame != hdr["n_analog"]:
        refuse(f"ANALOG:USED ({a_used:g} channels) x {per_frame} samples per frame = "
               f"{a_used * per_frame:g} analog values per frame, but the header says "
               f"{hdr['n_analog']}")


def _check_size(hdr: dict, params: Parameters, size: int, path: Path,
                trial: str | None) -> tuple[int, int]:
    """The data section must hold the frames the header announces (POINT:FRAMES where the
    header's 16-bit last-frame word is saturated), no whole frame more beyond two 512-byte
    blocks of padding (ezc3d's writer adds a block), and at most :data:`MAX_DATA_BYTES`.
    Returns the larger of the two frame counts, which the reader compares with what ezc3d
    read, and the bytes the announced frames take."""
    n_header = hdr["last"] - hdr["first"] + 1 if hdr["last"] >= hdr["first"] else 0
    p_frames = params.count("POINT", "FRAMES")
    p_frames = 0 if p_frames is None else int(p_frames)
    # frame numbers above 65535 do not fit the header's words: ezc3d writes 65535 as the
    # last frame, other writers let them wrap; POINT:FRAMES then holds the count
    wrapped = hdr["last"] == 0xFFFF or hdr["last"] < hdr["first"]
    expected = p_frames if wrapped and p_frames > 0 else n_header
    bpv = 4 if hdr["scale"] < 0 else 2                       # float or int16 samples
    frame_bytes = bpv * (4 * hdr["n_points"] + hdr["n_analog"])
    room = size - (hdr["data_start"] - 1) * 512
    if frame_bytes and expected * frame_bytes > room:
        raise FileFormatError(f"C3D file is truncated: the header announces {expected} "
                              f"frames of {frame_bytes} bytes, the data section holds "
                              f"{room // frame_bytes}", path=path, trial=trial)
    trial_frames = _trial_frames(params)
    if frame_bytes and trial_frames > max(expected, 0xFFFF) \
            and trial_frames * frame_bytes <= room:
        raise FileFormatError(
            f"the capture holds {trial_frames} frames (TRIAL:ACTUAL_START_FIELD/END_FIELD, "
            f"and the data section has room for them) but the header and POINT:FRAMES stop "
            f"at {expected}: ezc3d reads only those, and the rest would be lost without a "
            "word", path=path, trial=trial,
            hint="export the capture in parts of at most 65,535 frames")
    frames = max(expected, p_frames if 0 < p_frames < 0xFFFF else 0)
    data_bytes = frames * frame_bytes
    if frame_bytes and room - expected * frame_bytes >= max(2 * 512, frame_bytes):
        raise FileFormatError(
            f"the header announces {expected} frames of {frame_bytes} bytes "
            f"({expected * frame_bytes} bytes) but the data section holds {room} bytes, "
            f"room for {room // frame_bytes} frames: the frame count (header words 4-5, "
            "POINT:FRAMES) or the point/analog counts are wrong, and reading would lose "
            "or misplace frames", path=path, trial=trial,
            hint="re-export the file from the capture software")
    if data_bytes > MAX_DATA_BYTES:
        raise FileFormatError(
            f"the data section holds {data_bytes / 2 ** 20:.0f} MiB ({frames} frames of "
            f"{frame_bytes} bytes), more than gaitval reads at once "
            f"({MAX_DATA_BYTES / 2 ** 20:.0f} MiB; ezc3d needs ~10 times that in memory)",
            path=path, trial=trial, hint="export the capture in shorter parts")
    return frames, data_bytes


def _trial_frames(params: Parameters) -> int:
    """Frames from TRIAL:ACTUAL_START_FIELD to ACTUAL_END_FIELD (two unsigned 16-bit words
    each, low first, as Vicon writes captures longer than 65,535 frames); 0 when absent."""
    words = []
    for name in ("ACTUAL_START_FIELD", "ACTUAL_END_FIELD"):
        v = params.numbers("TRIAL", name)
        if not v or len(v) < 2 or params.params["TRIAL", name].type != 2:
            return 0
        words.append((int(v[0]) & 0xFFFF) + ((int(v[1]) & 0xFFFF) << 16))
    return words[1] - words[0] + 1 if words[1] >= words[0] else 0


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
    return f"ezc3d cannot read it: {getattr(exc, 'type_name', type(exc).__name__)}: {msg}"


def _open_ezc3d(path: Path, trial: str | None, pre: dict | None = None) -> dict[str, Any]:
    """What gaitval reads of ``ezc3d.c3d(path)``, with every failure one FileFormatError.

    ezc3d runs in a child process (:func:`gaitval.io.isolate.run_isolated`): should a file
    that passed the checks above still crash or stall it, the child dies, not gaitval.
    ``ignore_bad_formatting`` is deliberately never used: with ezc3d 1.7.2 it crashes the
    interpreter (segmentation fault) on ``c3dorg_sample18_bad_parameter_section.c3d``.

    Returns
    -------
    dict
        ``header`` and ``parameters`` as ezc3d gives them (parameters: group -> name ->
        ``{"value": ...}``), ``data`` with ``points`` and ``meta_points.residuals``, and
        ``n_analogs`` (the analog samples themselves are not read).
    """
    layout = (pre or {}).get("frames_only")
    if layout:
        got = _frames_only(path, trial, layout)
        if got is not None:
            return got
    return _ezc3d_child(path, path, trial)


def _ezc3d_child(target: Path, path: Path, trial: str | None) -> dict[str, Any]:
    """:func:`_extract` of ``target`` in a child process under a time and an
    address-space limit (:data:`EZC3D_MEMORY_BASE` + :data:`EZC3D_MEMORY_PER_BYTE` x the
    file's size); errors name ``path``."""
    from gaitval.io.isolate import ChildError, run_isolated

    n_bytes = target.stat().st_size
    timeout = 60.0 + 20.0 * n_bytes / 1e6                     # generous: ~1 s/MB is usual
    memory = EZC3D_MEMORY_BASE + EZC3D_MEMORY_PER_BYTE * n_bytes
    try:
        return run_isolated(_extract, str(target), path=path, trial=trial, what="ezc3d",
                            timeout_s=timeout, memory_bytes=memory)
    except ChildError as exc:  # ezc3d raises OSError, RuntimeError, ValueError, IndexError
        if exc.type_name == "MemoryError" or "bad_alloc" in str(exc):
            raise FileFormatError(f"ezc3d needed more than {memory / 2 ** 20:.0f} MiB to read "
                                  f"it (the limit for a {n_bytes / 2 ** 20:.1f} MiB file): "
                                  "a size in the header or parameters is corrupt",
                                  path=path, trial=trial) from None
        raise FileFormatError(_ezc3d_reason(exc), path=path, trial=trial) from None


#: the residual words of a float C3D the fast path decodes (float32 bits): 0.0 (a sample,
#: residual 0, no camera mask) and -1.0 (a gap), what gaitval's writer and Vicon's gaps use
_RESIDUAL_OK, _RESIDUAL_GAP = 0x00000000, 0xBF800000


def _frames_only(path: Path, trial: str | None, layout: dict[str, int]
                 ) -> dict[str, Any] | None:
    """ezc3d reads the file cut to its first frame (header, parameters, events), numpy the
    frames: what ezc3d gives for the whole file, bit for bit, without its C++ object per
    sample (0.28 against 0.02 CPU-s for 60,000 frames of 9 markers).  None, reading nothing
    more, when a residual word is other than 0.0 or -1.0 (a real residual or a camera mask:
    left to ezc3d's decoding).  ``tests/test_c3d_reader_fast.py`` compares the two."""
    import tempfile

    import numpy as np

    ds = (layout["data_start"] - 1) * 512
    n, m = layout["n_frames"], layout["n_points"]
    raw = np.fromfile(path, dtype="<f4", count=n * m * 4, offset=ds)
    if raw.size != n * m * 4:                  # changed since the checks: ezc3d's turn
        return None
    raw = raw.reshape(n, m, 4)
    word = raw[..., 3].view("<u4")
    gap = word == _RESIDUAL_GAP
    if not np.all(gap | (word == _RESIDUAL_OK)):
        return None
    with open(path, "rb") as fh:
        head = bytearray(fh.read(ds + m * 16))
    struct.pack_into("<H", head, 8, layout["first"])              # header: one frame
    struct.pack_into("<H", head, layout["point_frames_offset"], 1)  # POINT:FRAMES = 1
    head += bytes(-len(head) % 512)
    with tempfile.TemporaryDirectory(prefix="gaitval-c3d-") as tmp:
        one = Path(tmp) / "first_frame.c3d"
        one.write_bytes(bytes(head))
        got = _ezc3d_child(one, path, trial)
    points = np.empty((4, m, n))                                  # ezc3d's layout: C order
    points[:3] = raw[..., :3].transpose(2, 1, 0)
    points[3] = 1.0
    points[:3, gap.T] = np.nan                                    # ezc3d: a gap is NaN
    got["data"] = {"points": points,
                   "meta_points": {"residuals": np.ascontiguousarray(
                       np.where(gap.T, -1.0, 0.0)[None])}}
    got["parameters"]["POINT"]["FRAMES"]["value"] = np.array([n], dtype=np.int64)
    return got


def _extract(path: str) -> dict[str, Any]:
    """Open ``path`` with ezc3d and copy out plain, picklable values (runs in the child)."""
    import ezc3d
    import numpy as np

    from gaitval.io.isolate import keep_until_exit

    c = ezc3d.c3d(path)
    keep_until_exit(c)                 # the child's exit frees it, not its destructor
    params = {g: {n: {"value": v["value"]} for n, v in grp.items() if n != "__METADATA__"}
              for g, grp in c["parameters"].items()}
    h = c["header"]
    header = {"points": {"first_frame": int(h["points"]["first_frame"]),
                         "frame_rate": float(h["points"]["frame_rate"])},
              "analogs": {"frame_rate": float(h["analogs"]["frame_rate"])},
              "events": {"events_time": np.asarray(h["events"]["events_time"], dtype=float),
                         "events_label": [str(s) for s in h["events"]["events_label"]]}}
    data = {"points": np.asarray(c["data"]["points"], dtype=np.float64),
            "meta_points": {"residuals": np.asarray(c["data"]["meta_points"]["residuals"],
                                                    dtype=np.float64)}}
    return {"header": header, "parameters": params, "data": data,
            "n_analogs": int(c["data"]["analogs"].shape[1])}
