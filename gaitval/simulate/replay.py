"""Replay real kinematics: the laser log a scanner would have recorded of a real C3D walk.

Given a real C3D with knee and ankle information, the shank axis (ankle joint centre →
knee joint centre) is cut at the sensor height in every frame; the cross-section (an
ellipse sized from the configured leg width, stretched by the shank's tilt) is ray cast
by the same laser model as the simulated protocols.  The real markers are copied into a
new C3D together with two calibration pole markers, so the trial has *real* mocap as its
ground truth and a registration problem like any lab trial.

Joint centres, in order of preference per frame: PiG bone outputs ``LFEO/LTIO``,
explicit ``LKJC/LAJC``, the midpoint of lateral and medial condyle / malleolus markers
(``LLFC``+``LMFC``, ``LLMAL``+``LMMAL``; ``LKNE``+``LKNEin``, ``LANK``+``LANKin``), and
finally the lateral marker moved medially by half the knee / ankle width.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, GaitvalError, MarkerError
from gaitval.io.atomic import write_csv, write_parquet, write_text
from gaitval.io.c3d import read_c3d, write_c3d
from gaitval.io.scanlog import write_scanlog
from gaitval.simulate import render as RD
from gaitval.simulate.scene import ID_POLE
from gaitval.simulate.sheet import (SUBJECT_COLUMNS, TRIAL_COLUMNS, sensor_clock,
                                    summarise_realism)
from gaitval.simulate.trialsim import POLE_RADIUS_M, POLE_TOP_M, TrialSim, _walls

REPO_ROOT = Path(__file__).resolve().parents[2]
_NOT_A_MARKER = re.compile(r"(Angle|Force|Moment|Power|GRF|Gamage|Score|NM$|^#|CentreOfMass"
                           r"|HipCenter)")


@dataclass
class _Leg:
    ankle: np.ndarray
    knee: np.ndarray
    heading: np.ndarray
    tilt: np.ndarray

    def point_at_height(self, h):
        dz = self.knee[:, 2] - self.ankle[:, 2]
        u = (h - self.ankle[:, 2]) / np.where(np.abs(dz) < 1e-6, 1e-6, dz)
        return self.ankle[:, :2] + u[:, None] * (self.knee[:, :2] - self.ankle[:, :2])


def _interp_gaps(x: np.ndarray, t: np.ndarray, max_gap_s: float = 0.25) -> np.ndarray:
    """Linear interpolation over gaps shorter than ``max_gap_s`` (per column)."""
    x = x.copy()
    for c in range(x.shape[1]):
        ok = np.isfinite(x[:, c])
        if ok.sum() < 2:
            continue
        filled = np.interp(t, t[ok], x[ok, c])
        # leave long gaps and the ends empty
        prev = np.maximum.accumulate(np.where(ok, np.arange(len(t)), -1))
        nxt = np.minimum.accumulate(np.where(ok, np.arange(len(t)), len(t))[::-1])[::-1]
        inside = (prev >= 0) & (nxt < len(t))
        span = np.where(inside, t[np.clip(nxt, 0, len(t) - 1)] - t[np.clip(prev, 0, len(t) - 1)],
                        np.inf)
        fill = ~ok & inside & (span <= max_gap_s)
        x[fill, c] = filled[fill]
    return x


def joint_centres(m, side: str, knee_w: float, ankle_w: float) -> tuple[np.ndarray, np.ndarray]:
    """Knee and ankle joint centres (n, 3) of one side, combining the available sources."""
    n = m.n_frames

    def get(lab):
        return m.marker(lab) if m.has(lab) else np.full((n, 3), np.nan)

    def mid(a, b):
        return 0.5 * (get(a) + get(b))

    def medial_shift(lat, other_lat, w):
        # move the lateral marker half a joint width towards the other leg
        d = other_lat - lat
        d[:, 2] = 0
        nd = np.linalg.norm(d, axis=1, keepdims=True)
        return lat + (w / 2 + 0.007) * d / np.where(nd > 1e-6, nd, np.nan)

    o = "R" if side == "L" else "L"
    knee_src = [get(side + "FEO"), get(side + "KJC"), mid(side + "LFC", side + "MFC"),
                mid(side + "KNE", side + "KNEin"),
                medial_shift(get(side + "KNE"), get(o + "KNE"), knee_w)]
    ankle_src = [get(side + "TIO"), get(side + "AJC"), mid(side + "LMAL", side + "MMAL"),
                 mid(side + "ANK", side + "ANKin"),
                 medial_shift(get(side + "ANK"), get(o + "ANK"), ankle_w)]

    def first(srcs):
        out = np.full((n, 3), np.nan)
        for s in srcs:
            take = ~np.isfinite(out[:, 0]) & np.isfinite(s[:, 0])
            out[take] = s[take]
        return out
    return _interp_gaps(first(knee_src), m.t), _interp_gaps(first(ankle_src), m.t)


class ReplayWalker:
    """Real legs at arbitrary times (linear interpolation of the mocap frames)."""

    stick_side = None

    def __init__(self, t, knees, ankles, leg_width_m):
        self.t = t
        self.knees = knees          # (2, n, 3)
        self.ankles = ankles
        self.leg_width_m = leg_width_m
        mid = 0.5 * (ankles[0] + ankles[1])
        v = np.gradient(np.nan_to_num(mid[:, :2]), t, axis=0)
        k = max(1, int(0.5 / np.median(np.diff(t))))
        ker = np.ones(k) / k
        vs = np.column_stack([np.convolve(v[:, 0], ker, "same"), np.convolve(v[:, 1], ker, "same")])
        self.heading = np.unwrap(np.arctan2(vs[:, 1], vs[:, 0]))

    def _at(self, arr, t):
        return np.stack([np.interp(t, self.t, arr[:, c], left=np.nan, right=np.nan)
                         for c in range(arr.shape[1])], axis=1)

    def legs(self, t):
        out = []
        hd = np.interp(t, self.t, self.heading)
        for k in range(2):
            a = self._at(self.ankles[k], t)
            kn = self._at(self.knees[k], t)
            d = kn - a
            fwd = np.column_stack([np.cos(hd), np.sin(hd)])
            tilt = np.arctan2(np.sum(d[:, :2] * fwd, axis=1), d[:, 2])
            out.append(_Leg(a, kn, hd, tilt))
        return tuple(out)

    def shank_ellipses(self, t, height, legs=None):
        legs = self.legs(t) if legs is None else legs
        out = np.empty((len(t), 2, 5))
        for k, lg in enumerate(legs):
            out[:, k, 0:2] = lg.point_at_height(height)
            out[:, k, 2] = 0.95 * self.leg_width_m / 2 / np.cos(lg.tilt)
            out[:, k, 3] = self.leg_width_m / 2
            out[:, k, 4] = lg.heading
        return out


def replay_trial(out: Path, study: str, spec: dict, cfg: dict, seed: int, idx: int
                 ) -> tuple[dict, dict, dict, list]:
    """Write one replayed trial; returns (trial row, subject row, truth pose row, realism rows)."""
    src = Path(spec["file"])
    if not src.is_absolute():
        src = (REPO_ROOT / src).resolve()
    trial = str(spec["trial"])
    if not src.is_file():
        raise GaitvalError("real C3D for the replay study not found", path=src, trial=trial,
                           hint="the replay preset needs ../shared/realdata/ beside the "
                                "checkout; use the default or tiny preset otherwise")
    m = read_c3d(src)
    w = float(spec.get("leg_width_m", cfg.get("leg_width_m", 0.10)))
    kw, aw = 0.10, 0.07
    kL, aL = joint_centres(m, "L", kw, aw)
    kR, aR = joint_centres(m, "R", kw, aw)
    if np.isfinite(kL[:, 0]).mean() < 0.3 or np.isfinite(aL[:, 0]).mean() < 0.3:
        raise MarkerError("too few frames with knee and ankle positions to replay", path=src,
                          trial=trial, hint="needs LFEO/LTIO, LKJC/LAJC, condyle/malleolus "
                                            "or LKNE/LANK markers")
    t = m.t
    walker = ReplayWalker(t, np.stack([kL, kR]), np.stack([aL, aR]), w)
    rng = np.random.default_rng([seed, 21, idx])
    pose, poles, lo, hi = _place_sensor_and_poles(aL, aR, cfg, rng)
    h = float(cfg.get("sensor_height_m", 0.27))
    sim = TrialSim(study=study, protocol=str(cfg.get("protocol", "tug")), subject=str(spec["subject"]),
                   trial=trial, walker=walker, sensor=str(cfg.get("sensor", "utm30lx")),
                   sensor_height_m=h, mocap_rate_hz=m.rate_hz, t_end_s=float(t[-1]),
                   circles=np.array([(x, y, POLE_RADIUS_M, ID_POLE) for x, y in poles]),
                   walls=_walls(lo[0], hi[0], lo[1], hi[1]), poles=poles, fixed_pose=pose,
                   phase_fn=None, scenario="replay")
    clock = sensor_clock(rng, cfg.get("clock", {}))
    # the log is cut to the capture: no legs are known outside it
    series, scans, stats, _ = _render_window(sim, clock, rng, float(t[0]))
    mocap_rel, lrs_rel, legs = _write_replay_files(out, trial, m, walker, h, poles, series,
                                                   scans, rng)
    row = {"study": study, "protocol": sim.protocol, "subject": sim.subject, "trial": trial,
           "sensor_kind": "lrs", "mocap_file": mocap_rel, "sensor_file": lrs_rel,
           "sensor_topic": "", "annotation_file": "", "sensor_height_m": h,
           "clock_offset_s": np.nan, "speed": "", "speed_mps": np.nan, "stick": False,
           "scenario": "replay", "repetition": 1}
    subj = {"subject": sim.subject, "group": "adult", "age_y": np.nan, "sex": "",
            "height_m": np.nan, "mass_kg": np.nan, "leg_width_m": w, "knee_width_m": kw,
            "ankle_width_m": aw, "leg_length_m": np.nan, "shank_length_m": np.nan,
            "stick": False}
    pose_row = {"trial": trial, "x_m": pose[0], "y_m": pose[1], "yaw_rad": pose[2],
                "clock_offset_s": clock["clock_offset_s"],
                "clock_drift_ppm": clock["clock_drift_ppm"]}
    return row, subj, pose_row, _replay_realism(trial, legs, scans, stats)


def _place_sensor_and_poles(aL: np.ndarray, aR: np.ndarray, cfg: dict,
                            rng: np.random.Generator):
    """Sensor pose (x, y, yaw), pole positions (2, 2) and the room's corners (lo, hi).

    The walking line runs along the mid-ankle path; the sensor stands
    ``sensor_behind_m`` behind its start and ``sensor_side_m`` to its left, placed by hand
    (5 cm, 3° scatter drawn from ``rng``).
    """
    # walking line from the mid-ankle path: sensor behind the start, slightly to the side
    both = np.stack([aL, aR])[:, :, :2]
    cnt = np.isfinite(both[..., 0]).sum(axis=0)
    mid = np.where(cnt[:, None] > 0, np.nansum(both, axis=0) / np.maximum(cnt, 1)[:, None], np.nan)
    ok = np.isfinite(mid[:, 0])
    p0, p1 = mid[ok][0], mid[ok][-1]
    d = (p1 - p0) / np.linalg.norm(p1 - p0)
    left = np.array([-d[1], d[0]])
    back, side = cfg.get("sensor_behind_m", 1.0), cfg.get("sensor_side_m", -0.3)
    sx, sy = p0 - back * d + side * left
    yaw = float(np.arctan2(d[1], d[0]))
    pose = (float(sx + 0.05 * rng.standard_normal()), float(sy + 0.05 * rng.standard_normal()),
            float(yaw + np.deg2rad(3.0) * rng.standard_normal()))
    # Both poles on the same side of the walk: with one on each side the pole midpoint
    # sits on the walking line and the 180-degree pole swap maps the walk onto itself,
    # so no registration can tell the two transforms apart.  Both stand beside the start,
    # where the walker never passes between them and the sensor, at bearings far apart
    # (≈ 33° and ≈ 70° left of the walking line for the default sensor offset): a pole
    # beyond the end of the walk lines up behind the nearer one when the walk is short
    # (opensim_walking2: 1° apart) and its sight line crosses the walker's start position.
    poles = np.array([p0 + 1.0 * d + 1.0 * left, p0 - 0.5 * d + 1.5 * left])
    lo = np.minimum(p0, p1) - 2.5
    hi = np.maximum(p0, p1) + 2.5
    return pose, poles, lo, hi


def _write_replay_files(out: Path, trial: str, m, walker: ReplayWalker, h: float,
                        poles: np.ndarray, series, scans: pd.DataFrame,
                        rng: np.random.Generator) -> tuple[str, str, pd.DataFrame]:
    """Write the trial's C3D (real markers + two poles), scan log and truth.

    Returns the C3D and scan-log paths relative to ``out`` and the true leg points at
    sensor height (``t_s, side, x_m, y_m, phase``).
    """
    # markers: the real ones plus the two poles
    keep = [i for i, lab in enumerate(m.labels) if not _NOT_A_MARKER.search(lab)]
    labels = [m.labels[i] for i in keep] + ["POLE1", "POLE2"]
    poles_xyz = np.stack([np.tile([x, y, POLE_TOP_M], (m.n_frames, 1)) for x, y in poles], axis=1)
    poles_xyz = poles_xyz + 0.0003 * rng.standard_normal(poles_xyz.shape)
    xyz = np.concatenate([m.xyz[:, keep, :], poles_xyz], axis=1)
    mocap_rel = f"mocap/{trial}.c3d"
    lrs_rel = f"lrs/{trial}.scan.parquet"
    write_c3d(out / mocap_rel, labels, xyz, m.rate_hz, events=m.events if len(m.events) else None,
              first_frame=m.first_frame)
    write_scanlog(out / lrs_rel, series, scan_time_s=0.025)
    t = m.t
    rows = []
    for k, side in enumerate("LR"):
        c = walker.legs(t)[k].point_at_height(h)
        v = np.hypot(*np.gradient(c, t, axis=0).T)
        rows.append(pd.DataFrame({"t_s": t, "side": side, "x_m": c[:, 0], "y_m": c[:, 1],
                                  "phase": np.where(v < 0.3, "stance", "swing")}))
    legs = pd.concat(rows, ignore_index=True)
    tdir = out / "truth" / trial
    write_parquet(legs, tdir / "legs.parquet")
    write_parquet(scans, tdir / "scans_legs.parquet")
    ev = m.events.copy() if len(m.events) else pd.DataFrame(columns=["context", "label", "t_s"])
    write_csv(ev, tdir / "events.csv", float_format="%.5f")
    return mocap_rel, lrs_rel, legs


def _replay_realism(trial: str, legs: pd.DataFrame, scans: pd.DataFrame, stats: dict
                    ) -> list[dict]:
    """The trial's realism row (see :func:`gaitval.simulate.sheet.summarise_realism`)."""
    sp = RD.leg_speeds(legs.dropna())
    scans = scans[np.isfinite(scans["x_m"])]           # frames with a known leg only
    return [{"protocol": "replay", "phase": "all", "trial": trial, "leg_scans": len(scans),
             "occluded_leg_scans": int(scans["occluded"].sum()),
             "occluded_L": int(scans.loc[scans.side == "L", "occluded"].sum()),
             "occluded_R": int(scans.loc[scans.side == "R", "occluded"].sum()),
             "beams": stats["n_beams_total"], "returns": stats["n_returns"],
             "mixed": stats["n_mixed"], "dropouts": stats["n_dropout"],
             "stance_speed_mps": sp["stance_speed_mps"], "swing_speed_mps": sp["swing_speed_mps"],
             "swing_peak_mps": sp["swing_peak_mps"], "walking_speed_mps": np.nan,
             "steps": np.nan, "cross_steps": np.nan}]


def _render_window(sim: TrialSim, clock: dict, rng, t0: float):
    """Like :func:`render.render_laser` but only for scans inside the capture [t0, t_end]."""
    saved = sim.t_end_s
    series, scans, stats, poses = RD.render_laser(sim, clock, rng)
    keep = (scans["t_mocap_s"] >= t0) & (scans["t_mocap_s"] <= saved)
    idx = np.unique(scans.loc[keep, "scan"].to_numpy())
    series.t = series.t[idx]
    series.ranges = series.ranges[idx]
    scans = scans[keep].copy()
    scans["scan"] = np.searchsorted(idx, scans["scan"].to_numpy())
    scans = scans.reset_index(drop=True)
    return series, scans, stats, poses[idx]


def generate_replay_study(out_dir: Path, cfg: dict, seed: int | None = None) -> Path:
    """Write the replay study described by ``cfg["replay"]`` (see ``config/studies/replay.yaml``)."""
    rcfg = dict(cfg["replay"])
    trials_cfg = rcfg.get("trials") or []
    if not trials_cfg:
        raise ConfigError("the replay preset lists no trials (replay.trials)")
    seed = int(cfg.get("seed", 0) if seed is None else seed)
    study = str(cfg.get("study", "replay"))
    for c in ("clock",):
        if c in cfg and c not in rcfg:
            rcfg[c] = cfg[c]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows, subs, poses, realism = [], {}, [], []
    for i, spec in enumerate(trials_cfg, start=1):
        row, subj, pose, real = replay_trial(out, study, spec, rcfg, seed, i)
        rows.append(row)
        subs.setdefault(subj["subject"], subj)
        poses.append(pose)
        realism += real
    write_csv(pd.DataFrame(rows, columns=TRIAL_COLUMNS), out / "trials.csv")
    write_csv(pd.DataFrame(list(subs.values()), columns=SUBJECT_COLUMNS), out / "subjects.csv")
    write_csv(pd.DataFrame(poses), out / "truth" / "sensor_pose.csv", float_format="%.9g")
    write_csv(summarise_realism(realism), out / "realism.csv", float_format="%.6g")
    write_text(out / "study.yaml", f"study: {study}\nseed: {seed}\nregistration:\n"
                                   f"  pole_diameter_m: {2 * POLE_RADIUS_M}\n")
    return out / "trials.csv"
