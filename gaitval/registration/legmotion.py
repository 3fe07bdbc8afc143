"""The subject's leg motion as registration receives it, and the two ways it is used.

Registration needs the mocap side of an LRS trial twice: the leg points at sensor height,
pooled over the trial, as motion evidence that tells apart pole-pose hypotheses (step 4 of
:mod:`gaitval.registration.poles`), and per mocap frame in the sensor frame, to predict
which beams the legs occupy for the clock synchronisation
(:func:`gaitval.registration.clock.lrs_occupancy_signals`).

Registration does not compute these points.  The ground truth, a stage above, owns them
(markers -> gap filling -> joint centres -> point at the scan height, its
``legs.leg_points``); the pipeline (``steps.register_step``) computes them once per trial
with the ground truth's ``sensor_leg_points`` and hands the same object to
:func:`~gaitval.registration.trial.register_trial` and then to the ground truth's
``ground_truth``.  Anything with the attributes of :class:`LegMotion` will do, so
registration never imports the ground truth.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np

from gaitval import consts as C
from gaitval.registration.moving import (mount_from_cfg, rollator_labels, rollator_pose,
                                         sensor_pose_from_rollator)
from gaitval.registration.rigid import field_to_sensor
from gaitval.types import MocapTrial

#: At most this many pooled leg points are used as pole motion evidence.
MAX_EVIDENCE_POINTS = 1000


class LegMotion(Protocol):
    """What registration reads from the leg points handed to it.

    Attributes
    ----------
    t : ndarray (n_frames,)
        Mocap frame times, seconds.
    xyz : ndarray (n_frames, 2, 3)
        Leg points at sensor height in the field frame, metres; legs in order ``L, R``.
    valid : ndarray (n_frames, 2) bool
    source : str
        How the joint centres were found (``joint_centre_source`` of the record).
    n_excluded : int
        Mocap frames where either leg point is missing (``gt_frames_excluded``).
    markers : dict
        Gap-filled marker arrays (label -> (n_frames, 3)); for a moving sensor it holds
        the rollator markers (a rollator label missing here is read raw from the C3D).
    """

    t: np.ndarray
    xyz: np.ndarray
    valid: np.ndarray
    source: str
    n_excluded: int
    markers: dict


def pole_evidence(legs: LegMotion, max_points: int = MAX_EVIDENCE_POINTS) -> np.ndarray:
    """Leg points (m, 2) in the field of the frames where both legs are known, evenly
    thinned to at most ``max_points``: the motion evidence of the pole registration."""
    ok = legs.valid.all(axis=1)
    pts = legs.xyz[ok][:, :, :2].reshape(-1, 2)
    if len(pts) > max_points:
        pts = pts[np.linspace(0, len(pts) - 1, max_points).astype(int)]
    return pts


def legs_in_sensor_frame(mocap: MocapTrial, legs: LegMotion, trial: dict, cfg: dict | None,
                         pose: tuple[float, float, float] | None = None) -> np.ndarray:
    """Leg points (n_frames, 2, 2) in the sensor frame: through the fixed ``pose``, or, when
    ``pose`` is None (moving sensor), through the per-frame sensor pose from the rollator
    markers and ``rollator.sensor_mount`` (:mod:`gaitval.registration.moving`)."""
    P = legs.xyz[..., :2]
    if pose is not None:
        return field_to_sensor(P, *pose)
    tid = trial.get(C.TRIAL)
    rp = rollator_pose(mocap, rollator_labels(cfg), trial=tid, xyz=legs.markers)
    pm = sensor_pose_from_rollator(rp, mount_from_cfg(cfg, tid))
    return field_to_sensor(P, pm[:, None, 0], pm[:, None, 1], pm[:, None, 2])
