"""Gait parameters of seed 003's treadmill trials, ultrasonic track against camera reference.

:func:`gait_parameters` is §4.1–4.2 and eq. 16–22: the camera reference
(:func:`gaitval.groundtruth.reference.reference_trajectory`), resampled, low-passed and
aligned with the track (:mod:`gaitval.evaluate.alignment`), strides segmented in both
systems and matched (:mod:`gaitval.gait.strides`), then S, NS, T, V, NV, C per stride and
the autocorrelation symmetry hS, vS per window: the **gait parameter table** that
:mod:`gaitval.tables.ultrasonic` renders.

Frames: the ultrasonic frame of the log's anchor geometry (X progression, Y vertical,
Z lateral).

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, GaitvalError
from gaitval.evaluate.alignment import align_track_to_reference
from gaitval.evaluate.ultrasonic_config import reference_kwargs, resolve_cfg
from gaitval.gait.strides import autocorr_symmetry, match_strides, stride_table
from gaitval.groundtruth.reference import reference_trajectory
from gaitval.types import MocapTrial

#: The parameters of the gait parameter table and their units.
PARAMETERS = {"stride_length": "m", "stride_length_norm": "m", "stride_duration": "s",
              "stride_velocity": "m/s", "stride_velocity_norm": "m/s", "cadence": "1/s",
              "h_symmetry": "1", "v_symmetry": "1"}
#: Columns of the gait parameter table.
GAIT_COLUMNS = ["study", "trial", "subject", "speed", "stride", "parameter", "unit",
                "reference", "system"]
_PER_STRIDE = ("stride_length", "stride_length_norm", "stride_duration", "stride_velocity",
               "stride_velocity_norm", "cadence")


def gait_parameters(track_df: pd.DataFrame, mocap: MocapTrial, trial: dict, subject: dict,
                    cfg: dict | None = None, *, anchors: pd.DataFrame | None = None
                    ) -> pd.DataFrame:
    """Spatial-temporal gait parameters of one treadmill trial, reference vs system.

    Parameters
    ----------
    track_df : DataFrame
        Output of :meth:`gaitval.track.ukf.ToaUkf.track` (ultrasonic clock and frame).
    mocap : MocapTrial
        The trial's C3D with the transmitter marker and the receiver markers.
    trial : dict
        Trial-sheet row: ``study``, ``trial``, ``subject``, ``speed``, ``clock_offset_s``
        (NaN/empty = estimate by cross-correlation, a number = manual override).
    subject : dict
        Subject-table row (only ``subject`` is used).
    cfg : dict
        ``resample_hz``, ``lowpass``, ``align``, ``strides``, ``symmetry``, ``reference``
        and the marker keys of :data:`~gaitval.evaluate.ultrasonic_config.DEFAULT_CFG`.
    anchors : DataFrame, optional
        ``anchor, x_m, y_m, z_m`` of the log; default ``track_df.attrs["anchors"]``.

    Returns
    -------
    DataFrame
        The **gait parameter table**: one row per (trial, stride, parameter), columns
        ``study, trial, subject, speed, stride, parameter, unit, reference, system``.
        ``parameter`` is one of :data:`PARAMETERS`.  For the per-stride parameters
        ``stride`` is the reference stride index (0-based, strides matched between the
        systems by start time); for ``h_symmetry`` / ``v_symmetry`` it is the index of a
        window of ``symmetry.window_strides`` consecutive reference strides
        (non-overlapping).  ``n`` of NS and NV (eq. 18, 21) is the number of matched strides.
        ``attrs``: ``clock_offset_s``, ``n_strides_reference``, ``n_strides_system``,
        ``n_matched``, ``registration_rms_m``.

    Notes
    -----
    Reference: marker ``TX`` brought into the ultrasonic frame, linearly resampled to
    50 Hz; both trajectories low-passed (2nd-order Butterworth, 10 Hz, zero phase); the
    system trajectory delayed to the maximum of the cross-correlation of the horizontal and
    vertical displacements (§4.1–4.2).  Strides are segmented on each system's own
    horizontal displacement (eq. 17–22, :func:`gaitval.gait.strides.stride_table`) and
    matched by start time (:func:`gaitval.gait.strides.match_strides`).  Strides that
    touch a reference gap longer than ``reference.max_gap_s`` are dropped.
    """
    c = resolve_cfg(cfg)
    tname = str(trial.get("trial", ""))
    if anchors is None:
        recs = track_df.attrs.get("anchors")
        if not recs:
            raise ConfigError("gait_parameters needs the anchor geometry: pass anchors= "
                              "(the log's anchor table)", trial=tname)
        anchors = pd.DataFrame(recs)
    ref = reference_trajectory(mocap, anchors, **reference_kwargs(c), trial=tname)
    al = align_track_to_reference(track_df, ref, c, clock_offset_s=_clock_offset(trial))
    st_r, st_s = _strides(al, c["strides"])
    pairs = match_strides(st_r, st_s, float(c["strides"]["match_tolerance"]))
    if not pairs:
        raise GaitvalError(f"no stride found in both systems (reference {len(st_r)}, "
                           f"ultrasonic {len(st_s)} strides)", path=mocap.path, trial=tname,
                           hint="check the track (a process noise ultrasonic.ukf.W_sigma_mps2 "
                                "far below the heel's accelerations makes the filter lag) and "
                                "the clock offset")
    base = {"study": trial.get("study", ""), "trial": tname,
            "subject": trial.get("subject", subject.get("subject", "")),
            "speed": trial.get("speed", "")}
    rows = _stride_rows(base, st_r, st_s, pairs) + _symmetry_rows(
        base, st_r, al, int(c["symmetry"]["window_strides"]))
    out = pd.DataFrame(rows, columns=GAIT_COLUMNS)
    out["stride"] = out["stride"].astype(np.int64)
    out.attrs.update(clock_offset_s=al["clock_offset_s"], n_strides_reference=len(st_r),
                     n_strides_system=len(st_s), n_matched=len(pairs),
                     registration_rms_m=ref.attrs["registration_rms_m"])
    return out


def _clock_offset(trial: dict) -> float | None:
    """The trial sheet's manual clock offset, or None (estimate by cross-correlation)."""
    off = trial.get("clock_offset_s")
    try:
        return float(off) if off not in (None, "") else None
    except (TypeError, ValueError):
        return None


def _strides(al: dict, sc: dict) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Stride tables of reference and system on the aligned grid; reference strides that
    touch a long reference gap are dropped."""
    fs, t = al["fs"], al["t"]
    kw = {"min_period_s": sc["min_period_s"], "max_period_s": sc["max_period_s"]}
    st_r = stride_table(al["ref"][:, 0], fs, t0=t[0], subsample=sc["subsample_peaks"], **kw)
    st_s = stride_table(al["sys"][:, 0], fs, t0=t[0], subsample=sc["subsample_peaks"], **kw)
    gap = al["gap"]
    if len(st_r):
        bad = [gap[a:b + 1].any() for a, b in zip(st_r["i_start"], st_r["i_end"])]
        st_r = st_r[~np.asarray(bad, dtype=bool)].reset_index(drop=True)
    return st_r, st_s


def _stride_rows(base: dict, st_r: pd.DataFrame, st_s: pd.DataFrame,
                 pairs: list[tuple[int, int]]) -> list[dict]:
    """S, NS, T, V, NV, C of every matched stride (eq. 17–22)."""
    n = len(pairs)
    rows = []
    rec_r, rec_s = st_r.to_dict("records"), st_s.to_dict("records")   # not .iloc per row
    for i, j in pairs:
        r, s = rec_r[i], rec_s[j]
        for p in _PER_STRIDE:
            rv, sv = float(r[p]), float(s[p])
            if p.endswith("_norm"):              # seed003 eq. (18), (21): n = matched strides
                rv, sv = float(r[p.replace("_norm", "")]) / n, \
                    float(s[p.replace("_norm", "")]) / n
            rows.append({**base, "stride": int(r["stride"]), "parameter": p,
                         "unit": PARAMETERS[p], "reference": rv, "system": sv})
    return rows


def _symmetry_rows(base: dict, st_r: pd.DataFrame, al: dict, K: int) -> list[dict]:
    """hS and vS (§3.3.2) per window of ``K`` consecutive reference strides without a gap."""
    fs, gap = al["fs"], al["gap"]
    rows = []
    for w in range(len(st_r) // K if K > 0 else 0):
        a = int(st_r["i_start"].iloc[w * K])
        b = int(st_r["i_end"].iloc[w * K + K - 1])
        if gap[a:b + 1].any():
            continue
        T = float(st_r["stride_duration"].iloc[w * K:w * K + K].mean())
        for axis, p in ((0, "h_symmetry"), (1, "v_symmetry")):
            rs = autocorr_symmetry(al["ref"][a:b + 1, axis], fs, T)["symmetry"]
            ss = autocorr_symmetry(al["sys"][a:b + 1, axis], fs, T)["symmetry"]
            rows.append({**base, "stride": w, "parameter": p, "unit": PARAMETERS[p],
                         "reference": rs, "system": ss})
    return rows
