"""Notes under Chalvatzaki et al. 2017's tables: what was computed how, and whether the paper's direction
(PF better than KF in RMSE, MAD and error frames) holds, counted cell by cell."""
from __future__ import annotations

import numpy as np
import pandas as pd


def _wins(a: pd.Series, b: pd.Series) -> tuple[int, int]:
    """(cells where b < a, cells where both are finite)."""
    ok = np.isfinite(a.to_numpy(float)) & np.isfinite(b.to_numpy(float))
    return int((b[ok] < a[ok]).sum()), int(ok.sum())


def table1_notes(t1: pd.DataFrame, imp: pd.DataFrame, model_sources=()) -> list[str]:
    notes = []
    for st in ("rmse", "mad"):
        w, n = _wins(t1[f"{st}_kf"], t1[f"{st}_pf"])
        wp, npub = _wins(t1[f"{st}_kf_published"], t1[f"{st}_pf_published"])
        r = imp[imp["statistic"] == st.upper()].iloc[0]
        notes.append(f"{st.upper()}: PF below KF in {w} of {n} cells here, {wp} of {npub} "
                     "published for the same rows; mean reduction "
                     f"{r['improvement_pct']:.1f} % here, "
                     f"{r['improvement_pct_published_cells']:.1f} % from the published cells, "
                     f"~{r['improvement_pct_paper_text']:.0f} % in the paper's text.")
    for p in ("x", "y", "vx", "vy"):
        g = t1[t1["parameter"] == p]
        w, n = _wins(g["rmse_kf"], g["rmse_pf"])
        notes.append(f"{p}: PF RMSE below KF in {w} of {n} subject/scenario cells.")
    notes += [
        "Axes: the paper's x is lateral and y forward (direction of travel); they are "
        "gaitval's laser-frame y and x (x points from the laser on the rollator towards "
        "the user).",
        "Errors of the mean of both legs over every evaluated scan with an estimate of both "
        "legs, error frames included; MAD = mean absolute error (Chalvatzaki et al. 2017's usage). Truth: "
        "tibia-cylinder cross-section at laser height in the moving laser frame, velocities "
        "by differentiation of low-passed positions.",
        "PF parameters (velocity mixtures, window, region distributions, count kernel, "
        "Gamma, random walk) learned per held-out subject from the other subjects' trials, "
        "never from the tested trial; models used: "
        + (", ".join(s for s in model_sources if s) or "none recorded") + ".",
    ]
    return notes


def table2_notes(t2: pd.DataFrame, error_m: float) -> list[str]:
    kf = t2[t2["tracker"] == "KF"].set_index(["scenario", "subject"])
    pf = t2[t2["tracker"] == "PF"].set_index(["scenario", "subject"])
    both = kf.index.intersection(pf.index)
    fewer = int((pf.loc[both, "error_frames"] < kf.loc[both, "error_frames"]).sum())
    same = int((pf.loc[both, "error_frames"] == kf.loc[both, "error_frames"]).sum())
    tot = {k: (int(d["error_frames"].sum()), int(d["evaluated_frames"].sum()))
           for k, d in (("KF", kf), ("PF", pf))}
    pct = {k: 100.0 * e / n if n else float("nan") for k, (e, n) in tot.items()}
    return [
        f"Error frame: an evaluated scan where a leg has no estimate, either leg's estimate "
        f"is more than {error_m:.2f} m from its truth, or the legs are swapped (each "
        "estimate nearer the other leg's truth). The paper does not state its rule.",
        f"PF has fewer error frames than KF in {fewer} of {len(both)} subject/scenario rows "
        f"({same} equal); totals KF {tot['KF'][0]} of {tot['KF'][1]} frames "
        f"({pct['KF']:.1f} %), PF {tot['PF'][0]} of {tot['PF'][1]} ({pct['PF']:.1f} %).",
        "Tracking time = correct evaluated frames × the scan period (the paper's KF and PF "
        "times differ by its error frames at ~37 frames/s). KF re-initialisations: restarts "
        "of both legs after 15 scans without a detection (the PF is never re-initialised).",
        "Published inconsistencies are flagged, not fixed (see published_note).",
    ]
