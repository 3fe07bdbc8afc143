"""Physical checks of a simulated study: does the twin move like people and look like the
papers' recordings?  Written to ``data/<study>/physics.csv`` by :func:`write_physics`
(:func:`gaitval.simulate.generate_study` calls it for every simulated study).

Every row is one check: the twin's value, a reference, where the reference comes from, the
tolerance and whether the twin passes.  **The tolerances below were written down before
any twin value of these checks was computed (issue 10); a failing row is a finding to
report (``docs/simulator.md``), never a knob to turn until a tracker wins.**

========================  ==============================================================
check                     twin value / reference / tolerance
========================  ==============================================================
swing_shin_backward       per protocol: swings whose shin point (at sensor height, 10 Hz
                          low-pass) moves backwards along the swing's own direction faster
                          than :data:`SWING_BACKWARD_MPS`; reference 0 (a swinging shank is
                          carried forward by the thigh; the real C3D walks measured the same
                          way never go backwards); pass: no such swing
first_swing_backward      the same for each trial's first swing from standing (gait
                          initiation; the note gives its duration ÷ the trial's median
                          swing, 1 by the model); pass: no such swing
shin_swing_peak           peak swing speed / walking speed of the study's walkers on steady
                          straight walks vs the three real C3D walks
                          (:mod:`gaitval.simulate.shin`); pass: within ±15 %
shin_stance_speed         mean stance speed / walking speed, same walks; pass: within ±30 %
step_length, cadence      straight-walking steps of the twin's footfalls vs the published
                          range of the population (:data:`STEP_RANGES`); pass: mean inside
tug_phase_duration        forward / turning / return seconds per trial vs seed 000 Table 4
                          (leg-scans / 25 trials / 2 legs / 40 Hz); pass: within ±25 %.
                          Phases (issue 34): the rule that labels the reproduced Table 4
                          (:func:`gaitval.evaluate.tug_truth.tug_phase_bounds`: walking
                          direction more than 30° off the outbound / return line) applied
                          to the twin's true legs (the truth ``phase`` column); before, the
                          twin's step labels (first turning lift-off to first return
                          contact), given in the note.  Since the issue-34 follow-up the
                          three phases span the TUG, from the start of the rise to seated
                          (seed 000: "three TUG phases"); the capture's still-seated spans
                          before and after are labelled ``seated`` and not counted (the
                          whole-capture values are in the notes).  Tolerance unchanged
tug_occlusion             per TUG phase, leg-scans with < 3 returning beams vs seed 000
                          Table 4 (Method 2: 3.5 / 11.3 / 5.1 %); pass: ratio in [2/3, 3/2];
                          the note names what is on the line of sight (:func:`occluders`).
                          The forward and turning rows are the calibration targets of the
                          TUG sensor placement and the marker's section in the scan plane
                          (``experiments/tug_scene_calibration.py``), so only the return
                          row is an independent check; seed 000 counts the tracker's
                          unobservable steps, the twin the truth (docs/simulator.md)
tug_turn_to_sit           seconds from the last return-line contact to the last contact
                          before sitting vs 1.7 ± 0.5 s (final 180° turn of the TUG,
                          healthy adults); pass: inside mean ± 2 SD
tug_return_to_chair       lateral distance of the return path from the chair's axis where
                          the turn to sit starts (out-and-back, seed 000 §1); pass: ≤ 0.25 m
tug_marker_clearance      closest approach of a shank's surface to the marker's footprint
                          over the whole trial (the legs go around it, not through it;
                          before issue 34's turn model, over the turning phase); pass: > 0
tug_turn_radius           mean distance of the turning footholds from the marker; no
                          published value (shown; the clearance row is its check)
tug_turn_step_time        mean step time of the steps turning around the marker ÷ the
                          mean straight step time of the same trials; reference 1.0
                          (curved walking keeps the straight stepping rate); pass: within
                          ±10 % (:data:`TURN_STEP_TIME_REL`)
shank_clearance           per protocol: per swing, the closest the two shank centres come
                          (truth legs at sensor height, mocap rate) ÷ the subject's leg
                          width; value: the smallest over all swings (issue 34: a swing
                          shank goes around the standing one); pass: ≥ 0.95 in every swing
                          (:data:`SHANK_CLEARANCE_MIN`; the note counts swings below it)
shank_overlap_scans       per protocol: fraction of scans (truth ``scans_legs``, inside the
                          capture) whose two shank centres are closer than 0.95 × leg
                          width; reference 0; pass: 0
tug_sit_foot_separation   per TUG trial, |distance between the shank centres when seated
                          at the end − the same at the start| (feet back at hip width, as
                          when the trial began); value: the worst trial; pass: ≤
                          :data:`SIT_SEPARATION_TOL_M`
tug_turn_to_sit_cross     cross steps among the turn-to-sit steps (people pivot without
                          crossing the legs); reference 0; pass: 0
mtst_cross_steps          cross steps per 100 steps from the twin's truth footfalls vs seed 001
                          Table 4 (19 of 414 = 4.6); pass: inside the exact 95 % Poisson
                          interval of 19 counts (2.8–7.2 per 100)
treadmill_stride_sd       stride-to-stride SD of the reference stride length per trial (eq.
                          (17) on the true heel path, as the paper's reference system) vs
                          seed 003 Table 2 (Ref std, 0.019–0.056 m over subjects); pass: the
                          twin's mean inside that range
treadmill_subject_sd_     per belt speed: SD over subjects of their mean eq. (17) stride
  stride_length           length vs Table 8's reference SD (0.095, 0.112, 0.091 m); pass:
                          inside the 95 % chi-square interval of an SD of 10 subjects
treadmill_eq17_stride_    per belt speed: mean stride length by seed 003 eq. (17) on the
  length                  twin's true heel path vs Table 8's reference mean (0.884, 1.169,
                          1.410 m); pass: within 3 % (:data:`TREADMILL_EQ17_REL`)
pendulum_error_sd         per axis (X, Y, Z): SD of the pendulum's UKF estimate minus the
                          camera, as the pipeline's Table 1 makes it (V and W identified on
                          the trials) vs seed 003 Table 1 (4.08, 0.72, 1.08 mm); pass:
                          within a factor 1.5 either way (:data:`PENDULUM_SD_FACTOR`)
========================  ==============================================================

References
----------
Yorozu A, Moriguchi T, Takahashi M. Sensors 2015;15:22451–22472 (seed 000: Table 4).
Yorozu A et al. Sensors 2015;15:11151–11168 (seed 001: Table 4, 19 cross steps of 414).
Qi Y et al. Sensors 2014;14:15434–15457 (seed 003: Tables 2 and 8).
Podsiadlo D, Richardson S. The timed "Up & Go". J Am Geriatr Soc 1991;39:142–148.
Espy DD, Yang F, Bhatt T, Pai Y-C. Independent influence of gait speed and step length on
stability and fall risk. Gait Posture 2010;32:378–382, Table 2 (PMC2943048).
Aging Clin Exp Res 2020;33:1853–1864, doi:10.1007/s40520-020-01715-9, Table 3 (iTUG,
healthy controls: final 180° turn 1.7 ± 0.5 s).
Tudor-Locke C et al. (walk-to-run transition cadence ≈ 140 steps/min in adults; cited in
Sensors 2021;21:7910, PMC8629136).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.atomic import write_csv
from gaitval.simulate.swings import lrs_trials, swing_stats
from gaitval.simulate.physics_rows import (  # noqa: F401
    COLUMNS, GROUP_OF, _row, _straight_steps, poisson_ci)
from gaitval.simulate.physics_tug import (  # noqa: F401  (the TUG rows and their references)
    OCCLUSION_FACTOR, TUG_OCCLUSION, TUG_PHASE_LEG_SCANS, TUG_PHASE_REL, _tug_path_rows,
    _tug_phase_rows, _tug_sit_rows, occluders, step_label_bounds, tug_scene_circles, tug_span,
    tug_timeline)
from gaitval.simulate.physics_ultrasonic import (  # noqa: F401
    PENDULUM_SD_FACTOR, PENDULUM_SD_M, TREADMILL_EQ17_REL, TREADMILL_EQ17_S_M,
    TREADMILL_STRIDE_SD_M, TREADMILL_SUBJECT_SD_S_M, _pendulum_rows, _treadmill_rows)

# --------------------------------------------------------------------------------------
# Tolerances and references: stated before any value of these checks was computed.
# --------------------------------------------------------------------------------------
#: A swing "moves backwards" when the shin point's speed along the swing's direction
#: drops below this (m/s): numerical noise of the low-passed truth is far smaller.
SWING_BACKWARD_MPS = -0.05
#: Shin speed profile against the real C3D walks (the tolerances of
#: tests/test_simulate.py::test_simulated_shin_speed_profile_matches_real_walks).
SHIN_PEAK_REL = 0.15
SHIN_STANCE_REL = 0.30
#: Issue 34 (stated before the contact model was written): the two shank centres at sensor
#: height never come closer than this many leg widths in any swing (two 10 cm sections
#: touch at 1.0; 5 % for soft tissue and trouser cloth), and no scan has them closer.
SHANK_CLEARANCE_MIN = 0.95
#: seed 001 Table 4: cross steps, steps.
MTST_CROSS = (19, 414)#: Published step length (/ body height) and cadence (steps/min) ranges per walker group.
#: young: TUG at maximum speed — from seed 003's fast treadmill walking (stride
#: 1.410 ± 0.090 m at 1.714 m height, mean ± 2 SD; cadence 0.993 strides/s = 119 /min)
#: up to the walk-to-run transition cadence (≈ 140 /min).  elderly: the published older-
#: adult groups of Espy et al. 2010 Table 2 (step 0.297–0.403 body heights, speed / step
#: length 1.75–1.98 /s = 105–119 /min).  patient: no published range (seed 002 gives none).
STEP_RANGES = {
    "young": {"step_per_height": ((1.410 - 2 * 0.090) / 2 / 1.714,
                                  (1.410 + 2 * 0.090) / 2 / 1.714),
              "cadence_per_min": (0.993 * 120, 140.0),
              "source": "seed 003 Table 8 (fast, mean ± 2 SD); walk-run transition cadence"},
    "elderly": {"step_per_height": (0.297, 0.403), "cadence_per_min": (1.75 * 60, 1.98 * 60),
                "source": "Espy et al. 2010 Table 2 (older-adult groups)"},
}
def _swing_rows(study_dir: Path, trials: pd.DataFrame, real: dict | None,
                stats: dict) -> list[dict]:
    """The swing rows from ``stats``: :func:`swing_stats` of every trial, by name."""
    rows = []
    ref = real["swing_fwd_min_mps"] if real else np.nan
    for proto, g in trials.groupby("protocol", sort=True):
        mins = np.concatenate([stats[t][0] for t in g["trial"]])
        n_back = int(np.sum(mins < SWING_BACKWARD_MPS))
        rows.append(_row("swing_shin_backward", proto, n_back, 0, 0, 0, "swings",
                         f"no swing below {SWING_BACKWARD_MPS} m/s forward",
                         "real gait; the real C3D walks' lowest swing forward speed is "
                         f"{ref:.2f} m/s", group=GROUP_OF.get(proto, ""),
                         note=f"{len(mins)} swings; lowest forward speed "
                              f"{np.min(mins) if len(mins) else np.nan:.2f} m/s"))
        first = np.array([stats[t][1] for t in g["trial"]])
        rows.append(_row("first_swing_backward", proto,
                         int(np.sum(first[:, 0] < SWING_BACKWARD_MPS)), 0, 0, 0, "swings",
                         f"no first swing below {SWING_BACKWARD_MPS} m/s forward",
                         "gait initiation (docs/simulator.md): hip and knee lead the first "
                         "step, the thigh carries the knee forward", group=GROUP_OF.get(proto, ""),
                         note=f"{_n_first(first)} first swings from standing; lowest "
                              f"forward speed {np.nanmin(first[:, 0]):.2f} m/s; duration "
                              f"{first[:, 1].min():.2f}-{first[:, 1].max():.2f} x the trial's "
                              "median swing"))
    return rows


def _n_first(first: np.ndarray) -> str:
    """How many first swings the row measured (a shuffle with no direction is not)."""
    n_nan = int(np.isnan(first[:, 0]).sum())
    shuffles = f" ({n_nan} more without a direction: the shin moved < 5 cm)" if n_nan else ""
    return f"{len(first) - n_nan}{shuffles}"


def _shin_rows(walkers: list | None, realdata: Path | None) -> tuple[list[dict], dict | None]:
    """Shin-height peak swing and stance speed of the study's walkers vs the real walks."""
    from gaitval.simulate.shin import MEASURES, REAL_WALKS, real_walk, sim_walk

    real = None
    if realdata is not None and all((realdata / f).is_file() for f in REAL_WALKS):
        ms = [real_walk(realdata / f) for f in REAL_WALKS]
        real = {k: float(np.mean([m[k] for m in ms])) for k in MEASURES}
    rows = []
    if not walkers:
        return rows, real
    by_group: dict[str, list] = {}
    for k, (proto, group, gp) in enumerate(walkers):
        by_group.setdefault((proto, group), []).append(sim_walk(gp, seed=k))
    src = "real C3D walks FunctionalWalk, PiG FlatFoot, opensim_walking2 (gaitval.simulate.shin)"
    for (proto, group), ms in by_group.items():
        for key, check, rel in (("swing_peak_norm", "shin_swing_peak", SHIN_PEAK_REL),
                                ("stance_norm", "shin_stance_speed", SHIN_STANCE_REL)):
            v = float(np.mean([m[key] for m in ms]))
            r = real[key] if real else np.nan
            rows.append(_row(check, proto, v, r, r * (1 - rel) if real else None,
                             r * (1 + rel) if real else None, "× walking speed",
                             f"±{rel:.0%} of the real mean", src if real else
                             "real data absent: not checked", group=group,
                             note=f"{len(ms)} walkers, steady straight walks"))
    return rows, real


def step_rows_from_events(protocol: str, trials: list[tuple[pd.DataFrame, float]]
                          ) -> list[dict]:
    """The ``step_length`` and ``cadence`` rows of one protocol from its trials' true
    events: ``trials`` holds ``(events, body height in m)`` per trial (``events`` as in
    ``truth/<trial>/events.csv``; steps by :func:`_straight_steps`)."""
    sl, st = [], []
    for ev, height in trials:
        L, T = _straight_steps(ev, protocol)
        sl.append(L / float(height))
        st.append(T)
    sl = np.concatenate(sl) if sl else np.zeros(0)
    st = np.concatenate(st) if st else np.zeros(0)
    if not len(sl):
        return []
    group = GROUP_OF.get(protocol, "")
    rng = STEP_RANGES.get(group)
    rows = []
    for check, v, key, unit in (("step_length", float(np.mean(sl)), "step_per_height",
                                 "body heights"),
                                ("cadence", 60.0 / float(np.mean(st)), "cadence_per_min",
                                 "steps/min")):
        lo, hi = rng[key] if rng else (None, None)
        rows.append(_row(check, protocol, v, np.nan if lo is None else (lo + hi) / 2, lo, hi,
                         unit, "mean inside the published range" if rng else "not checked",
                         rng["source"] if rng else "no published range for this cohort",
                         group=group, note=f"{len(sl)} straight steps"))
    return rows


def _step_rows(study_dir: Path, trials: pd.DataFrame) -> list[dict]:
    subj = pd.read_csv(study_dir / "subjects.csv").set_index("subject")
    rows = []
    for proto, g in trials.groupby("protocol", sort=True):
        rows += step_rows_from_events(proto, [
            (pd.read_csv(study_dir / "truth" / tr["trial"] / "events.csv"),
             float(subj.loc[tr["subject"], "height_m"])) for _, tr in g.iterrows()])
    return rows

def _contact_rows(study_dir: Path, trials: pd.DataFrame, stats: dict) -> list[dict]:
    """Shank clearance per swing and overlapping scans, per protocol (issue 34)."""
    rows = []
    for proto, g in trials.groupby("protocol", sort=True):
        per_swing = np.concatenate([stats[t][0] for t in g["trial"]])
        n_close = sum(stats[t][1] for t in g["trial"])
        n_scans = sum(stats[t][2] for t in g["trial"])
        bad = int(np.sum(per_swing < SHANK_CLEARANCE_MIN))
        rows.append(_row("shank_clearance", proto,
                         float(per_swing.min()) if len(per_swing) else np.nan, 1.0,
                         SHANK_CLEARANCE_MIN, None, "leg widths",
                         f"≥ {SHANK_CLEARANCE_MIN} × leg width in every swing",
                         "physics: a swinging shank passes the standing one, it does not go "
                         "through it (issue 34)", group=GROUP_OF.get(proto, ""),
                         note=f"{bad} of {len(per_swing)} swings closer than "
                              f"{SHANK_CLEARANCE_MIN} leg widths; median closest "
                              f"{np.median(per_swing) if len(per_swing) else np.nan:.2f}"))
        rows.append(_row("shank_overlap_scans", proto, n_close / max(n_scans, 1), 0.0, None,
                         0.0, "fraction", "0 (no scan)",
                         "physics: two shanks never overlap (issue 34)",
                         group=GROUP_OF.get(proto, ""),
                         note=f"{n_close} of {n_scans} scans with shank centres closer than "
                              f"{SHANK_CLEARANCE_MIN} leg widths"))
    return rows


def contact_stats(study_dir: Path, trial: str) -> tuple[np.ndarray, int, int]:
    """One trial's contact statistics from its truth: per complete swing the closest
    shank-centre distance ÷ leg width (legs at sensor height, mocap rate), and the number
    of scans with the centres closer than :data:`SHANK_CLEARANCE_MIN` leg widths, of all
    scans inside the capture."""
    from gaitval.simulate.swings import swings

    d = Path(study_dir) / "truth" / trial
    tr = pd.read_csv(Path(study_dir) / "trials.csv").set_index("trial")
    subj = pd.read_csv(Path(study_dir) / "subjects.csv").set_index("subject")
    w = float(subj.loc[tr.loc[trial, "subject"], "leg_width_m"])
    legs = pd.read_parquet(d / "legs.parquet")
    ev = pd.read_csv(d / "events.csv")
    L = legs[legs["side"] == "L"].sort_values("t_s")
    R = legs[legs["side"] == "R"].sort_values("t_s")
    t = L["t_s"].to_numpy(float)
    dist = np.hypot(*(L[["x_m", "y_m"]].to_numpy(float) - R[["x_m", "y_m"]].to_numpy(float)).T)
    mins = []
    for side in ("L", "R"):
        for a, b in swings(ev, side):
            m = (t >= a) & (t <= b)
            if m.any():
                mins.append(float(dist[m].min()) / w)
    s = pd.read_parquet(d / "scans_legs.parquet")
    s = s[(s["t_mocap_s"] >= 0) & (s["t_mocap_s"] <= float(t.max()))]
    p = s.pivot_table(index="scan", columns="side", values=["x_m", "y_m"], aggfunc="first")
    ds = np.hypot(p[("x_m", "L")] - p[("x_m", "R")], p[("y_m", "L")] - p[("y_m", "R")])
    return np.array(mins), int(np.sum(ds.to_numpy(float) < SHANK_CLEARANCE_MIN * w)), len(ds)

def mtst_cross_row(events: list[pd.DataFrame]) -> dict:
    """The ``mtst_cross_steps`` row from the MTST trials' true events (``events.csv``):
    cross steps per 100 foot contacts."""
    n_cross = n_steps = 0
    for ev in events:
        n_cross += int((ev["event"] == "cross_step").sum())
        n_steps += int((ev["event"] == "foot_contact").sum())
    k, m = MTST_CROSS
    lo, hi = poisson_ci(k)
    return _row("mtst_cross_steps", "mtst", 100.0 * n_cross / max(n_steps, 1), 100.0 * k / m,
                100.0 * lo / m, 100.0 * hi / m, "per 100 steps",
                "inside the exact 95 % Poisson interval of 19 counts",
                "seed 001 Table 4: 19 cross steps of 414 steps", group="elderly",
                note=f"{n_cross} of {n_steps} steps (truth footfalls)")


def _mtst_rows(study_dir: Path, trials: pd.DataFrame) -> list[dict]:
    return [mtst_cross_row([pd.read_csv(study_dir / "truth" / t / "events.csv")
                            for t in trials["trial"]])]

def physics_table(study_dir: str | Path, walkers: list | None = None,
                  realdata: str | Path | None = None, map_fn=map) -> pd.DataFrame:
    """All checks of one simulated study (rows as in the module table).

    Parameters
    ----------
    study_dir : path
        A study written by :func:`gaitval.simulate.generate_study` (reads ``trials.csv``,
        ``subjects.csv`` and ``truth/``).
    walkers : list of (protocol, group, GaitParams), optional
        The study's participants, for the shin-speed rows (left out when None).
    realdata : path, optional
        Folder of the real C3D walks (default ``../shared/realdata/c3d`` beside the
        checkout); the shin rows show "not checked" when it is absent.
    map_fn : callable
        ``map``-like (results in order) for the per-trial swing statistics, e.g. a process
        pool's ``map`` (:func:`gaitval.simulate.generate_study` passes its own); same rows.

    Returns
    -------
    DataFrame
        Columns :data:`COLUMNS`; ``passed`` is True/False, NaN where nothing is checked.
    """
    d = Path(study_dir)
    if realdata is None:
        realdata = Path(__file__).resolve().parents[3] / "shared" / "realdata" / "c3d"
    realdata = Path(realdata)
    lrs = lrs_trials(d)
    tug = lrs[lrs["protocol"] == "tug"]
    mtst = lrs[lrs["protocol"] == "mtst"]
    # every group of rows and every trial's swing statistics is a task of ``map_fn``
    # (the simulation's process pool), the groups first (the longest); rows in this order
    names = list(lrs["trial"])
    tasks = [("shin", walkers, realdata if realdata.is_dir() else None),
             ("steps", d, lrs), ("tug_phase", d, tug), ("tug_path", d, tug),
             ("tug_sit", d, tug), ("mtst", d, mtst), ("treadmill", d), ("pendulum", d)] + \
        [("swing", d, t) for t in names] + [("contact", d, t) for t in names]
    out = list(map_fn(_physics_task, tasks))
    (shin_rows, real), steps, tug_phase, tug_path, tug_sit, mtst_rows, treadmill, pend = out[:8]
    stats = dict(zip(names, out[8:8 + len(names)]))
    contact = dict(zip(names, out[8 + len(names):]))
    rows = _swing_rows(d, lrs, real, stats) + _contact_rows(d, lrs, contact) + shin_rows + steps
    if len(tug):
        rows += tug_phase + tug_path + tug_sit
    if len(mtst):
        rows += mtst_rows
    rows += treadmill + pend
    return pd.DataFrame(rows, columns=COLUMNS)


def _physics_task(task: tuple):
    """One task of :func:`physics_table`: ``(kind, *arguments)``."""
    kind, *args = task
    if kind in ("tug_phase", "tug_path", "tug_sit", "mtst") and not len(args[1]):
        return []
    fn = {"shin": _shin_rows, "steps": _step_rows, "tug_phase": _tug_phase_rows,
          "tug_path": _tug_path_rows, "tug_sit": _tug_sit_rows, "mtst": _mtst_rows,
          "treadmill": _treadmill_rows, "pendulum": _pendulum_rows, "swing": swing_stats,
          "contact": contact_stats}[kind]
    return fn(*args)


def write_physics(study_dir: str | Path, walkers: list | None = None,
                  realdata: str | Path | None = None, map_fn=map) -> Path:
    """Write ``<study_dir>/physics.csv`` (:func:`physics_table`) and return its path."""
    out = Path(study_dir) / "physics.csv"
    write_csv(physics_table(study_dir, walkers, realdata, map_fn), out, float_format="%.6g")
    return out

