"""Chalvatzaki et al. 2017 Tables I and II (KF vs PF on the rollator), published values beside.

Inputs are the per-trial evaluations of :mod:`gaitval.evaluate.rollator` (frames and
summaries, with ``subject``, ``scenario``, ``repetition``).  Repetitions of a subject and
scenario are pooled, as the paper's per-subject rows are.

Axes.  The paper's x is lateral and its y the direction of travel (its σ_ay > σ_ax and its
v_y errors exceed the v_x ones everywhere); gaitval's laser frame has x forward from the
laser (towards the user, the direction of travel) and y to the laser's left.  So the
tables' x, v_x are gaitval's y, v_y and the tables' y, v_y are gaitval's x, v_x.

Scenarios: the trial sheet's ``straight`` is Scenario 1, ``obstacle`` Scenario 2.  Subjects
are numbered 1..n in the order of their ids; the published columns are the paper's subject
with that number (simulated subjects are not the paper's patients: compare direction and
size, not subject by subject).  Values in SI units (m, m/s); the published cm, cm/s are
converted.

Table I: RMSE and MAD (mean absolute error, :func:`gaitval.stats.summary.summarize_errors`)
of the mean of both legs over the evaluated scans with an estimate.  Table II: tracking
time, error frames, their share of the evaluated frames, KF re-initialisations, and the
frames left out because the laser pose (rollator markers) or a leg's truth was unknown.
The improvement table: the mean over Table I's cells of 100·(KF − PF)/KF, for ours and for
the published cells, beside the paper's stated ~30 % (RMSE) and ~43 % (MAD).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.stats.summary import summarize_errors
from gaitval.tables import _published_chalvatzaki2017 as PUB
from gaitval.tables.render import write_table

SCENARIO_NO = {v: k for k, v in PUB.SCENARIOS.items()}
#: paper parameter -> (gaitval truth column stem, unit); "_L"/"_R" appended per leg
AXES = {"x": ("y", "m"), "y": ("x", "m"), "vx": ("vy", "m/s"), "vy": ("vx", "m/s")}


def mean_of_legs(frames: pd.DataFrame) -> pd.DataFrame:
    """Per evaluated scan with an estimate: truth and estimate of the mean of both legs in
    the paper's axes (``<p>_true``, ``<p>_est`` for p in x, y, vx, vy)."""
    f = frames[(frames["status"] == "evaluated") & frames["has_estimate"].astype(bool)]
    out = f[["trial", "tracker", "subject", "scenario", "scan"]].copy()
    for p, (g, _) in AXES.items():
        tcol = "m" if not g.startswith("v") else "mps"
        t = f"{g}_true_{tcol}"
        e = f"{g}_{tcol}"
        out[f"{p}_true"] = 0.5 * (f[f"{t}_L"] + f[f"{t}_R"])
        out[f"{p}_est"] = 0.5 * (f[f"{e}_L"] + f[f"{e}_R"])
    return out


def _numbers(summary: pd.DataFrame) -> tuple[dict, dict]:
    subjects = sorted(summary["subject"].astype(str).unique())
    return {s: i + 1 for i, s in enumerate(subjects)}, SCENARIO_NO


def _cell_note(key: tuple, p: str) -> str:
    notes = []
    if key[0] in PUB.RECONSTRUCTED:
        notes.append("reconstructed from a garbled extraction")
    if p in PUB.ONE_DECIMAL.get(key, ()):
        notes.append("PF MAD printed with one decimal (±0.1 cm)")
    for table in (PUB.ALTERNATIVE, PUB.INCONSISTENT):
        if (*key, p) in table:
            notes.append(table[(*key, p)])
    if (*key, p) in PUB.ILLEGIBLE:
        notes.append("illegible")
    return "; ".join(notes)


def rollator_table1(frames: pd.DataFrame, summary: pd.DataFrame, kf: str, pf: str,
                    external: list[str] = ()) -> pd.DataFrame:
    """Table I.

    Returns
    -------
    DataFrame, one row per scenario, subject and parameter: ``scenario_no, scenario,
    subject_no, subject, parameter, unit, n_kf, n_pf, rmse_kf, rmse_pf, mad_kf, mad_pf``,
    the four ``*_published`` values and ``published_note``; then ``n_<m>, rmse_<m>,
    mad_<m>`` of each external method ``m`` (tracking.external, issue 37; no published
    values).
    """
    sub_no, scen_no = _numbers(summary)
    m = mean_of_legs(frames)
    rows = []
    for (scen, subj), g in m.groupby(["scenario", "subject"], sort=True):
        key = (scen_no.get(scen, 0), sub_no[str(subj)])
        pub = PUB.TABLE_I.get(key, {})
        for p, (_, unit) in AXES.items():
            row = {"scenario_no": key[0] or np.nan, "scenario": scen, "subject_no": key[1],
                   "subject": subj, "parameter": p, "unit": unit}
            for tag, method in (("kf", kf), ("pf", pf), *((m, m) for m in external)):
                e = g[g["tracker"] == method]
                s = summarize_errors(e[f"{p}_true"].to_numpy(), e[f"{p}_est"].to_numpy())
                row.update({f"n_{tag}": s["n"], f"rmse_{tag}": s["rmse"],
                            f"mad_{tag}": s["mad"]})
            vals = pub.get(p, (np.nan,) * 4)
            for name, v in zip(("rmse_kf", "rmse_pf", "mad_kf", "mad_pf"), vals):
                row[f"{name}_published"] = v / 100.0                     # cm -> m
            row["published_note"] = _cell_note(key, p) if pub else "no published row"
            rows.append(row)
    cols = ["scenario_no", "scenario", "subject_no", "subject", "parameter", "unit", "n_kf",
            "n_pf", "rmse_kf", "rmse_pf", "mad_kf", "mad_pf", "rmse_kf_published",
            "rmse_pf_published", "mad_kf_published", "mad_pf_published", "published_note"]
    cols += [f"{st}_{m}" for m in external for st in ("n", "rmse", "mad")]
    return pd.DataFrame(rows, columns=cols).sort_values(
        ["scenario_no", "subject_no"], kind="stable").reset_index(drop=True)


def rollator_table2(summary: pd.DataFrame, kf: str, pf: str,
                    external: list[str] = (), own: list[str] = ()) -> pd.DataFrame:
    """Table II.

    Returns
    -------
    DataFrame, one row per scenario, subject and tracker (``KF``, ``PF``, then each
    external method by its name, without published values or re-initialisations): ``trials,
    evaluated_frames, tracking_time_s, error_frames, error_pct, swapped_frames,
    reinitialisations, pose_unknown_frames, no_truth_frames`` and ``*_published``.
    ``own``: those of the extra methods that are gaitval's own (rollator.methods, issue
    36), noted "gaitval method" instead of "external method".
    """
    sub_no, scen_no = _numbers(summary)
    s = summary[summary["status"] == "ok"]
    rows = []
    for (scen, subj, method), g in s.groupby(["scenario", "subject", "tracker"], sort=True):
        if method not in (kf, pf, *external):
            continue
        key = (scen_no.get(scen, 0), sub_no[str(subj)])
        tag = "KF" if method == kf else "PF" if method == pf else method
        pub = PUB.TABLE_II.get(key) if tag in ("KF", "PF") else None
        i = 0 if tag == "KF" else 1
        n_ev, n_err = int(g["n_evaluated"].sum()), int(g["n_error"].sum())
        rows.append({
            "scenario_no": key[0] or np.nan, "scenario": scen, "subject_no": key[1],
            "subject": subj, "tracker": tag, "trials": len(g), "evaluated_frames": n_ev,
            "tracking_time_s": float(g["tracking_time_s"].sum()),
            "tracking_time_s_published": pub[i] if pub else np.nan,
            "error_frames": n_err, "error_frames_published": pub[2 + i] if pub else np.nan,
            "error_pct": 100.0 * n_err / n_ev if n_ev else np.nan,
            "error_pct_published": pub[4 + i] if pub else np.nan,
            "swapped_frames": int(g["n_swapped"].sum()),
            "reinitialisations": int(g["restarts"].sum()) if tag == "KF" else np.nan,
            "reinitialisations_published": pub[6] if (pub and tag == "KF") else np.nan,
            "pose_unknown_frames": int(g["n_pose_unknown"].sum()),
            "no_truth_frames": int(g["n_no_truth"].sum()),
            "published_note": (PUB.TABLE_II_FLAGS.get(key, "") if pub else
                               ("gaitval method, no published values" if tag in own
                                else "external method") if tag not in ("KF", "PF") else
                               "no published row")})
    order = {"KF": 0, "PF": 1, **{m: 2 + i for i, m in enumerate(external)}}
    df = pd.DataFrame(rows)
    if len(df):
        df = df.assign(_o=df["tracker"].map(order)).sort_values(
            ["scenario_no", "subject_no", "_o"], kind="stable").drop(columns="_o")
    df = df.reset_index(drop=True)
    for c in ("reinitialisations", "reinitialisations_published", "error_frames_published"):
        if c in df:
            df[c] = df[c].astype("Int64")
    return df


def published_improvement(stat: str) -> tuple[float, int]:
    """Mean of 100·(KF − PF)/KF over every transcribed Table I cell of ``stat``."""
    i = 0 if stat == "rmse" else 2
    red = [100.0 * (v[i] - v[i + 1]) / v[i] for cell in PUB.TABLE_I.values()
           for v in cell.values() if np.isfinite(v[i]) and np.isfinite(v[i + 1])]
    return float(np.mean(red)), len(red)


def improvement(t1: pd.DataFrame) -> pd.DataFrame:
    """Mean over Table I's cells of 100·(KF − PF)/KF, ours and published (module notes).

    Returns
    -------
    DataFrame ``statistic, improvement_pct, cells, improvement_pct_published_cells,
    published_cells, improvement_pct_paper_text``; the published cells are all of the
    transcribed Table I, whatever subjects and scenarios were run here.
    """
    rows = []
    for st in ("rmse", "mad"):
        ours = 100.0 * (t1[f"{st}_kf"] - t1[f"{st}_pf"]) / t1[f"{st}_kf"]
        pub, n_pub = published_improvement(st)
        rows.append({"statistic": st.upper(), "improvement_pct": float(np.nanmean(ours)),
                     "cells": int(np.isfinite(ours).sum()),
                     "improvement_pct_published_cells": pub, "published_cells": n_pub,
                     "improvement_pct_paper_text": PUB.IMPROVEMENT_PCT[st]})
    return pd.DataFrame(rows)


def write_rollator_tables(frames: pd.DataFrame, summary: pd.DataFrame, tables_dir, *,
                          kf: str, pf: str, error_m: float = 0.10,
                          model_sources=(), shown: dict[str, str] | None = None,
                          external: list[str] = (), own: list[str] = ()) -> list[Path]:
    """Write ``rollator_table1``, ``rollator_table2`` and ``rollator_improvement``.
    ``shown``: method -> its name with the overrides it ran with
    (:func:`gaitval.methods.display_name`); a modified KF or PF is named in a note of
    every table (the columns keep their ``_kf``/``_pf`` suffixes).  ``external``: every
    extra row's method (KF and PF first, then these); ``own``: those of them that are
    gaitval's own methods (rollator.methods), the others being another tracker's
    tracks (tracking.external) — each kind gets its own note."""
    from gaitval.tables.rollator_notes import table1_notes, table2_notes

    td = Path(tables_dir)
    t1 = rollator_table1(frames, summary, kf, pf, external)
    t2 = rollator_table2(summary, kf, pf, external, own)
    imp = improvement(t1)
    changed = []
    mine = [m for m in external if m in own]
    theirs = [m for m in external if m not in own]
    if mine:                      # gaitval's own extra methods (rollator.methods)
        changed.append(
            f"Extra method{'s' * (len(mine) > 1)} {', '.join(mine)}: gaitval's own "
            "(rollator.methods), not the paper's, evaluated like the KF and PF; no published "
            "values, no re-initialisation count and no verdict; the people tracker runs with "
            "the KF's user window, detector and initialiser (docs/people.md)")
    if theirs:                    # another tracker's tracks (tracking.external)
        changed.append(
            f"External method{'s' * (len(theirs) > 1)} {', '.join(theirs)}: "
            "another tracker's tracks (tracking.external), evaluated like the KF and "
            "PF; no published values and no re-initialisation count")
    changed += [f"{tag} ran as {(shown or {})[m]}: parameters changed by "
               "tracking.overrides; the published values beside are the paper's method's"
               for tag, m in (("KF", kf), ("PF", pf)) if (shown or {}).get(m, m) != m]
    paths = write_table(t1, td / "rollator_table1", notes=changed + table1_notes(
        t1, imp, model_sources), caption=(
        "Chalvatzaki et al. 2017 Table I (tracking accuracy): RMSE and MAD of the mean position (x lateral, "
        "y forward) and mean velocity of both legs, KF (§II) vs PF (§III), per scenario and "
        "subject (repetitions pooled), in the moving laser frame; shown in the paper's cm "
        "and cm/s, published values beside (the CSV holds m and m/s)."))
    paths += write_table(t2, td / "rollator_table2", notes=changed + table2_notes(
        t2, error_m), caption=(
        "Chalvatzaki et al. 2017 Table II (tracking robustness): time of correct tracking, error frames and "
        "their share of the evaluated frames, KF re-initialisations, per scenario and "
        "subject (repetitions summed); published values beside; frames without a laser pose "
        "(rollator markers missing) or without a leg's truth are counted, not evaluated."))
    paths += write_table(imp, td / "rollator_improvement", notes=changed + [
        "Mean over the Table I cells with a value of 100·(KF − PF)/KF; the published-cells "
        "column applies the same formula to the transcribed Table I (Scenario 2 "
        "reconstructed); the paper's text states ~30 % (RMSE) and ~43 % (MAD)."], caption=(
        "Chalvatzaki et al. 2017: average error reduction of the PF over the KF (Table I cells), ours and "
        "published."))
    return paths
