"""The few data types shared across gaitval's modules.

All arrays are in SI units: metres, seconds, radians.  Loaders in :mod:`gaitval.io`
return these types; everything downstream receives them and never sees file units.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from gaitval import consts as C


@dataclass
class MocapTrial:
    """Marker trajectories of one motion-capture trial.

    Attributes
    ----------
    path : str
        The source file.
    rate_hz : float
        Point sampling rate.
    first_frame : int
        The 1-based frame number of the first stored frame (C3D ``header.points.first_frame``
        + 1, as Vicon numbers frames).  Time convention: ``t[i] = (first_frame - 1 + i) / rate_hz``,
        so the first stored frame of a file whose ``first_frame`` is 1 is at t = 0 s.
    labels : list[str]
        Marker labels after prefix handling (see :mod:`gaitval.io.c3d`).
    xyz : ndarray, shape (n_frames, n_markers, 3)
        Positions in metres in the mocap (field) frame; NaN where the marker is missing.
    events : DataFrame
        Columns ``context`` (e.g. ``Left``), ``label`` (e.g. ``Foot Strike``), ``t_s``.
        Empty when the file has no EVENT section.
    units : str
        The unit the file stored points in (``mm``, ``cm`` or ``m``) before conversion.
    meta : dict
        Anything else a loader wants to report (manufacturer, original labels, ...).
    """

    path: str
    rate_hz: float
    first_frame: int
    labels: list[str]
    xyz: np.ndarray
    events: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(
        columns=["context", "label", "t_s"]))
    units: str = "mm"
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        return int(self.xyz.shape[0])

    @property
    def t(self) -> np.ndarray:
        """Frame times in seconds (see ``first_frame`` for the convention)."""
        return (self.first_frame - 1 + np.arange(self.n_frames)) / self.rate_hz

    def marker(self, label: str) -> np.ndarray:
        """(n_frames, 3) positions of one marker in metres; KeyError if absent."""
        try:
            i = self.labels.index(label)
        except ValueError:
            raise KeyError(label) from None
        return self.xyz[:, i, :]

    def has(self, label: str) -> bool:
        return label in self.labels

    def to_arrow(self):
        """Tidy long table ``frame, t_s, marker, x_m, y_m, z_m`` as a ``pyarrow.Table``
        (gaps as nulls), built column by column: the marker labels are decoded from a
        dictionary, without the 540,000 label strings a 60,000-frame trial of 9 markers
        would cost as Python objects."""
        import pyarrow as pa

        n, m, _ = self.xyz.shape
        labels = pa.array([str(s) for s in self.labels], type=pa.large_string())
        marker = pa.DictionaryArray.from_arrays(
            pa.array(np.tile(np.arange(m, dtype=np.int32), n)), labels).dictionary_decode()
        return pa.table({
            C.FRAME: np.repeat(np.arange(n, dtype=np.int64) + self.first_frame, m),
            C.T: pa.array(np.repeat(self.t, m), from_pandas=True),
            C.MARKER: marker,
            **{c: pa.array(np.ascontiguousarray(self.xyz[:, :, i]).ravel(), from_pandas=True)
               for i, c in enumerate((C.X, C.Y, C.Z))},
        })

    def to_frame(self) -> pd.DataFrame:
        """Tidy long table: ``frame, t_s, marker, x_m, y_m, z_m`` (NaN for gaps)."""
        return self.to_arrow().to_pandas()


@dataclass
class ScanSeries:
    """A series of 2-D laser scans (one LRS log or one ROS bag topic).

    Attributes
    ----------
    t : ndarray, shape (n_scans,)
        Scan timestamps in seconds on the sensor's own clock, in file order (never
        reordered; see ``timestamp_issues``).
    ranges : ndarray, shape (n_scans, n_beams), float
        Ranges in metres.  "No return" (inf, NaN, zero, out of [range_min, range_max]) is
        NaN: the one documented value (:data:`gaitval.consts.NO_RETURN`).
    angle_min, angle_increment : float
        Beam ``i`` points at ``angle_min + i * angle_increment`` radians in the sensor frame
        (x forward, y left, counter-clockwise positive, as ROS ``sensor_msgs/LaserScan``).
    range_min, range_max : float
        The sensor's valid range in metres.
    sensor_model : str
    mounting_height_m : float or None
        Height of the scan plane above the floor.
    source : str
        File path (and ``#topic`` for bags).
    timestamp_issues : DataFrame
        One row per problem found: ``index, t_s, problem`` (``non-monotonic`` or
        ``duplicate``).  Empty when the clock is clean.
    n_no_return_raw : int
        How many beams were mapped to "no return".
    meta : dict
    """

    t: np.ndarray
    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    sensor_model: str = "unknown"
    mounting_height_m: float | None = None
    source: str = ""
    timestamp_issues: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(
        columns=["index", "t_s", "problem"]))
    n_no_return_raw: int = 0
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def n_scans(self) -> int:
        return int(self.ranges.shape[0])

    @property
    def n_beams(self) -> int:
        return int(self.ranges.shape[1])

    @property
    def angles(self) -> np.ndarray:
        return self.angle_min + self.angle_increment * np.arange(self.n_beams)

    @property
    def angle_max(self) -> float:
        return float(self.angle_min + self.angle_increment * (self.n_beams - 1))

    def points(self, k: int) -> np.ndarray:
        """(n_beams, 2) Cartesian points of scan ``k`` in the sensor frame (NaN: no return)."""
        a = self.angles
        r = self.ranges[k]
        return np.column_stack([r * np.cos(a), r * np.sin(a)])


@dataclass
class UltrasonicLog:
    """Per-anchor time-of-flight (or distance) log of an ultrasonic ranging system.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Sample times in seconds on the ultrasonic system's clock.
    tof_s : ndarray, shape (n, n_anchors) or None
        Time of flight transmitter → receiver in seconds; NaN where no echo was received.
    distance_m : ndarray, shape (n, n_anchors) or None
        Distances when the log stores distances instead of times of flight.
    temperature_c : ndarray, shape (n,)
        Air temperature in degrees Celsius (for the speed of sound, seed 003 eq. 2).
    anchors : DataFrame
        ``anchor, x_m, y_m, z_m``: receiver positions in the system's frame.
    source : str
    meta : dict
    """

    t: np.ndarray
    temperature_c: np.ndarray
    anchors: pd.DataFrame
    tof_s: np.ndarray | None = None
    distance_m: np.ndarray | None = None
    source: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def anchor_ids(self) -> list[str]:
        return [str(a) for a in self.anchors["anchor"]]

    @property
    def rate_hz(self) -> float:
        if len(self.t) < 2:
            return float("nan")
        return float(1.0 / np.median(np.diff(self.t)))
