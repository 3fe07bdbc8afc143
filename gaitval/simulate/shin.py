"""Shin-height leg speed profile of real and simulated walks, measured the same way.

The trackers see the shank where the scan plane cuts it (0.27 m in seeds 000/001).  This
module measures how that point moves, identically for real C3D walks and for the
simulator's kinematics, so the two can be compared (``docs/simulator.md``, "Shin speed"):

1. knee and ankle joint centres (``gaitval.groundtruth.joints.joint_centre``: PiG bone
   outputs ``LFEO/LTIO`` or explicit ``LKJC/LAJC``), leg point on the ankle→knee axis at
   height ``h`` (``gaitval.groundtruth.shank.point_at_height``);
2. 2nd-order 10 Hz zero-phase Butterworth low-pass (``gaitval.groundtruth.filters``,
   seed 003 §4.1), central differences → horizontal speed per frame;
3. everything divided by the walk's mean walking speed ``v`` (pelvis progression for
   real walks, foothold progression for simulated ones), accelerations by ``v / T``
   (``T`` = stride time), so walks at different speeds compare.

Stance/swing come from the C3D foot strike/off events, or (no events, e.g.
``opensim_walking2.c3d``) from heel/toe marker heights (contact: heel marker within
2 cm of its lowest height and descending; off: toe marker above its lowest + 2 cm).

Run ``python -m gaitval.simulate.shin [realdata/c3d folder]`` for the table.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from gaitval.groundtruth.filters import differentiate, lowpass
from gaitval.groundtruth.shank import point_at_height

REAL_WALKS = ("FunctionalWalk.c3d", "PiG_Motion-FlatFoot-Full.c3d", "opensim_walking2.c3d")
SCAN_HEIGHT_M = 0.27
MEASURES = ("v_walk_mps", "stride_s", "stance_norm", "swing_norm", "swing_peak_norm",
            "p95_norm", "p99_norm", "max_norm", "decel_mps2", "decel_norm",
            "shank_range_deg", "shank_omega_dps", "shank_omega_norm", "swing_fwd_min_mps")


def _phase_intervals(contacts: np.ndarray, offs: np.ndarray) -> list[tuple[float, float]]:
    """Swing intervals (t_off, next contact) from sorted contact and off times."""
    out = []
    for to in np.sort(offs):
        nxt = contacts[contacts > to]
        if len(nxt):
            out.append((float(to), float(nxt[0])))
    return out


def profile(t: np.ndarray, knee: np.ndarray, ankle: np.ndarray, swings: list, v_walk: float,
            fwd: np.ndarray, rate_hz: float, h: float = SCAN_HEIGHT_M, stride_s: float = 1.0
            ) -> dict:
    """Shin-height measures of one leg.

    Parameters
    ----------
    t : (n,) seconds; knee, ankle : (n, 3) joint centres (metres, NaN in gaps)
    swings : list of (t_off, t_contact) swing intervals of this leg
    v_walk : mean walking speed (m/s); fwd : (2,) unit walking direction
    rate_hz : frame rate; h : scan height; stride_s : stride time ``T``

    Returns
    -------
    dict of arrays: ``v`` (speed per frame), ``swing`` mask, per-stride ``peak`` and
    ``decel`` (largest speed drop rate in the 0.15 s around contact), per-swing ``fwd_min``
    (:func:`point_profile`), shank angle ``theta`` (sagittal, knee ahead positive,
    degrees) and ``omega`` (deg/s).
    """
    knee = lowpass(knee, rate_hz)
    ankle = lowpass(ankle, rate_hz)
    p, ok = point_at_height(knee, ankle, h)
    out = _point_measures(t, p[:, :2], ok, swings, stride_s)
    d = knee - ankle
    theta = np.degrees(np.arctan2(d[:, :2] @ fwd, d[:, 2]))
    omega = differentiate(theta, t)
    keep = out.pop("_keep")
    out.update(theta=theta[keep], omega=omega[keep])
    return out


def point_profile(t: np.ndarray, xy: np.ndarray, swings: list, rate_hz: float,
                  stride_s: float = 1.0) -> dict:
    """Shin-height measures of one leg from its point at sensor height (a simulated
    study's ``truth/<trial>/legs.parquet``), low-passed like :func:`profile`.

    Returns the keys of :func:`profile` except the shank angles.  ``fwd_min`` holds, per
    complete swing, the lowest speed of the point along the swing's own direction (the
    chord from its position at foot off to its position at contact; m/s): negative when
    the swinging shin moves backwards.  Swings whose point travels less than 5 cm have no
    direction and are left out.
    """
    xy = lowpass(np.asarray(xy, dtype=float), rate_hz)
    ok = np.isfinite(xy).all(axis=1)
    out = _point_measures(t, xy, ok, swings, stride_s)
    out.pop("_keep")
    return out


def _point_measures(t, p2, ok, swings, stride_s) -> dict:
    """Speeds, swing mask, per-stride peak / contact deceleration / forward minimum."""
    v2 = differentiate(p2, t)
    v = np.hypot(v2[:, 0], v2[:, 1])
    dv = differentiate(v, t)
    swing = np.zeros(len(t), dtype=bool)
    peaks, decs, fmins = [], [], []
    for a, b in swings:
        m = (t >= a) & (t < b)
        swing |= m
        full = (a > t[0]) and (b < t[-1]) and np.isfinite(v[m]).all()
        if full and m.any():
            peaks.append(np.nanmax(v[m]))
            w = (t >= b - 0.15) & (t <= b + 0.05)
            decs.append(-np.nanmin(dv[w]))
            i = np.flatnonzero(m)
            chord = p2[i[-1]] - p2[i[0]]
            dist = float(np.hypot(*chord))
            if dist >= 0.05:
                fmins.append(float(np.nanmin(v2[i] @ (chord / dist))))
    # frames between the first and last event are classified; the rest is unknown
    known = np.zeros(len(t), dtype=bool)
    if swings:
        known = (t >= min(a for a, _ in swings) - 0.6 * stride_s) & (t <= max(b for _, b in swings)
                                                                        + 0.6 * stride_s)
    keep = ok & np.isfinite(v) & known
    return {"v": v[keep], "swing": swing[keep], "peak": np.array(peaks), "decel": np.array(decs),
            "fwd_min": np.array(fmins), "_keep": keep}


def summarise(legs: list[dict], v_walk: float, stride_s: float) -> dict:
    """Pool the legs of one walk into the normalised measures (:data:`MEASURES`)."""
    v = np.concatenate([g["v"] for g in legs])
    sw = np.concatenate([g["swing"] for g in legs])
    pk = np.concatenate([g["peak"] for g in legs])
    dc = np.concatenate([g["decel"] for g in legs])
    fm = np.concatenate([g["fwd_min"] for g in legs])
    rng_deg = np.mean([np.ptp(g["theta"]) for g in legs if len(g["theta"])])
    om = max(np.nanmax(np.abs(g["omega"])) for g in legs if len(g["omega"]))
    a_ref = v_walk / stride_s
    return {"v_walk_mps": v_walk, "stride_s": stride_s,
            "stance_norm": float(np.mean(v[~sw])) / v_walk,
            "swing_norm": float(np.mean(v[sw])) / v_walk,
            "swing_peak_norm": float(np.mean(pk)) / v_walk if len(pk) else np.nan,
            "p95_norm": float(np.percentile(v[sw], 95)) / v_walk,
            "p99_norm": float(np.percentile(v[sw], 99)) / v_walk,
            "max_norm": float(np.max(v[sw])) / v_walk,
            "decel_mps2": float(np.mean(dc)) if len(dc) else np.nan,
            "decel_norm": float(np.mean(dc)) / a_ref if len(dc) else np.nan,
            "shank_range_deg": float(rng_deg), "shank_omega_dps": float(om),
            "shank_omega_norm": float(om) * stride_s / 360.0,
            "swing_fwd_min_mps": float(np.min(fm)) if len(fm) else np.nan}


def _marker_events(mocap, side: str, heel: str, toe: str) -> tuple[np.ndarray, np.ndarray]:
    """Foot contact / off times from heel and toe marker heights (no C3D events)."""
    t = mocap.t
    zh = lowpass(mocap.marker(side + heel)[:, 2], mocap.rate_hz)
    zt = lowpass(mocap.marker(side + toe)[:, 2], mocap.rate_hz)
    hc = (zh < np.nanmin(zh) + 0.02)
    tc = (zt < np.nanmin(zt) + 0.02)
    con = t[1:][hc[1:] & ~hc[:-1] & np.isfinite(zh[:-1])]
    off = t[1:][~tc[1:] & tc[:-1] & np.isfinite(zt[1:])]
    return con, off


def real_walk(path, h: float = SCAN_HEIGHT_M) -> dict:
    """Measures (:func:`summarise`) of one real C3D walk (both legs pooled)."""
    from gaitval.groundtruth.joints import joint_centre
    from gaitval.io.c3d import read_c3d

    m = read_c3d(path)
    t = m.t
    pel = [lb for lb in ("SACR", "LPSI", "RPSI", "LASI", "RASI")
           if m.has(lb) and np.isfinite(m.marker(lb)).all(axis=1).any()]
    stack = np.stack([m.marker(lb) for lb in pel])
    cnt = np.isfinite(stack).sum(axis=0)
    P = np.where(cnt > 0, np.nansum(stack, axis=0) / np.maximum(cnt, 1), np.nan)
    knees = {s: joint_centre(m, s, "knee")[0] for s in "LR"}
    ankles = {s: joint_centre(m, s, "ankle")[0] for s in "LR"}
    both = np.all(np.isfinite(np.concatenate([knees["L"], knees["R"], P], axis=1)), axis=1)
    idx = np.flatnonzero(both)
    i0, i1 = idx[0], idx[-1]
    v_walk = float(np.hypot(*(P[i1, :2] - P[i0, :2])) / (t[i1] - t[i0]))
    fwd = (P[i1, :2] - P[i0, :2]) / np.hypot(*(P[i1, :2] - P[i0, :2]))
    ev = m.events
    legs, strides = [], []
    for s, ctx in (("L", "Left"), ("R", "Right")):
        if ev is not None and len(ev) and (ev["context"] == ctx).any():
            e = ev[ev["context"] == ctx]
            con = np.sort(e.loc[e["label"] == "Foot Strike", "t_s"].to_numpy(float))
            off = np.sort(e.loc[e["label"] == "Foot Off", "t_s"].to_numpy(float))
        else:
            heel, toe = ("CAL", "MT2") if m.has(s + "CAL") else ("HEE", "TOE")
            con, off = _marker_events(m, s, heel, toe)
        if len(con) > 1:
            strides += list(np.diff(con))
        legs.append((s, con, off))
    stride = float(np.median(strides))
    out = [profile(t, knees[s], ankles[s], _phase_intervals(con, off), v_walk, fwd, m.rate_hz,
                   h, stride) for s, con, off in legs]
    return summarise(out, v_walk, stride)


def sim_walk(gp, seed: int = 0, h: float = SCAN_HEIGHT_M, rate_hz: float = 200.0,
             length_m: float = 12.0) -> dict:
    """Measures of a simulated straight walk with gait ``gp`` (steady strides only)."""
    from gaitval.simulate.kinematics import leg_kinematics, make_path, plan_steps

    rng = np.random.default_rng(seed)
    path = make_path((0.0, 0.0), 0.0, [("line", length_m, "forward")])
    plan = plan_steps(path, gp, rng, t0=0.5)
    t = np.arange(0.0, plan.t_end + 1.0, 1.0 / rate_hz)
    # steady state: from the 4th contact to the 4th-last
    tc = plan.t_contact[2:]
    lo, hi = tc[3], tc[-5]
    keep = (t >= lo - 0.3) & (t <= hi + 0.3)
    xs = plan.xy[2:, 0]
    v_walk = float((xs[-5] - xs[3]) / (hi - lo))
    stride = float(np.median(np.diff(tc[::2])))
    legs = []
    for side in (0, 1):
        st = leg_kinematics(plan, side, t, gp)
        f = plan.foot(side)
        sw = [(a, b) for a, b in zip(f["t_off"], f["t_contact"])
              if np.isfinite(a) and a >= lo and b <= hi]
        legs.append(profile(t[keep], st.knee[keep], st.ankle[keep], sw, v_walk,
                            np.array([1.0, 0.0]), rate_hz, h, stride))
    return summarise(legs, v_walk, stride)


def sim_groups(seeds=(1, 2, 3), h: float = SCAN_HEIGHT_M) -> dict:
    """Mean measures over a few simulated young (TUG) and elderly (MTST) walkers."""
    from gaitval.simulate.protocols import sample_subject

    out = {}
    for group in ("young", "elderly"):
        rows = []
        for s in seeds:
            rng = np.random.default_rng(s)
            _, gp = sample_subject(rng, group, "S", h)
            rows.append(sim_walk(gp, seed=s, h=h))
        out[group] = {k: float(np.mean([r[k] for r in rows])) for k in MEASURES}
    return out


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    folder = Path(argv[0]) if argv else Path(__file__).resolve().parents[3] / "shared/realdata/c3d"
    cols = {}
    for f in REAL_WALKS:
        cols[f.split(".")[0].split("-")[0].replace("_Motion", "")] = real_walk(folder / f)
    real = {k: float(np.mean([c[k] for c in cols.values()])) for k in MEASURES}
    cols["real mean"] = real
    cols.update({f"sim {k}": v for k, v in sim_groups().items()})
    names = list(cols)
    print("| measure | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for k in MEASURES:
        print(f"| {k} | " + " | ".join(f"{cols[n][k]:.2f}" for n in names) + " |")


if __name__ == "__main__":
    main()
