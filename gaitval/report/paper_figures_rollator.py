"""Seed 002's Fig. 5 (Chalvatzaki et al. 2017: clutter and occlusion handled by the KF and
the PF) from the run's rollator evaluations and scans.

:func:`figure5` draws scan snapshots (:mod:`gaitval.report.paper_figures_scans`), one row
per tracker (KF, PF) and one column per situation:

- *clutter*: the first scan at which the KF's error began (Table II's error frames) while
  both true legs had laser points on them and the PF was not in error — the KF took
  something else for a leg;
- *occlusion*: the first scan at which the KF's error began while one true leg had fewer
  than ``min_points`` laser points within a leg radius (hidden), the PF again not in error.

Where the run has no such scan, a column falls back to the first KF error onset of any kind,
and without any KF error to the scan where a leg was hidden longest; its heading says so.
The paper's panels also show the KF's detected leg positions and the PF's particles; the
track files keep neither, so they are not drawn.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.paper_figures_scans import nearest_scan, scan_points, snapshot_figure


def leg_truth(frames: pd.DataFrame) -> pd.DataFrame:
    """The evaluation frames' true legs as ``t_sensor_s, side, xs_m, ys_m`` rows (the laser
    frame, as the tracks)."""
    parts = [pd.DataFrame({"t_sensor_s": frames["t_sensor_s"].to_numpy(float), "side": side,
                           "xs_m": frames[f"x_true_m_{side}"].to_numpy(float),
                           "ys_m": frames[f"y_true_m_{side}"].to_numpy(float)})
             for side in ("L", "R")]
    return pd.concat(parts, ignore_index=True).sort_values(["t_sensor_s", "side"],
                                                          kind="stable")


def points_on_legs(scans, frame: pd.Series, radius_m: float) -> tuple[int, int]:
    """Laser points within ``radius_m`` of the true left and right leg at a frame's scan."""
    pts = scan_points(scans, nearest_scan(scans.t, float(frame["t_sensor_s"])))
    out = []
    for side in ("L", "R"):
        c = np.array([frame[f"x_true_m_{side}"], frame[f"y_true_m_{side}"]], dtype=float)
        out.append(int((np.hypot(*(pts - c).T) <= radius_m).sum()) if np.all(np.isfinite(c))
                   else 0)
    return out[0], out[1]


def error_onsets(kf: pd.DataFrame, pf: pd.DataFrame) -> pd.DataFrame:
    """The KF's evaluated frames at which its error begins (error now, not at the previous
    frame), with ``pf_ok``: the PF evaluated and not in error at that scan."""
    kf = kf.sort_values("scan")
    err = kf["error"].astype(bool).to_numpy()
    onset = err & ~np.concatenate([[False], err[:-1]])
    on = kf[onset & (kf["status"] == "evaluated").to_numpy()].copy()
    pfe = pf.set_index("scan")
    on["pf_ok"] = [bool(s in pfe.index and pfe.loc[s, "status"] == "evaluated"
                        and not bool(pfe.loc[s, "error"])) for s in on["scan"]]
    return on


def pick_situations(frames: pd.DataFrame, kf: str, pf: str, scans_of, radius_m: float,
                    min_points: int = 3) -> list[tuple[str, str, float]]:
    """``(situation heading, trial, time)`` of the clutter and the occlusion column
    (module notes)."""
    found: dict[str, tuple[str, float]] = {}
    fallback = None
    hidden_best = None
    for trial in sorted(frames["trial"].astype(str).unique()):
        f = frames[frames["trial"].astype(str) == trial]
        fk, fp = f[f["tracker"] == kf], f[f["tracker"] == pf]
        if fk.empty:
            continue
        scans = scans_of(trial)
        on = error_onsets(fk, fp)
        for r in on.itertuples(index=False):
            row = pd.Series(r._asdict())
            nl, nr = points_on_legs(scans, row, radius_m)
            kind = "occlusion" if min(nl, nr) < min_points else "clutter"
            if fallback is None:
                fallback = (trial, float(row["t_sensor_s"]), kind)
            if row["pf_ok"] and kind not in found:
                found[kind] = (trial, float(row["t_sensor_s"]))
        if hidden_best is None:
            ev = fk[fk["status"] == "evaluated"]
            if len(ev):
                n = [min(points_on_legs(scans, ev.iloc[i], radius_m))
                     for i in range(0, len(ev), max(1, len(ev) // 200))]
                i = int(np.argmin(n))
                hidden_best = (trial, float(ev.iloc[i * max(1, len(ev) // 200)]["t_sensor_s"]))
    out = []
    for kind in ("clutter", "occlusion"):
        if kind in found:
            out.append((f"{kind}: KF error begins, PF right", *found[kind]))
        elif fallback is not None:
            out.append((f"no {kind} case with the PF right: first KF error ({fallback[2]})",
                        fallback[0], fallback[1]))
        elif hidden_best is not None:
            out.append(("no KF error in this run: fewest points on a leg", *hidden_best))
    return out


def figure5(frames: pd.DataFrame, tracks: pd.DataFrame, scans_of, path: str | Path, *,
            kf: str = "rollator_kf", pf: str = "rollator_pf", leg_radius_m: float = 0.06
            ) -> Path | None:
    """KF (top) and PF (bottom) at the clutter and the occlusion scan of
    :func:`pick_situations` (each column from its own trial); None without KF frames."""
    if frames.empty or not (frames["tracker"] == kf).any():
        return None
    sit = pick_situations(frames, kf, pf, scans_of, leg_radius_m)
    if not sit:
        return None
    rows = []
    for m in (kf, pf):
        per = [tracks[(tracks["trial"].astype(str) == tr) & (tracks["method"].astype(str) == m)]
               for _, tr, _ in sit]
        if any(len(p) for p in per):
            rows.append((m, per))
    truth = [leg_truth(frames[(frames["trial"].astype(str) == tr) & (frames["tracker"] == kf)])
             for _, tr, _ in sit]
    title = ("Rollator: KF and PF estimates on the laser scan, laser frame (cf. Chalvatzaki "
             "et al. 2017 Fig. 5)\nthe KF's detections and the PF's particles are not drawn: "
             "the track files do not keep them")
    return snapshot_figure([scans_of(tr) for _, tr, _ in sit], rows, [t for *_, t in sit],
                           path, title=title, truth=truth, half_m=0.6,
                           column_titles=[f"{h}\n{tr}" for h, tr, _ in sit])


def write_rollator_paper_figures(frames: pd.DataFrame, tracks: pd.DataFrame, scans_of,
                                 out_dir, kf: str = "rollator_kf", pf: str = "rollator_pf"
                                 ) -> list[Path]:
    """``rollator_fig5.png`` when the run has KF frames."""
    p = figure5(frames, tracks, scans_of, Path(out_dir) / "rollator_fig5.png", kf=kf, pf=pf)
    return [p] if p is not None else []
