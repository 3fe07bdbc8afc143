"""The TUG rows of ``physics.csv`` (:mod:`gaitval.simulate.physics`, whose module table
describes each check): phase durations and occlusion per phase (with what hides each
occluded leg-scan), the path around the marker, and the turn to sit."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.simulate.physics_rows import _row, _straight_steps

#: seed 000 Table 4, Method 2: leg-scans per TUG phase over 25 trials (40 Hz, 2 legs).
TUG_PHASE_LEG_SCANS = {"forward": 6364, "turning": 2264, "return": 6686}
TUG_PHASE_REL = 0.25
#: seed 000 Table 4, Method 2: occluded / all leg-scans per phase.
TUG_OCCLUSION = {"forward": (225, 6364), "turning": (255, 2264), "return": (344, 6686)}
OCCLUSION_FACTOR = 1.5
#: Final 180° turn (turn to sit) of the instrumented TUG, healthy controls: mean, SD (s).
TURN_TO_SIT_S = (1.7, 0.5)
RETURN_OFFSET_MAX_M = 0.25
#: Issue 34, the turn at the marker (stated before the sourced turn model was written or
#: simulated): the mean step time of the turning steps (path label ``turning``) ÷ the mean
#: step time of the same trials' straight outbound steps.  Reference 1.0: on curved paths
#: the stepping rate stays that of straight walking and speed changes through the step
#: length (Grasso, Glasauer, Takei, Berthoz, doi:10.1201/9780203735701-41; Madrid et al.
#: 2024, young adults turning
#: 90 / 180 / 360°: cadence a "pace gait constant").  Pass: within ±10 % (the young
#: walkers' step-time CV is 2.5 %, four turning steps per trial).
TURN_STEP_TIME_REL = 0.10
#: Issue 34: feet back at hip width when seated: the end's shank-centre distance within
#: this of the start's (m), worst trial.
SIT_SEPARATION_TOL_M = 0.05


def step_label_bounds(ev: pd.DataFrame) -> tuple[float, float]:
    """The TUG turn by the twin's step labels (the phase rule before issue 34): lift-off
    of the first step labelled ``turning`` and the first contact labelled ``return``."""
    c = ev[ev["event"] == "foot_contact"].sort_values("t_s")
    lab = c["label"].astype(str)
    first = c[lab == "turning"].iloc[0]
    offs = ev[(ev["event"] == "foot_off") & (ev["side"] == first["side"])
              & (ev["t_s"] < first["t_s"])]["t_s"]
    return float(offs.max()), float(c[lab == "return"]["t_s"].iloc[0])


def occluders(scans: pd.DataFrame, pose, leg_width_m: float, circles: np.ndarray
              ) -> pd.DataFrame:
    """What stands between the sensor and each occluded leg-scan of a fixed-sensor trial.

    Geometry only, from the truth: a leg (a circle of ``leg_width_m`` about its true
    centre) is screened by an object when the object is nearer to the sensor and the two
    angular extents, seen from the sensor, overlap.  Objects: the other leg of the same
    scan and the scene's static ``circles`` (``x, y, radius, id`` in the field frame, e.g.
    :func:`gaitval.simulate.tug.scene_circles`), brought into the sensor frame by the fixed
    sensor's ``pose`` (``x, y, yaw`` in the field).

    Parameters
    ----------
    scans : DataFrame
        ``truth/<trial>/scans_legs.parquet`` rows (``scan, side, x_m, y_m`` sensor frame,
        ``occluded``, ``phase``).

    Returns
    -------
    DataFrame
        One row per occluded leg-scan: ``scan, side, phase``, ``by_leg`` (the other leg is
        on the line of sight) and one bool column per scene object kind
        (:data:`gaitval.simulate.scene.ID_NAMES`, e.g. ``by_turn_marker``).  A leg-scan
        may have several screens, or none (a sliver left by mixed pixels and dropouts).
    """
    from gaitval.simulate.scene import ID_NAMES

    x0, y0, yaw = (float(v) for v in pose)
    c, s_ = np.cos(yaw), np.sin(yaw)
    kinds = sorted({ID_NAMES[int(k)] for k in np.asarray(circles)[:, 3]}) if len(circles) else []
    occ = scans[scans["occluded"].astype(bool)]
    mate = scans[["scan", "side", "x_m", "y_m"]].assign(
        side=lambda f: np.where(f["side"] == "L", "R", "L"))
    pair = occ[["scan", "side"]].merge(mate, on=["scan", "side"], how="left")
    ox, oy = pair["x_m"].to_numpy(float), pair["y_m"].to_numpy(float)
    x, y = occ["x_m"].to_numpy(float), occ["y_m"].to_numpy(float)
    rho, ang = np.hypot(x, y), np.arctan2(y, x)
    half = np.arcsin(np.clip(leg_width_m / 2 / rho, 0, 1))

    def screens(px, py, rad):
        r = np.hypot(px, py)
        d = np.angle(np.exp(1j * (np.arctan2(py, px) - ang)))
        return (r < rho) & (np.abs(d) < half + np.arcsin(np.clip(rad / r, 0, 1)))

    out = pd.DataFrame({"scan": occ["scan"].to_numpy(), "side": occ["side"].to_numpy(),
                        "phase": occ["phase"].to_numpy(),
                        "by_leg": screens(ox, oy, leg_width_m / 2)})
    for kind in kinds:
        hit = np.zeros(len(occ), bool)
        for cx, cy, rad, oid in np.asarray(circles, float):
            if ID_NAMES[int(oid)] != kind:
                continue
            dx, dy = cx - x0, cy - y0
            hit |= screens(c * dx + s_ * dy, -s_ * dx + c * dy, rad)
        out["by_" + kind] = hit
    return out


def tug_span(ev: pd.DataFrame, t_end: float) -> tuple[float, float]:
    """The TUG itself in a trial's mocap time: from the start of the rise to seated (the
    truth events' ``phase_start`` of ``forward`` and the ``seated`` after it; a study
    written before they existed: the whole capture, 0 to ``t_end``)."""
    p = ev[ev["event"] == "phase_start"]
    fwd = p.loc[p["label"].astype(str) == "forward", "t_s"]
    t0 = float(fwd.iloc[0]) if len(fwd) else 0.0
    after = p.loc[(p["label"].astype(str) == "seated") & (p["t_s"] > t0), "t_s"]
    return t0, float(after.iloc[0]) if len(after) else float(t_end)


def tug_timeline(ev: pd.DataFrame, phase_of_scans: pd.DataFrame, t_end: float) -> dict:
    """Where a TUG trial's seconds go (s), in the TUG's span (:func:`tug_span`): the
    forward phase split into rising (until the first lift-off) and walking; the return
    phase (from the end of the turning phase, the truth ``phase`` column) into the walk
    back (to the last contact labelled ``return``), the turn to sit (to the last pivot
    contact, where the descent begins: :func:`gaitval.simulate.tug.build_tug`) and the
    sitting down; and the capture's still-seated spans before the rise and after
    sitting."""
    c = ev[ev["event"] == "foot_contact"].sort_values("t_s")
    lab = c["label"].astype(str).to_numpy()
    tc = c["t_s"].to_numpy(float)
    t_rise, t_seated = tug_span(ev, t_end)
    t_off = float(ev.loc[ev["event"] == "foot_off", "t_s"].min())
    tm = phase_of_scans.drop_duplicates("scan")
    turn = tm.loc[tm["phase"] == "turning", "t_mocap_s"]
    t0, t1 = float(turn.min()), float(turn.max())
    last_ret = float(tc[lab == "return"][-1])
    last_pivot = float(tc[lab == "turn_to_sit"][-2])
    return {"rising": t_off - t_rise, "walk_out": t0 - t_off, "walk_back": last_ret - t1,
            "turn_to_sit": last_pivot - last_ret, "sitting_down": t_seated - last_pivot,
            "seated_before": t_rise, "seated_after": t_end - t_seated}


def tug_scene_circles(study_dir: str | Path) -> np.ndarray:
    """The TUG scene's static circles ``(k, 4)``: ``x, y, radius, id`` (field frame) of a
    simulated study, from its ``truth/tug_scene.csv``; a study written before that file
    existed had the default scene (:func:`gaitval.simulate.tug.scene_circles`)."""
    from gaitval.simulate.tug import scene_circles

    f = Path(study_dir) / "truth" / "tug_scene.csv"
    if not f.is_file():
        return scene_circles()
    t = pd.read_csv(f)
    return t[["x_m", "y_m", "radius_m", "object_id"]].to_numpy(float)


def _tug_phase_rows(study_dir: Path, trials: pd.DataFrame) -> list[dict]:
    durations = {ph: [] for ph in TUG_PHASE_LEG_SCANS}
    occ = {ph: [0, 0] for ph in TUG_PHASE_LEG_SCANS}
    by_steps = {ph: [] for ph in TUG_PHASE_LEG_SCANS}
    capture = {ph: [0, 0, 0] for ph in TUG_PHASE_LEG_SCANS}     # the definition before
    screens = []
    timeline = []
    subj = pd.read_csv(study_dir / "subjects.csv").set_index("subject")
    poses = pd.read_csv(study_dir / "truth" / "sensor_pose.csv").set_index("trial")
    circles = tug_scene_circles(study_dir)
    for _, tr in trials.iterrows():
        t = tr["trial"]
        ev = pd.read_csv(study_dir / "truth" / t / "events.csv")
        a, b = step_label_bounds(ev)
        s = pd.read_parquet(study_dir / "truth" / t / "scans_legs.parquet")
        t_end = float(pd.read_parquet(study_dir / "truth" / t / "legs.parquet")["t_s"].max())
        s = s[(s["t_mocap_s"] >= 0) & (s["t_mocap_s"] <= t_end)]
        dt = float(np.median(np.diff(np.unique(s["t_mocap_s"]))))
        t_rise, t_seated = tug_span(ev, t_end)
        tm = s.drop_duplicates("scan")["t_mocap_s"].to_numpy(float)
        tm = tm[(tm >= t_rise) & (tm <= t_seated)]
        for ph, m in (("forward", tm < a), ("turning", (tm >= a) & (tm < b)),
                      ("return", tm >= b)):
            by_steps[ph].append(int(m.sum()) * dt)
        for ph in durations:
            e = s[s["phase"] == ph]
            durations[ph].append(e["scan"].nunique() * dt)
            occ[ph][0] += int(e["occluded"].sum())
            occ[ph][1] += len(e)
        # over the whole capture, the still-seated spans counted with the next / last
        # phase (the rows' definition before; in the notes)
        seated = s["phase"].astype(str) == "seated"
        cap = s["phase"].astype(str).where(~seated, np.where(s["t_mocap_s"] < t_rise,
                                                             "forward", "return"))
        for ph in capture:
            e = s[cap == ph]
            capture[ph][0] += e["scan"].nunique() * dt
            capture[ph][1] += int(e["occluded"].sum())
            capture[ph][2] += len(e)
        screens.append(occluders(s, poses.loc[t, ["x_m", "y_m", "yaw_rad"]].to_numpy(float),
                                 float(subj.loc[tr["subject"], "leg_width_m"]), circles))
        timeline.append(tug_timeline(ev, s, t_end))
    screens = pd.concat(screens, ignore_index=True)
    tl = pd.DataFrame(timeline).mean()
    n_tr = max(len(trials), 1)
    split = {"forward": f"rising {tl['rising']:.2f} s + walking {tl['walk_out']:.2f} s",
             "turning": "",
             "return": f"walk back {tl['walk_back']:.2f} s + turn to sit (pivot steps) "
                       f"{tl['turn_to_sit']:.2f} s + sitting down {tl['sitting_down']:.2f} s"}
    seated = {"forward": f"; seated before the rise {tl['seated_before']:.2f} s (not counted)",
              "turning": "",
              "return": f"; seated at the end {tl['seated_after']:.2f} s (not counted)"}
    rows = []
    src4 = "seed 000 Table 4, Method 2 (25 trials)"
    for ph, n in TUG_PHASE_LEG_SCANS.items():
        ref = n / 25 / 2 / 40.0
        rows.append(_row("tug_phase_duration", "tug", float(np.mean(durations[ph])), ref,
                         ref * (1 - TUG_PHASE_REL), ref * (1 + TUG_PHASE_REL), "s/trial",
                         f"±{TUG_PHASE_REL:.0%}", src4 + ": leg-scans / 25 / 2 / 40 Hz",
                         group="young", phase=ph,
                         note="phases of the TUG from the start of the rise to seated, "
                              "turning while the walking direction is > 30° off the line "
                              "(the rule of the reproduced Table 4, on the true legs); by "
                              f"the twin's step labels {np.mean(by_steps[ph]):.3f} s; over "
                              f"the whole capture {capture[ph][0] / n_tr:.3f} s"
                              + (f"; mean split: {split[ph]}" if split[ph] else "")
                              + seated[ph]))
        k, m = TUG_OCCLUSION[ph]
        ref = k / m
        e = screens[screens["phase"] == ph]
        marker = e.get("by_turn_marker", pd.Series(False, index=e.index))
        rows.append(_row("tug_occlusion", "tug", occ[ph][0] / max(occ[ph][1], 1), ref,
                         ref / OCCLUSION_FACTOR, ref * OCCLUSION_FACTOR, "fraction",
                         f"ratio within 1/{OCCLUSION_FACTOR}–{OCCLUSION_FACTOR}",
                         src4 + f": {k}/{m}", group="young", phase=ph,
                         note="twin: fewer than 3 returning beams on the leg (truth); paper: "
                              "the tracker's unobservable pattern; on the line of sight of "
                              f"the {len(e)} occluded leg-scans: the turn marker "
                              f"{int(marker.sum())}, the other leg only "
                              f"{int((e['by_leg'] & ~marker).sum())}, neither "
                              f"{int((~e['by_leg'] & ~marker).sum())}; over the whole "
                              f"capture {capture[ph][1] / max(capture[ph][2], 1):.4f}"))
    return rows


def _tug_path_rows(study_dir: Path, trials: pd.DataFrame) -> list[dict]:
    """Turn around the marker, return to the chair and turn to sit, from the truth."""
    from gaitval.simulate.tug import MARKER_RADIUS_M, TUG_MARKER_XY

    subj = pd.read_csv(study_dir / "subjects.csv").set_index("subject")
    mk = np.asarray(TUG_MARKER_XY, float)
    tts, offs, clear, radii, turn_T, straight_T = [], [], [], [], [], []
    for _, tr in trials.iterrows():
        d = study_dir / "truth" / tr["trial"]
        ev = pd.read_csv(d / "events.csv")
        c = ev[ev["event"] == "foot_contact"].sort_values("t_s")
        lab = c["label"].astype(str).to_numpy()
        p = c[["x_m", "y_m"]].to_numpy(float)
        ret = np.flatnonzero(lab == "return")
        if (lab == "turn_to_sit").any() and len(ret) >= 2:
            tts.append(float(c["t_s"].iloc[-1] - c["t_s"].iloc[ret[-1]]))
            offs.append(abs(float(0.5 * (p[ret[-1], 1] + p[ret[-2], 1]))))
        turn = np.flatnonzero(lab == "turning")
        if len(turn) >= 2:
            radii.append(float(np.mean(np.hypot(*(p[turn] - mk).T))))
        # the whole trial (since issue 34; before, the turning phase only): the legs come
        # near the marker only while going around it
        legs = pd.read_parquet(d / "legs.parquet")
        dist = np.hypot(*(legs[["x_m", "y_m"]].to_numpy(float) - mk).T)
        w = float(subj.loc[tr["subject"], "leg_width_m"])
        clear.append(float(dist.min()) - MARKER_RADIUS_M - w / 2)
        tc = c["t_s"].to_numpy(float)
        k = turn[turn >= 1]
        turn_T.append(tc[k] - tc[k - 1])
        straight_T.append(_straight_steps(ev, "tug")[1])
    mu, sd = TURN_TO_SIT_S
    src = "Aging Clin Exp Res 2020;33:1853, Table 3 (healthy controls, final 180° turn)"
    rows = [
        _row("tug_turn_to_sit", "tug", float(np.mean(tts)) if tts else np.nan, mu,
             mu - 2 * sd, mu + 2 * sd, "s", "inside mean ± 2 SD", src, group="young",
             note="last return-line contact to the last contact before sitting"),
        _row("tug_return_to_chair", "tug", float(np.max(offs)) if offs else np.nan, 0.0,
             None, RETURN_OFFSET_MAX_M, "m", f"≤ {RETURN_OFFSET_MAX_M} m (worst trial)",
             "seed 000 §1: walks back to the chair (out and back); Podsiadlo & Richardson "
             "1991", group="young", note="feet midpoint off the chair axis at the turn to sit"),
        _row("tug_marker_clearance", "tug", float(np.min(clear)) if clear else np.nan, 0.0,
             0.0, None, "m", "> 0 (worst trial)", "physics: the legs go around the marker",
             group="young", note="shank surface to the marker's footprint at shin height "
                                 "(0.06 m radius, what the path goes around)"),
        _row("tug_turn_radius", "tug", float(np.mean(radii)) if radii else np.nan, np.nan,
             None, None, "m", "no published value", "docs/simulator.md (choice of the "
             "path)", group="young", note="mean distance of the turning footholds from the "
                                          "marker (inner and outer feet)"),
    ]
    tT = np.concatenate(turn_T) if turn_T else np.zeros(0)
    sT = np.concatenate(straight_T) if straight_T else np.zeros(0)
    if len(tT) and len(sT):
        rows.append(_row("tug_turn_step_time", "tug", float(np.mean(tT) / np.mean(sT)), 1.0,
                         1 - TURN_STEP_TIME_REL, 1 + TURN_STEP_TIME_REL, "× straight step time",
                         f"±{TURN_STEP_TIME_REL:.0%}",
                         "curved walking keeps the straight stepping rate (Grasso et al.; "
                         "Madrid et al. 2024, Front Hum Neurosci 18:1269772)", group="young",
                         note=f"{len(tT)} turning steps {np.mean(tT):.3f} s, {len(sT)} "
                              f"straight steps {np.mean(sT):.3f} s"))
    return rows


def _tug_sit_rows(study_dir: Path, trials: pd.DataFrame) -> list[dict]:
    """Feet back at hip width when seated, and no cross step in the turn to sit (issue 34)."""
    seps, n_cross, n_tts = [], 0, 0
    for t in trials["trial"]:
        d = study_dir / "truth" / t
        legs = pd.read_parquet(d / "legs.parquet")
        first = legs[legs["t_s"] == legs["t_s"].min()].set_index("side")
        last = legs[legs["t_s"] == legs["t_s"].max()].set_index("side")
        sep = lambda f: float(np.hypot(f.loc["L", "x_m"] - f.loc["R", "x_m"],
                                       f.loc["L", "y_m"] - f.loc["R", "y_m"]))
        seps.append((sep(first), sep(last)))
        ev = pd.read_csv(d / "events.csv")
        c = ev[(ev["event"] == "foot_contact") & (ev["label"].astype(str) == "turn_to_sit")]
        x = ev[ev["event"] == "cross_step"]
        n_tts += len(c)
        n_cross += int(np.isin(np.round(x["t_s"].to_numpy(float), 5),
                               np.round(c["t_s"].to_numpy(float), 5)).sum())
    seps = np.array(seps) if seps else np.zeros((0, 2))
    worst = float(np.max(np.abs(seps[:, 1] - seps[:, 0]))) if len(seps) else np.nan
    return [
        _row("tug_sit_foot_separation", "tug", worst, 0.0, None, SIT_SEPARATION_TOL_M, "m",
             f"≤ {SIT_SEPARATION_TOL_M} m (worst trial)",
             "seated at the end as at the start: feet at hip width (issue 34)", group="young",
             note=f"shank-centre distance seated at the start {seps[:, 0].mean():.3f} m, at "
                  f"the end {seps[:, 1].mean():.3f} m (means over {len(seps)} trials)"),
        _row("tug_turn_to_sit_cross", "tug", n_cross, 0, None, 0, "steps", "0",
             "people pivot to sit without crossing the legs (issue 34)", group="young",
             note=f"{n_cross} cross steps of {n_tts} turn-to-sit steps"),
    ]
