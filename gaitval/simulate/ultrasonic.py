"""Simulated treadmill and pendulum trials of the ultrasonic gait system (seed 003).

What is simulated, and where things sit
---------------------------------------
*Ultrasonic frame* (the paper's Fig. 1a): X = direction of progression, Y = vertical (up),
Z = X x Y (lateral, pointing to the subject's right).  The four receivers (anchors) sit at
the paper's positions ``p1 = 0``, ``p2 = (0.324, 0, 0)``, ``p3 = (0.324, 0.230, 0)``,
``p4 = (0, 0.230, 0)`` m: a vertical 0.324 x 0.230 m board standing on the floor beside the
treadmill, to the right of the subject, facing the transmitter strapped to the lateral side of
the right heel (the paper: "the transmitter ... pointing towards the four anchors").  The
transmitter therefore moves at Z < 0 (about -0.3 m); a planar array has a mirror solution at
Z > 0, which the tracker excludes by its initial guess.

*Field (mocap) frame*: x along the treadmill (walking direction), y left, z up, z = 0 on the
belt surface (a flush-mounted treadmill; a raised belt only shifts z).  The board's pose in
the field is drawn per study: origin near ``(-0.16, -0.40, 0.0)`` m and a yaw
misalignment of up to 2 degrees, so the ultrasonic frame is *not* the mocap frame.  The
receivers carry markers ``ANC1..ANC4`` (marker centre on the acoustic centre), so the
pipeline recovers the board pose by a rigid fit; the pose is never given to it.

*Heel on a treadmill* (right foot; the left foot is the same model half a cycle later):
a footstep plan of strides with subject-specific duration at each belt speed
(population curve through the paper's Table 8 means, scaled by leg length) and
stride-to-stride variability (CV ~2 %), plus a slow random wander of the foot-strike
position along the belt.  Within stride j (heel strike at ``u = 0``):

* loading and mid-stance, ``0 <= u < u_ho``: the heel rides on the belt backwards at the
  belt speed; the foot pitch goes from dorsiflexed (-0.3 rad) to flat in the first 10 %;
* heel rise, ``u_ho <= u < u_to``: the foot rotates about the metatarsal heads, which still
  move with the belt; pitch ``theta = theta_to s^2`` (heel accelerating upward);
* swing, ``u_to <= u < 1``: cubic Hermite arcs in x and z from the toe-off state (position,
  velocity) to the next foot strike, arriving slightly retracting (vx = -0.2 v) and
  descending (vz = -0.2 m/s): forward arc with heel lift (peak ~0.2 m).

The transmitter is strapped to the heel (acoustic centre 2 cm forward, 4 cm lateral, 1 cm
up of the posterior heel point ``RHEE``) and wobbles on its elastic strap after each heel
strike (2–4 mm, 15 Hz, damped; :mod:`gaitval.simulate.us_treadmill`); its camera marker
``TX`` sits on the shoe beside it, within 4 mm (per axis, drawn per trial) of the acoustic
centre at rest, and turns with the foot but does not wobble, so the camera reference and
the ultrasonic ranges do not see exactly the same point; toe markers follow from the foot
pitch.  Stride times fluctuate as persistent fractional Gaussian noise (H = 0.8).  (Pendulum trials: the marker is aligned with the transducer
head to within 2 mm, as the paper built that experiment to do.)

*Ranging*: time of flight with the speed of sound of dry air ``331.3 sqrt(1 + T/273.15)``
(the physics; the pipeline uses the paper's linear eq. (2), ``331.5 + 0.6 T``, whose
0.1 % error at room temperature is part of what it must live with), Gaussian noise with the
paper's ``V = diag(11, 9.3, 9, 9) mm^2`` per anchor, independent between anchors as the
paper assumes (``noise_common_fraction`` > 0 makes that share of the smallest V common to
the four: :func:`gaitval.simulate.us_sensor.range_noise`), the threshold detector's
delay (the burst's amplitude falls off both transducers' axes and with distance: later
detection, cycle slips of one wavelength or missed echoes; :mod:`gaitval.simulate.us_sensor`),
a 1 us counter tick, occasional multipath (a late echo: path longer by 0.05-0.5 m, probability
``multipath_prob`` per anchor and sample) and missing echoes (``dropout_prob``).  Air
temperature drifts slowly around 22-26 degC and is logged with 0.0625 degC resolution.

*Clocks*: the ultrasonic log starts between 1.5 s before and 3 s after the mocap capture
(and may outlast it by up to 1 s), on its own clock:
``t_us = clock_offset_s + (1 + clock_drift_ppm 1e-6) t_mocap`` with drift up to 10 ppm
(the common brief's convention).  The pipeline must find the offset by cross-correlation.

*Mocap*: 200 Hz, 0.4 mm noise per coordinate (the paper's reference accuracy
0.43 +- 0.18 mm), occasional short TX gaps (one per ~20 s, 10-100 ms).

*Pendulum trials* (seed 003 §4.3): the transmitter (with a marker on it) at the end of a
0.50-0.60 m wooden pendulum pivoting about a horizontal axis, swinging in a plane parallel
to the board ``pendulum_board_distance_m`` (0.3 m) in front of it; held at
``pendulum_release_deg`` (25-35 degrees), released after 1 s and left to swing (nonlinear
pendulum, damping ratio ``pendulum_damping_ratio``, 0.03) for ``pendulum_duration_s``.
One pendulum (length, pivot, swing plane, marker) serves all of a study's pendulum trials,
as the paper built one and released it M times.

Truth (for tests only, never read by the pipeline) goes to ``out_dir/truth/<trial>/``:
``tx.parquet`` (true transmitter path in field and ultrasonic frames on the mocap clock,
100 Hz, float32 coordinates),
``strides.csv`` (true right-heel strikes, durations, belt-relative stride lengths) and
``meta.json`` (clock offset and drift, board pose, noise settings); and one row per trial
in ``out_dir/truth/ultrasonic_truth.csv``.

Where the code lives: the board, ranging physics and clocks in
:mod:`gaitval.simulate.us_sensor`, the heel on the treadmill in
:mod:`gaitval.simulate.us_treadmill`, the pendulum in :mod:`gaitval.simulate.us_pendulum`;
this module draws the study and writes it, and re-exports their public names.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError
from gaitval.io.atomic import write_csv, write_parquet, write_text
from gaitval.io.c3d import write_c3d
from gaitval.io.ultrasonic import write_ultrasonic
from gaitval.simulate.us_pendulum import pendulum_apparatus, simulate_pendulum_trial
from gaitval.simulate.us_sensor import (ANCHOR_IDS, BOARD_DISTANCE_M, PAPER_ANCHORS,
                                        PAPER_V_M2, board_pose, speed_of_sound_true)
from gaitval.simulate.us_treadmill import (foot_points, heel_path, simulate_treadmill_trial,
                                           stride_plan)

__all__ = ["ANCHOR_IDS", "DEFAULTS", "PAPER_ANCHORS", "PAPER_V_M2", "UltrasonicPlan",
           "board_pose", "finish_ultrasonic", "foot_points", "generate_ultrasonic",
           "pendulum_apparatus",
           "heel_path", "plan_ultrasonic", "simulate_pendulum_trial",
           "simulate_treadmill_trial", "simulate_ultrasonic_trial", "speed_of_sound_true",
           "stride_plan"]

#: Shortest treadmill or pendulum trial (s) the simulator accepts.
MIN_TRIAL_S = 5.0

DEFAULTS: dict = {
    "study": "default",
    "n_subjects": 10,
    "speeds": {"slow": 0.54, "normal": 0.99, "fast": 1.40},
    "duration_s": 300.0,
    "n_pendulum_trials": 5,
    "pendulum_duration_s": 20.0,
    "mocap_rate_hz": 200.0,
    "us_rate_hz": 50.0,
    "noise_V_m2": PAPER_V_M2.tolist(),
    "multipath_prob": 0.005,
    "dropout_prob": 0.002,
    "mocap_noise_m": 0.0004,
    "stride_cv": 0.02,
    "pendulum_marker_offset_m": 0.002,
    "pendulum_release_deg": [25.0, 35.0],
    "pendulum_board_distance_m": 0.30,
    "pendulum_damping_ratio": 0.03,
    "noise_common_fraction": 0.0,
    "folder": "ultrasonic",
}


def _write_trial(out_dir: Path, folder: str, trial: str, labels, xyz, mocap_rate, log,
                 truth_tx: pd.DataFrame, truth_meta: dict, strides: pd.DataFrame | None
                 ) -> tuple[str, str]:
    c3d_rel = f"{folder}/{trial}.c3d"
    us_rel = f"{folder}/{trial}.us.parquet"
    write_c3d(out_dir / c3d_rel, labels, xyz, mocap_rate)
    write_ultrasonic(out_dir / us_rel, log, transmitter="right heel" if strides is not None
                     else "pendulum", sensor_model="simulated 40 kHz TOA system (seed 003)")
    tdir = out_dir / "truth" / trial
    step = max(1, int(round(mocap_rate / 100.0)))       # truth path at 100 Hz, float32
    small = truth_tx.iloc[::step].reset_index(drop=True)
    small = small.astype({c: np.float32 for c in small.columns if c != "t_s"})
    write_parquet(small, tdir / "tx.parquet")
    write_text(tdir / "meta.json", json.dumps(truth_meta, indent=1, sort_keys=True) + "\n")
    if strides is not None:
        write_csv(strides, tdir / "strides.csv", float_format="%.6f")
    return c3d_rel, us_rel


#: Log-SD of a subject's stride-duration factor (:func:`plan_ultrasonic`):
#: sqrt(0.096^2 - 0.0215^2), the paper's between-subject CV of S less leg length's share.
T_FACTOR_LOG_SD = 0.0935


def _subjects(rng: np.random.Generator, n: int) -> pd.DataFrame:
    rows = []
    for i in range(n):
        h = float(np.clip(rng.normal(1.714, 0.065), 1.55, 1.90))
        sex = "M" if rng.random() < 0.6 else "F"
        leg = 0.53 * h * (1 + 0.02 * rng.standard_normal())
        rows.append({"subject": f"US{i + 1:02d}", "group": "adult",
                     "age_y": float(np.round(rng.normal(25.7, 1.4), 0)), "sex": sex,
                     "height_m": round(h, 3),
                     "mass_kg": round(float(np.clip(rng.normal(62.8, 5.6), 45, 90)), 1),
                     "leg_width_m": round(float(rng.uniform(0.095, 0.115)), 3),
                     "knee_width_m": round(float(rng.uniform(0.095, 0.11)), 3),
                     "ankle_width_m": round(float(rng.uniform(0.065, 0.075)), 3),
                     "leg_length_m": round(leg, 3), "shank_length_m": round(0.246 * h, 3),
                     "stick": False})
    return pd.DataFrame(rows)


def _trial_row(cfg, protocol, subject, trial, c3d_rel, us_rel, speed="", speed_mps=np.nan,
               repetition=1):
    return {"study": cfg["study"], "protocol": protocol, "subject": subject, "trial": trial,
            "sensor_kind": "ultrasonic", "mocap_file": c3d_rel, "sensor_file": us_rel,
            "sensor_topic": "", "annotation_file": "", "sensor_height_m": np.nan,
            "clock_offset_s": np.nan, "speed": speed, "speed_mps": speed_mps,
            "stick": False, "scenario": "", "repetition": repetition}


def _truth_row(trial: str, meta: dict) -> dict:
    """One row of ``truth/ultrasonic_truth.csv``: the clock and error counts of a trial."""
    return {"trial": trial, "clock_offset_s": meta["clock_offset_s"],
            "clock_drift_ppm": meta["clock_drift_ppm"],
            "n_multipath": meta["n_multipath"], "n_dropout": meta["n_dropout"]}


def _treadmill_tasks(subjects: pd.DataFrame, speeds: dict, t_factor: np.ndarray,
                     trial_seeds) -> list[tuple]:
    """One task per treadmill trial (every subject, one per belt speed, in order)."""
    tasks, k = [], 0
    for si, sub in subjects.iterrows():
        sub = {**sub.to_dict(), "_t_factor": float(t_factor[si])}
        for name, v_nom in speeds.items():
            tasks.append(("treadmill", f"us_{sub['subject']}_{name}", trial_seeds[k],
                          {"subject": sub, "speed": name, "v_nom": float(v_nom)}))
            k += 1
    return tasks


def _pendulum_tasks(pend_seeds) -> list[tuple]:
    """One task per pendulum trial (one child seed each)."""
    return [("pendulum", f"us_pendulum_{i + 1:02d}", ps, {"repetition": i + 1})
            for i, ps in enumerate(pend_seeds)]


@dataclass
class UltrasonicPlan:
    """What :func:`plan_ultrasonic` draws before any trial: the full config, the
    participants, the receiver board's pose in the field (``R``, ``o``), one task per
    trial, each with its own seed, so the trials can be simulated in any order or process,
    and the pendulum all pendulum trials release (``pendulum``,
    :func:`gaitval.simulate.us_pendulum.pendulum_apparatus`)."""

    cfg: dict
    subjects: pd.DataFrame
    R: np.ndarray
    o: np.ndarray
    tasks: list = field(default_factory=list)
    pendulum: dict | None = None


def plan_ultrasonic(cfg: dict | None = None, seed: int = 0) -> UltrasonicPlan:
    """The draws shared by the trials of the ultrasonic study, and its trial tasks."""
    cfg = {**DEFAULTS, **(cfg or {})}
    for key in ("duration_s", "pendulum_duration_s"):
        # the log starts up to 3 s after the capture and stops up to 1.5 s before its end
        # (us_sensor._clock): a shorter trial can leave no ultrasonic sample at all
        if not float(cfg[key]) >= MIN_TRIAL_S:
            raise ConfigError(f"ultrasonic.{key} is {cfg[key]!r} s; the simulated trials "
                              f"need at least {MIN_TRIAL_S:g} s")
    root = np.random.SeedSequence(seed)
    s_subj, s_board, s_trials, s_pend, s_app = root.spawn(5)
    subjects = _subjects(np.random.default_rng(s_subj), int(cfg["n_subjects"]))
    R, o = board_pose(np.random.default_rng(s_board),
                      float(cfg.get("board_distance_m", BOARD_DISTANCE_M)))
    # each subject's own stride duration at a given speed, beyond leg length: with the
    # stride velocity fixed by the speed, the between-subject CV of the stride length is
    # that of the duration, 9.6 % in seed 003 Table 8 (Ref S, normal: 0.112 / 1.169 m);
    # leg length (CV 4.3 %, T ~ sqrt) gives 2.15 %, this factor the rest (log-sd 0.0935)
    t_factor = np.exp(T_FACTOR_LOG_SD * np.random.default_rng(s_subj.spawn(1)[0])
                      .standard_normal(len(subjects)))
    speeds = dict(cfg["speeds"])
    tasks = _treadmill_tasks(subjects, speeds, t_factor,
                             s_trials.spawn(len(subjects) * len(speeds)))
    tasks += _pendulum_tasks(s_pend.spawn(int(cfg["n_pendulum_trials"])))
    # one pendulum with one marker, released n_pendulum_trials times (seed 003 §4.3)
    app = pendulum_apparatus(np.random.default_rng(s_app), cfg)
    return UltrasonicPlan(cfg, subjects, R, o, tasks, app)


def simulate_ultrasonic_trial(out_dir: Path, plan: UltrasonicPlan, task: tuple
                              ) -> tuple[dict, dict]:
    """Simulate and write one trial of :func:`plan_ultrasonic`; its (sheet, truth) rows."""
    kind, trial, trial_seed, extra = task
    cfg, out_dir = plan.cfg, Path(out_dir)
    rng = np.random.default_rng(trial_seed)
    if kind == "treadmill":
        sub = extra["subject"]
        v = float(round(extra["v_nom"] + 0.03 * rng.standard_normal(), 3))
        labels, xyz, log, truth_tx, meta, strides = simulate_treadmill_trial(
            rng, cfg, sub, v, plan.R, plan.o)
    else:
        labels, xyz, log, truth_tx, meta = simulate_pendulum_trial(rng, cfg, plan.R, plan.o,
                                                                   plan.pendulum)
        strides = None
    log.meta["trial"] = trial
    c3d_rel, us_rel = _write_trial(out_dir, cfg["folder"], trial, labels, xyz,
                                   cfg["mocap_rate_hz"], log, truth_tx, meta, strides)
    if kind == "treadmill":
        row = _trial_row(cfg, "treadmill", sub["subject"], trial, c3d_rel, us_rel,
                         extra["speed"], meta["speed_mps"])          # the belt's speed
    else:
        row = _trial_row(cfg, "pendulum", "pendulum", trial, c3d_rel, us_rel,
                         repetition=extra["repetition"])
    return row, _truth_row(trial, meta)


def finish_ultrasonic(out_dir: Path, plan: UltrasonicPlan, results
                      ) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Write ``truth/ultrasonic_truth.csv`` from the trials' results (in task order); the
    (trials, subjects) of :func:`generate_ultrasonic`."""
    rows = [r for r, _ in results]
    truth_rows = [t for _, t in results]
    write_csv(pd.DataFrame(truth_rows), Path(out_dir) / "truth" / "ultrasonic_truth.csv",
              float_format="%.9g")
    subjects = plan.subjects
    if int(plan.cfg["n_pendulum_trials"]) > 0:
        subjects = pd.concat([subjects, pd.DataFrame([{
            "subject": "pendulum", "group": "", "age_y": np.nan, "sex": "",
            "height_m": np.nan, "mass_kg": np.nan, "leg_width_m": 0.05,
            "knee_width_m": np.nan, "ankle_width_m": np.nan, "leg_length_m": np.nan,
            "shank_length_m": np.nan, "stick": False}])], ignore_index=True)
    return pd.DataFrame(rows), subjects


def generate_ultrasonic(out_dir: Path, cfg: dict | None = None, seed: int = 0
                        ) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Write the treadmill and pendulum trials of the ultrasonic study (seed 003).

    Parameters
    ----------
    out_dir : Path
        Study folder; files go to ``out_dir/<folder>/`` and truth to ``out_dir/truth/``.
    cfg : dict, optional
        Keys (defaults in :data:`DEFAULTS`): ``study`` ("default"), ``n_subjects`` (10),
        ``speeds`` ({slow: 0.54, normal: 0.99, fast: 1.40} m/s), ``duration_s`` (300;
        at least :data:`MIN_TRIAL_S`), ``n_pendulum_trials`` (5), ``pendulum_duration_s``
        (20; at least :data:`MIN_TRIAL_S`), ``mocap_rate_hz`` (200),
        ``us_rate_hz`` (50), ``noise_V_m2`` (the paper's V), ``multipath_prob`` (0.005),
        ``dropout_prob`` (0.002), ``mocap_noise_m`` (0.0004), ``stride_cv`` (0.02),
        ``pendulum_marker_offset_m`` (0.002: largest per-axis offset of the pendulum's
        camera marker from the transducer head), ``pendulum_release_deg`` ([25, 35]:
        range of the release angle), ``pendulum_board_distance_m`` (0.30),
        ``pendulum_damping_ratio`` (0.03), ``noise_common_fraction`` (0: share of the
        smallest V common to the four anchors), ``board_distance_m`` (the receiver
        board from the heel transmitter's path, :data:`BOARD_DISTANCE_M`), ``folder``
        ("ultrasonic").
    seed : int
        Seed of ``np.random.default_rng``; each trial gets its own child stream, so the
        same seed gives byte-identical files.

    Returns
    -------
    trials : DataFrame
        Trial-sheet rows (columns of the common brief), paths relative to ``out_dir``;
        protocols ``treadmill`` and ``pendulum``, sensor_kind ``ultrasonic``.
    subjects : DataFrame
        Subject-table rows: ``US01..`` (adults like the paper's: 25.7 +- 1.4 y,
        1.714 +- 0.065 m, 62.8 +- 5.6 kg) and a ``pendulum`` row for the pendulum trials
        (``leg_width_m`` is the pendulum arm's width; the subject table requires it).

    Notes
    -----
    The same three steps :func:`gaitval.simulate.study.generate_study` spreads over its
    worker processes: :func:`plan_ultrasonic` (the shared draws), one
    :func:`simulate_ultrasonic_trial` per task, :func:`finish_ultrasonic`.
    """
    plan = plan_ultrasonic(cfg, seed)
    results = [simulate_ultrasonic_trial(out_dir, plan, task) for task in plan.tasks]
    return finish_ultrasonic(out_dir, plan, results)
