"""Seed 003's camera reference: the transmitter marker in the ultrasonic frame.

The transmitter carries a camera marker (``TX``); the receivers carry ``ANC1..``.  The
reference trajectory of seed 003 (§4.1, Tables 1–8) is ``TX`` brought into the ultrasonic
system's frame by the rigid fit of the receiver markers to the log's anchor positions
(:func:`gaitval.registration.anchors.fit_anchor_frame`, marker means), on the mocap
clock, with its gaps bridged linearly
(:func:`gaitval.groundtruth.gaps.fill_short_gaps`, ``method="linear"``) and the samples in
long gaps flagged.

Frames: the ultrasonic frame of the log's anchor geometry (seed 003: X progression, Y
vertical, Z lateral), not the mocap field frame.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import MarkerError
from gaitval.groundtruth.gaps import fill_short_gaps
from gaitval.registration.anchors import DEFAULT_MARKERS, fit_anchor_frame
from gaitval.types import MocapTrial

#: Longest reference gap trusted after linear bridging (s); config ``reference.max_gap_s``.
MAX_GAP_S = 0.2
#: Largest receiver-marker residual of the anchor fit (m).
MAX_ANCHOR_RESIDUAL_M = 0.02


def reference_trajectory(mocap: MocapTrial, anchors: pd.DataFrame, *, tx_marker: str = "TX",
                         anchor_markers=DEFAULT_MARKERS, max_gap_s: float = MAX_GAP_S,
                         trial: str | None = None) -> pd.DataFrame:
    """The camera reference: marker ``tx_marker`` in the ultrasonic frame on the mocap clock.

    Parameters
    ----------
    mocap : MocapTrial
        The trial's C3D with the transmitter marker and the receiver markers.
    anchors : DataFrame
        ``anchor, x_m, y_m, z_m``: the log's anchor table (ultrasonic frame).
    tx_marker : str
        Transmitter marker label (config ``ultrasonic.transmitter_marker``).
    anchor_markers : sequence of str
        Receiver marker labels in anchor order (config ``ultrasonic.anchor_markers``).
    max_gap_s : float
        Gaps longer than this (and gaps at the ends) are flagged in ``gap``
        (config ``ultrasonic.reference.max_gap_s``).
    trial : str, optional
        For error messages.

    Returns
    -------
    DataFrame
        ``t_s`` (mocap time), ``x_m, y_m, z_m`` (ultrasonic frame; gaps bridged linearly),
        ``gap`` (True inside gaps longer than ``max_gap_s`` or at the ends).
        ``attrs``: ``registration_rms_m`` (RMS residual of the anchor fit, metres).

    Raises
    ------
    MarkerError
        No transmitter marker, or fewer than two samples of it.
    RegistrationError
        The receiver markers do not register the anchors (see
        :func:`~gaitval.registration.anchors.fit_anchor_frame`).
    """
    if not mocap.has(tx_marker):
        raise MarkerError(f"transmitter marker {tx_marker!r} is not in the C3D",
                          path=mocap.path, trial=trial,
                          hint="set ultrasonic.transmitter_marker")
    fit = fit_anchor_frame(mocap, anchors, anchor_markers, centre="mean",
                           max_residual_m=MAX_ANCHOR_RESIDUAL_M, trial=trial)
    p = fit.to_ultrasonic(mocap.marker(tx_marker))                 # p_us = R^T (p_f - t)
    t = mocap.t
    rate = 1.0 / np.median(np.diff(t))                     # the samples' own rate
    filled, short = fill_short_gaps(p, rate, max_gap_s, method="linear", t=t)
    missing = ~np.all(np.isfinite(p), axis=1)
    if (~missing).sum() < 2:
        raise MarkerError(f"transmitter marker {tx_marker!r} has fewer than two samples",
                          path=mocap.path, trial=trial)
    df = pd.DataFrame({"t_s": t, "x_m": filled[:, 0], "y_m": filled[:, 1],
                       "z_m": filled[:, 2], "gap": missing & ~short})
    df.attrs["registration_rms_m"] = fit.rms_m
    return df
