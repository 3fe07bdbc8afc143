"""Knee and ankle joint centres from markers, in a documented order of preference.

For each side ``S`` (``L``/``R``) and each joint the first available source is used:

1. ``pig_bone_outputs``: Plug-in-Gait bone outputs ``SFEO`` (femur origin = knee joint
   centre) and ``STIO`` (tibia origin = ankle joint centre);
   ``joint_centre_markers``: explicit ``SKJC`` / ``SAJC`` (e.g. OpenSim marker sets);
2. ``lateral_medial_midpoint``: midpoint of ``SKNE``/``SKNEin`` and ``SANK``/``SANKin``;
3. ``lateral_offset``: the lateral marker ``SKNE`` / ``SANK`` moved medially by half the
   joint width from the subject table (``knee_width_m`` / ``ankle_width_m``) plus the
   marker's radius, horizontally: Plug-in Gait's offset of the joint centre from its
   lateral marker, ``(joint width + marker diameter) / 2`` (CGM1 / VCM "chord"; the
   caller passes half of :data:`MARKER_DIAMETER_M`, PiG's default 14 mm markers).  The
   medial direction is, per frame, perpendicular to this side's foot long axis (heel ->
   toe, horizontal; with one foot marker missing, the other one and the malleolus marker,
   :func:`_foot_heading`): the knee and ankle flexion axes turn with the shank and the
   foot, whereas the pelvis turns ahead of a planted foot in a turn (hip rotation).
   Where both foot markers are missing, the pelvis axis (``SASI -> other ASI``) turned by
   the foot-to-pelvis angle interpolated across the gap; without foot markers the pelvis
   axis itself; where an ASIS marker is missing too, from this lateral marker to the
   other leg's same lateral marker.  (Until issue 10 the rule was the pelvis axis and half
   the joint width: 7 mm off everywhere, and in the twin's turns, where the foot points up
   to 60° away from the pelvis, up to 45 mm (tiny) and 92 mm (default study) off; see
   docs/simulator.md.)  Not modelled: a foot turned out against the knee axis (tibial
   torsion; the twin has none), which on real data turns the medial direction with it.

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

#: Diameter of the lateral knee and ankle markers (m): Plug-in Gait's default
#: ``MarkerDiameter`` (14 mm), also the twin's markers (``simulate/markers.py``).  The
#: seed papers do not state theirs.  Not a config key yet (the config schema lives in
#: workflow/); a lab with other markers passes ``marker_radius_m`` to :func:`joint_centre`.
MARKER_DIAMETER_M = 0.014

#: Shortest horizontal heel-to-toe distance (m) that defines a foot heading.
MIN_FOOT_AXIS_M = 0.03

SOURCES = ("pig_bone_outputs", "joint_centre_markers", "lateral_medial_midpoint",
           "lateral_offset")


def _has(mocap: MocapTrial, lb: str) -> bool:
    return mocap.has(lb) and bool(np.isfinite(mocap.marker(lb)).all(axis=1).any())


def _get(mocap, lb, markers):
    return markers[lb] if markers is not None and lb in markers else mocap.marker(lb)


def _horizontal_angle(v: np.ndarray, min_norm: float = 0.0) -> np.ndarray:
    """Heading (rad) of the horizontal part of ``v`` (n, 2+); NaN where it is missing or
    shorter than ``min_norm``."""
    a = np.arctan2(v[:, 1], v[:, 0])
    a[~(np.hypot(v[:, 0], v[:, 1]) > min_norm)] = np.nan
    return a


def _foot_heading(mocap, side, markers, ank_offset_m):
    """Heading (rad) of this side's foot long axis per frame, NaN where unknown.

    The long axis runs from the heel marker ``SHEE`` through the ankle joint centre to the
    toe marker ``STOE`` (Plug-in Gait's foot axis, ankle centre to toe).  Where one of the
    two foot markers is missing, the other one and the lateral malleolus marker ``SANK``
    give it: ``SANK`` sits ``ank_offset_m`` lateral of the ankle centre, perpendicular to
    the axis, so the horizontal ``SHEE - SANK`` (or ``STOE - SANK``) is ``d`` along the
    axis and ``ank_offset_m`` across it.  The heel comes first (``d`` ≈ 6 cm all the
    time; the toe is only ≈ 1 cm ahead of the ankle at toe off).
    """
    n = mocap.n_frames
    hee, toe, ank = (f"{side}{x}" for x in ("HEE", "TOE", "ANK"))
    P = {lb: (_get(mocap, lb, markers)[:, :2] if _has(mocap, lb) else np.full((n, 2), np.nan))
         for lb in (hee, toe, ank)}
    h = _horizontal_angle(P[toe] - P[hee], MIN_FOOT_AXIS_M)
    if ank_offset_m is None or not ank_offset_m > 0:
        return h
    sigma = -1.0 if side == "L" else 1.0      # the medial side is at sigma · 90° of forward
    for lb, behind in ((hee, True), (toe, False)):
        v = P[lb] - P[ank]
        r2 = np.sum(v ** 2, axis=1)
        with np.errstate(invalid="ignore"):
            d = np.sqrt(np.maximum(r2 - ank_offset_m ** 2, 0.0))
            ok = np.isnan(h) & (d > MIN_FOOT_AXIS_M / 2)
        across = np.arctan2(ank_offset_m, d)
        est = np.arctan2(v[:, 1], v[:, 0]) - sigma * (np.pi - across if behind else across)
        h = np.where(ok, est, h)
    return h


def _medial_dir(mocap, side, lateral_label, markers, ank_offset_m=None):
    """Horizontal unit vector from ``lateral_label`` towards the joint centre, per frame
    (NaN where no rule applies); the rules are in the module notes."""
    other = "R" if side == "L" else "L"
    n = mocap.n_frames
    a_pel = np.full(n, np.nan)
    if _has(mocap, f"{side}ASI") and _has(mocap, f"{other}ASI"):
        a_pel = _horizontal_angle(_get(mocap, f"{other}ASI", markers)
                                  - _get(mocap, f"{side}ASI", markers))
    # foot long axis turned 90° towards the body's midline (right of the heading for the
    # left leg, left of it for the right leg); in its gaps the pelvis axis turned by the
    # foot-to-pelvis angle interpolated across the gap
    a_foot = _foot_heading(mocap, side, markers, ank_offset_m) \
        + (-0.5 * np.pi if side == "L" else 0.5 * np.pi)
    rel = np.angle(np.exp(1j * (a_foot - a_pel)))
    both = np.isfinite(rel)
    a = np.where(np.isfinite(a_foot), a_foot, a_pel)
    if both.any():
        k = np.arange(n)
        a = np.where(np.isfinite(a_foot), a_foot,
                     a_pel + np.interp(k, k[both], np.unwrap(rel[both])))
    u = np.column_stack([np.cos(a), np.sin(a)])
    ol = other + lateral_label[1:]
    if _has(mocap, ol):
        alt = _get(mocap, ol, markers)[:, :2] - _get(mocap, lateral_label, markers)[:, :2]
        with np.errstate(invalid="ignore", divide="ignore"):
            alt = alt / np.linalg.norm(alt, axis=1, keepdims=True)
        bad = ~np.all(np.isfinite(u), axis=1)
        u[bad] = alt[bad]
    return u


def joint_centre(mocap: MocapTrial, side: str, joint: str, subject: dict | None = None, *,
                 markers: dict | None = None, trial: str | None = None,
                 marker_radius_m: float = 0.0) -> tuple[np.ndarray, str]:
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
    marker_radius_m : float
        Radius of the lateral marker (its centre is this far outside the skin), added to
        half the joint width by the lateral-offset source; :func:`~gaitval.groundtruth.
        legs.leg_points` passes half of :data:`MARKER_DIAMETER_M`.

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
        wa = as_float((subject or {}).get("ankle_width_m"))
        u = _medial_dir(mocap, S, S + lat, markers,
                        None if wa is None else 0.5 * wa + marker_radius_m)
        p = _get(mocap, S + lat, markers).copy()
        p[:, :2] = p[:, :2] + (0.5 * w + marker_radius_m) * u
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
