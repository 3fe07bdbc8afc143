"""gaitval's ultrasonic ranging log (``*.us.parquet``), reader and writer.

Format (version 1), documented in full in ``docs/formats.md``
------------------------------------------------------------
One Parquet file, one row per sample, in the order the system produced them:

* ``t_s`` (float64): sample time in seconds on the ultrasonic system's clock;
* ``temperature_c`` (float64): air temperature in degrees Celsius (seed 003 eq. 2);
* one column per receiver (anchor) ``A``: ``tof_A_s`` (time of flight, seconds) when
  ``quantity`` is ``tof``, or ``dist_A_m`` (metres) when it is ``distance``; NaN where no
  echo was received.

Schema metadata key ``gaitval:ultrasonic`` holds a JSON object::

    {"format": "gaitval-ultrasonic", "version": 1, "quantity": "tof",
     "anchors": [{"anchor": "R1", "x_m": 0.0, "y_m": 0.0, "z_m": 0.0}, ...],
     "transmitter": "heel", "sensor_model": "...", "frame": "..."}

The anchor geometry (receiver positions, metres, in the ultrasonic system's frame) lives in
the metadata so one file is a complete record.

Ranging (seed 003 eq. (1)–(2)) is the one unit conversion of these logs and lives here
too: :func:`tof_to_distance` (and its inverse :func:`distance_to_tof`, which the simulator
uses with its own speed-of-sound law), :func:`log_distances` (the ranges of a log in metres,
whichever quantity it stores) and :func:`anchor_positions`.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError, TimestampError
from gaitval.io.atomic import atomic_path
from gaitval.io.guard import (column_kind, column_names, enough_rows, json_meta, loader,
                              number, text_field, version_field)
from gaitval.io.scanlog import check_timestamps
from gaitval.types import UltrasonicLog

META_KEY = b"gaitval:ultrasonic"
FORMAT = "gaitval-ultrasonic"
VERSION = 1
SUFFIX = ".us.parquet"
#: physical bounds of an air temperature (degrees Celsius) the ranging may use
TEMPERATURE_RANGE_C = (-60.0, 80.0)
#: Columns of an anchor table (``UltrasonicLog.anchors``): id, then position (m).
ANCHOR_COLUMNS = ["anchor", "x_m", "y_m", "z_m"]


# ------------------------------------------------------------------------------ ranging
def speed_of_sound(temp_c):
    """Speed of ultrasound in air, ``v_s = 331.5 + 0.6 T_c`` (m/s), seed003 eq. (2)."""
    return 331.5 + 0.6 * np.asarray(temp_c, dtype=float)


def _per_sample(v, x: np.ndarray):
    """Speeds per sample ``(n,)`` as a column when ``x`` holds ``(n, m)`` anchors."""
    return v[:, None] if x.ndim == 2 and np.ndim(v) == 1 else v


def tof_to_distance(tof_s, temp_c, *, speed=speed_of_sound):
    """Range from time of flight, ``d = t v_s(T_c)`` (seed003 eq. (1)–(2)).

    Parameters
    ----------
    tof_s : array_like, shape (n,) or (n, m)
        Times of flight (s); NaN stays NaN.
    temp_c : array_like, shape (n,) or scalar
        Air temperature (degrees Celsius) at each sample.
    speed : callable, optional
        Speed of sound (m/s) from the temperature; default :func:`speed_of_sound`
        (seed003 eq. (2)).

    Returns
    -------
    ndarray
        Distances in metres, shape of ``tof_s``.
    """
    tof = np.asarray(tof_s, dtype=float)
    return tof * _per_sample(speed(temp_c), tof)                          # seed003 eq. (1)


def distance_to_tof(d_m, temp_c, *, speed=speed_of_sound):
    """Time of flight of a range, ``t = d / v_s(T_c)``: seed003 eq. (1) solved for ``t``.

    Same shapes and ``speed`` as :func:`tof_to_distance`, of which it is the inverse; the
    simulator passes its own physical law
    (:func:`gaitval.simulate.us_sensor.speed_of_sound_true`).
    """
    d = np.asarray(d_m, dtype=float)
    return d / _per_sample(speed(temp_c), d)                              # seed003 eq. (1)


def log_distances(log: UltrasonicLog) -> np.ndarray:
    """(n, m) ranges in metres of a log that stores either TOF or distances."""
    if log.distance_m is not None:
        return np.asarray(log.distance_m, dtype=float)
    if log.tof_s is None:
        raise TimestampError("ultrasonic log holds neither times of flight nor distances",
                             path=log.source or None)
    return tof_to_distance(log.tof_s, log.temperature_c)


def anchor_positions(anchors: pd.DataFrame) -> np.ndarray:
    """Receiver positions ``(m, 3)`` (metres, ultrasonic frame) of an anchor table."""
    return anchors[ANCHOR_COLUMNS[1:]].to_numpy(dtype=float)


# ------------------------------------------------------------------------------ files


def write_ultrasonic(path: str | Path, log: UltrasonicLog, *, transmitter: str = "heel",
                     sensor_model: str = "unknown") -> Path:
    """Write an :class:`~gaitval.types.UltrasonicLog` atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    ids = log.anchor_ids
    cols = {"t_s": np.asarray(log.t, dtype=np.float64),
            "temperature_c": np.asarray(log.temperature_c, dtype=np.float64)}
    if log.tof_s is not None:
        quantity, data, fmt = "tof", np.asarray(log.tof_s, dtype=np.float64), "tof_{}_s"
    elif log.distance_m is not None:
        quantity, data, fmt = "distance", np.asarray(log.distance_m, dtype=np.float64), "dist_{}_m"
    else:
        raise ValueError("UltrasonicLog has neither tof_s nor distance_m")
    for j, a in enumerate(ids):
        cols[fmt.format(a)] = data[:, j]
    meta = {"format": FORMAT, "version": VERSION, "quantity": quantity,
            "anchors": [{"anchor": str(r.anchor), "x_m": float(r.x_m), "y_m": float(r.y_m),
                         "z_m": float(r.z_m)} for r in log.anchors.itertuples()],
            "transmitter": transmitter, "sensor_model": sensor_model,
            **{k: v for k, v in log.meta.items() if isinstance(v, (str, int, float))}}
    table = pa.table(cols).replace_schema_metadata({META_KEY: json.dumps(meta).encode()})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="zstd")
    return Path(path)


@loader("ultrasonic log")
def read_ultrasonic(path: str | Path, *, trial: str | None = None) -> UltrasonicLog:
    """Read an ultrasonic log in gaitval's format (seconds, metres, degC; NaN = no echo).

    Raises
    ------
    FileFormatError
        Missing file, not Parquet, missing or non-JSON metadata, a ``format`` other than
        ``gaitval-ultrasonic``, a version that is not a whole number from 1 to
        :data:`VERSION`, a ``sensor_model`` or ``transmitter`` that is not text, anchors
        that are not a list of ``{anchor, x_m, y_m, z_m}`` with finite coordinates and
        distinct names, an unknown ``quantity``, missing columns, columns of the wrong
        type (``t_s``/``temperature_c`` not float or integer, ``tof_*``/``dist_*`` not
        float: a bool, a timestamp), fewer than 2 samples or times that never advance,
        non-finite times or temperatures, temperatures outside
        :data:`TEMPERATURE_RANGE_C` (the row is named).
    """
    from gaitval.io.parquet import read_table

    path = Path(path)
    if not path.is_file():
        raise FileFormatError("ultrasonic log not found", path=path, trial=trial)
    try:
        tab = read_table(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow: ArrowInvalid, OSError, ...
        raise FileFormatError(f"not a readable Parquet ultrasonic log: {exc}", path=path,
                              trial=trial) from None
    md = tab.schema.metadata or {}
    if META_KEY not in md:
        raise FileFormatError("Parquet file has no 'gaitval:ultrasonic' metadata",
                              path=path, trial=trial, hint="see docs/formats.md")
    meta = json_meta(md[META_KEY], META_KEY.decode(), path, trial)
    kw = {"path": path, "trial": trial, "what": "ultrasonic metadata"}
    text_field(meta, "format", expected=FORMAT, **kw)
    version_field(meta, VERSION, **kw)
    for key in ("sensor_model", "transmitter"):
        text_field(meta, key, **kw)
    anchors = _anchors(meta, path, trial)
    quantity = meta.get("quantity")
    fmt = {"tof": "tof_{}_s", "distance": "dist_{}_m"}.get(quantity) \
        if isinstance(quantity, str) else None
    if fmt is None:
        raise FileFormatError(f"unknown quantity {quantity!r} (expected 'tof' or "
                              "'distance')", path=path, trial=trial)
    need = ["t_s", "temperature_c"] + [fmt.format(a) for a in anchors["anchor"]]
    missing = [c for c in need if c not in column_names(tab, path, trial)]
    if missing:
        raise FileFormatError(f"ultrasonic log lacks columns {missing}", path=path,
                              trial=trial)
    for c in need:                   # times, temperatures: any number; ranges: floats
        column_kind(tab, c, ("float", "integer") if c in need[:2] else ("float",), path,
                    trial, what="ultrasonic column")
    cols = _numeric_columns(tab, need, path, trial)
    enough_rows(cols["t_s"], 2, path, trial, what="ultrasonic log", unit="sample")
    lo, hi = TEMPERATURE_RANGE_C
    bad = np.flatnonzero((cols["temperature_c"] < lo) | (cols["temperature_c"] > hi))
    if bad.size:
        worst = float(cols["temperature_c"][bad[0]])
        raise FileFormatError(f"column 'temperature_c' holds {worst!r}"
                              f" degC at row {int(bad[0])}; an air temperature lies within "
                              f"{lo:g} .. {hi:g} degC", path=path, trial=trial)
    data = np.column_stack([cols[c] for c in need[2:]]) if len(need) > 2 else \
        np.empty((len(cols["t_s"]), 0))
    with np.errstate(invalid="ignore"):
        data[~np.isfinite(data) | (data <= 0)] = np.nan
    t = cols["t_s"]
    log = UltrasonicLog(t=t, temperature_c=cols["temperature_c"],
                        anchors=anchors.reset_index(drop=True), source=str(path),
                        meta={**meta, "timestamp_issues": check_timestamps(t)})
    if quantity == "tof":
        log.tof_s = data
    else:
        log.distance_m = data
    return log


def _anchors(meta: dict, path: Path, trial: str | None) -> pd.DataFrame:
    """``meta["anchors"]`` checked: a list of objects with a name and finite x, y, z."""
    raw = meta.get("anchors")
    if not isinstance(raw, list) or not raw:
        raise FileFormatError(f"ultrasonic metadata incomplete: 'anchors' must be a "
                              f"non-empty list, not {type(raw).__name__}", path=path,
                              trial=trial)
    rows = []
    for k, a in enumerate(raw):
        if not isinstance(a, dict) or not isinstance(a.get("anchor"), (str, int)):
            raise FileFormatError(f"ultrasonic metadata: anchor {k} must be an object with "
                                  "a name 'anchor'", path=path, trial=trial)
        xyz = [number(a, c, path, trial, what=f"ultrasonic metadata: anchor {a['anchor']!r}")
               for c in ("x_m", "y_m", "z_m")]
        rows.append((str(a["anchor"]), *xyz))
    df = pd.DataFrame(rows, columns=["anchor", "x_m", "y_m", "z_m"])
    if df["anchor"].duplicated().any():
        raise FileFormatError(f"ultrasonic metadata: anchor "
                              f"{df['anchor'][df['anchor'].duplicated()].iloc[0]!r} is listed "
                              "twice", path=path, trial=trial)
    return df


def _numeric_columns(tab, names: list[str], path: Path, trial: str | None
                     ) -> dict[str, np.ndarray]:
    """Columns as float64; times and temperatures must be finite (the row is named)."""
    out = {}
    for c in names:
        try:
            out[c] = np.asarray(tab[c].to_numpy(), dtype=np.float64).copy()
        except Exception as exc:  # noqa: BLE001 - pyarrow/numpy conversion of odd types
            raise FileFormatError(f"column {c!r} is not numeric ({exc})", path=path,
                                  trial=trial) from None
        if c in ("t_s", "temperature_c"):
            bad = np.flatnonzero(~np.isfinite(out[c]))
            if bad.size:
                raise FileFormatError(f"column {c!r} holds {out[c][bad[0]]!r} at row "
                                      f"{int(bad[0])}; it must be finite", path=path,
                                      trial=trial)
    return out
