"""The default TUG trials re-rendered in memory with one free choice of the twin changed:
a sensitivity check of the ``tug_phase_duration`` and ``tug_occlusion`` rows of
:mod:`gaitval.simulate.physics` (docs/history/simulator.md, "Why the TUG turning occlusion
and return rows failed").  Nothing is written; every trial keeps its random streams.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.simulate.physics import TUG_PHASE_LEG_SCANS


def tug_occlusion_variant(preset: str | dict = "default", marker_in_scan_plane: bool = True,
                          turn_step_factor: float | None = None,
                          marker_scan_radius_m: float | None = None,
                          sensor_nominal_pose: tuple[float, float, float] | None = None
                          ) -> pd.DataFrame:
    """The TUG trials of a preset re-rendered in memory with one scene or gait choice
    changed, and their truth phase durations and occlusion (the ``tug_phase_duration`` and
    ``tug_occlusion`` rows' measures; nothing is written).

    A sensitivity check of two free choices of the twin (docs/history/simulator.md, "Why
    the TUG turning occlusion and return rows failed"): ``marker_in_scan_plane=False`` leaves the
    turn marker out of the laser's scene (a marker lower than the scan plane; the walker's
    path still goes around its base), ``turn_step_factor`` replaces the walkers'
    ``GaitParams.turn_step_factor``, ``marker_scan_radius_m`` the marker's section in the
    scan plane (the preset's ``tug.marker_scan_radius_m``; 0 = below the plane; the path
    around the marker is unchanged), ``sensor_nominal_pose`` the preset's
    ``tug.sensor_nominal_pose`` (``x, y, yaw``; each participant's jitter is drawn from
    the same stream).  Every trial keeps its random streams, so with the defaults the
    figures are those of the written study.

    Returns
    -------
    DataFrame
        Per phase: ``occluded`` and ``leg_scans`` (summed over trials), ``occlusion``, and
        ``seconds`` (mean per trial).
    """
    from dataclasses import replace

    from gaitval.simulate import render as RD
    from gaitval.simulate import study as S

    cfg = S.load_preset(preset)
    if not marker_in_scan_plane:                  # a marker below the plane: radius 0
        marker_scan_radius_m = 0.0
    if marker_scan_radius_m is not None:
        cfg["tug"]["marker_scan_radius_m"] = float(marker_scan_radius_m)
    if sensor_nominal_pose is not None:
        cfg["tug"]["sensor_nominal_pose"] = [float(v) for v in sensor_nominal_pose]
    seed = int(cfg["seed"])
    tasks = [t for t in S._lrs_tasks(cfg, cfg["study"], seed, [])
             if t[1] == "tug"]
    tot = {ph: [0, 0, 0] for ph in TUG_PHASE_LEG_SCANS}
    period = np.nan
    for idx, _proto, build, bargs, _subj, drift in tasks:
        rng_t = S._rng(seed, 3, idx)
        if turn_step_factor is not None:
            bargs = list(bargs)
            bargs[2] = replace(bargs[2], turn_step_factor=float(turn_step_factor))
        sim = build(rng_t, *bargs)
        sim.variant.update(S._variant(rng_t, cfg))
        clock = {**S.sensor_clock(rng_t, cfg.get("clock", {})), "clock_drift_ppm": drift}
        _, scans, _, _ = RD.render_laser(sim, clock, S._rng(seed, 11, idx))
        t_end = float(RD.mocap_frames(sim)[-1])
        s = scans[(scans["t_mocap_s"] >= 0) & (scans["t_mocap_s"] <= t_end)]
        period = float(np.median(np.diff(np.unique(s["t_mocap_s"]))))
        for ph in tot:
            e = s[s["phase"] == ph]
            tot[ph][0] += int(e["occluded"].sum())
            tot[ph][1] += len(e)
            tot[ph][2] += e["scan"].nunique()
    return pd.DataFrame([{"phase": ph, "occluded": k, "leg_scans": m,
                          "occlusion": k / max(m, 1), "seconds": n * period / len(tasks)}
                         for ph, (k, m, n) in tot.items()]).set_index("phase")
