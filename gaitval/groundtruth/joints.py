"""Knee and ankle joint centres from markers, in a documented order of preference.

For each side ``S`` (``L``/``R``) and each joint the first available source is used:

1. ``pig_bone_outputs``: Plug-in-Gait bone outputs ``SFEO`` (femur origin = knee joint
   centre) and ``STIO`` (tibia origin = ankle joint centre);
   ``joint_centre_markers``: explicit ``SKJC`` / ``SAJC`` (e.g. OpenSim marker sets);
2. ``lateral_medial_midpoint``: midpoint of ``SKNE``/``SKNEin`` and ``SANK``/``SANKin``;
3. ``lateral_offset``: the lateral marker ``SKNE`` / ``SANK`` moved medially by half the
   joint width from the subject table (``knee_width_m`` / ``ankle_width_m``), horizontally.
   The medial direction is, per frame, the horizontal unit vector from this side's ASIS
   to the other side's (``LASI -> RASI`` for the left leg); where an ASIS marker is
   missing, from this lateral marker to the other leg's same lateral marker.  (The knee
   flexion axis is close to the pelvis' medio-lateral axis in walking; in turns the
   difference is a few degrees, i.e. ~1 mm at half a knee width.)

A source is available when its markers are in the C3D with at least one valid frame
(gaps are handled afterwards, not by switching source).  The source actually used is
reported as ``joint_centre_source`` (one name, or ``L:<knee>/<ankle>;R:...`` when joints
or sides differ).
"""
from __future__ import annotations

import numpy as np

from gaitval.config import as_float
from gaitval.errors import MarkerError
from gaitval.types import MocapTrial

SOURCES = ("pig_bone_outputs", "joint_centre_markers", "lateral_medial_midpoint",
           "lateral_offset")


def _has(mocap: MocapTrial, lb: str) -> bool:
    return mocap.has(lb) and bool(np.isfinite(mocap.marker(lb)).all(axis=1).any())


def _get(mocap, lb, markers):
    return markers[lb] if markers is not None and lb in markers else mocap.marker(lb)


def _medial_dir(mocap, side, lateral_label, markers):
    other = "R" if side == "L" else "L"
    n = mocap.n_frames
    u = np.full((n, 2), np.nan)
    if _has(mocap, f"{side}ASI") and _has(mocap, f"{other}ASI"):
        u = _get(mocap, f"{other}ASI", markers)[:, :2] - _get(mocap, f"{side}ASI", markers)[:, :2]
    ol = other + lateral_label[1:]
    if _has(mocap, ol):
        alt = _get(mocap, ol, markers)[:, :2] - _get(mocap, lateral_label, markers)[:, :2]
        bad = ~np.all(np.isfinite(u), axis=1)
        u[bad] = alt[bad]
    with np.errstate(invalid="ignore", divide="ignore"):
        return u / np.linalg.norm(u, axis=1, keepdims=True)


def joint_centre(mocap: MocapTrial, side: str, joint: str, subject: dict | None = None, *,
                 markers: dict | None = None, trial: str | None = None
                 ) -> tuple[np.ndarray, str]:
    """One joint centre (``joint`` = ``knee`` or ``ankle``) of one side.

    Parameters
    ----------
    mocap : MocapTrial
    side : ``"L"`` or ``"R"``
    joint : ``"knee"`` or ``"ankle"``
    subject : dict, optional
        Subject-table row (``knee_width_m``, ``ankle_width_m``) for the lateral-offset source.
    markers : dict, optional
        Gap-filled marker arrays (label -> (n, 3) metres) to use instead of the raw ones.

    Returns
    -------
    xyz : ndarray (n_frames, 3), metres, field frame (NaN in gaps)
    source : str, one of :data:`SOURCES`

    Raises
    ------
    MarkerError
        When no source is available (names the markers looked for).
    """
    bone, jc, lat, width = {"knee": ("FEO", "KJC", "KNE", "knee_width_m"),
                            "ankle": ("TIO", "AJC", "ANK", "ankle_width_m")}[joint]
    S = side
    if _has(mocap, S + bone):
        return _get(mocap, S + bone, markers), "pig_bone_outputs"
    if _has(mocap, S + jc):
        return _get(mocap, S + jc, markers), "joint_centre_markers"
    if _has(mocap, S + lat) and _has(mocap, S + lat + "in"):
        return 0.5 * (_get(mocap, S + lat, markers) + _get(mocap, S + lat + "in", markers)), \
            "lateral_medial_midpoint"
    if _has(mocap, S + lat):
        w = as_float((subject or {}).get(width))
        if w is None:
            raise MarkerError(
                f"the {S} {joint} centre needs {S}{bone}/{S}{jc}, {S}{lat}+{S}{lat}in, or "
                f"{S}{lat} with the subject's {width}, which is empty",
                path=mocap.path, trial=trial,
                hint=f"fill {width} in subjects.csv or add medial markers")
        u = _medial_dir(mocap, S, S + lat, markers)
        p = _get(mocap, S + lat, markers).copy()
        p[:, :2] = p[:, :2] + 0.5 * w * u
        return p, "lateral_offset"
    raise MarkerError(
        f"no marker for the {S} {joint} centre: looked for {S}{bone}, {S}{jc}, "
        f"{S}{lat}(+{S}{lat}in)", path=mocap.path, trial=trial,
        hint="the trial needs Plug-in-Gait knee/ankle markers or joint centres")


def source_label(sources: dict) -> str:
    """Summarise ``{(side, joint): source}`` as one name or ``L:knee/ankle;R:...``."""
    vals = set(sources.values())
    if len(vals) == 1:
        return vals.pop()
    parts = []
    for side in ("L", "R"):
        k, a = sources.get((side, "knee")), sources.get((side, "ankle"))
        if k is None and a is None:
            continue
        parts.append(f"{side}:{k}" if k == a else f"{side}:{k}/{a}")
    return ";".join(parts)
