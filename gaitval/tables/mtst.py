"""Yorozu et al. 2015b (MTST) Tables 1, 3 and 4, published values beside the reproduced ones.

Inputs are the per-(trial, method) tables of :mod:`gaitval.pipeline.mtst` concatenated
(``summary``, ``gates``), so this module only counts and renders.

* ``mtst_table1``: the variable validation region — Table 1's four formulas, how often the
  proposed method used each cell and the radii it realised (in metres and leg widths).
* ``mtst_table3``: lost and false tracks per method, without / with a stick, success rate,
  per reference (mocap truth where the study has it; the rater's contacts always); the
  paper's judging rule first, then the persistent-swap rule's columns
  (``*_persistent_swap``: a swap counts only when it lasts > 0.5 s; mocap rows only,
  :mod:`gaitval.evaluate.mtst_tracking`).
* ``mtst_table4``: target-step judgement and cross-step detection on the trials the
  proposed method tracked successfully (by the mocap verdict where there is mocap, else
  by the rater verdict: the mocap truth sees the track as the paper's video check did).

References
----------
Yorozu, A.; Nishiguchi, S.; Yamada, M.; Aoyama, T.; Moriguchi, T.; Takahashi, M. Gait
Measurement System for the Multi-Target Stepping Task Using a Laser Range Sensor. Sensors
2015, 15, 11151–11168 (Yorozu et al. 2015b).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.tables import _published_yorozu2015b as P
from gaitval.tables.mtst_notes import table3_notes, table4_notes
from gaitval.tables.render import write_table

CELLS = (("stance", "observable"), ("stance", "unobservable"), ("swing", "observable"),
         ("swing", "unobservable"))
GROUPS = (("no_stick", False), ("stick", True))


def _pct(a: int, b: int) -> str:
    return f"{100.0 * a / b:.1f}% ({a}/{b})" if b else ""


def _label(method: str) -> str:
    from gaitval.methods import METHODS
    return str(METHODS.get(method, {}).get("label", method))


def table1(gates: pd.DataFrame) -> pd.DataFrame:
    """Table 1 with the realised radii of the variable-region method(s)."""
    rows = []
    g = gates if len(gates) else pd.DataFrame(columns=["method", "cell", "radius_m",
                                                       "radius_leg_widths"])
    for method, d in ([("", g)] if g.empty else g.groupby("method", sort=True)):
        n = len(d)
        for phase, obs in CELLS:
            c = d[d["cell"] == f"{phase}_{obs}"]
            r, rw = c["radius_m"].astype(float), c["radius_leg_widths"].astype(float)
            rows.append({
                "method": method, "gait_phase_at_k-1": phase, "leg": obs,
                "r_val_formula": P.TABLE1[(phase, obs)], "n_leg_scans": int(len(c)),
                "share_pct": 100.0 * len(c) / n if n else np.nan,
                "radius_median_m": r.median() if len(c) else np.nan,
                "radius_p5_m": r.quantile(0.05) if len(c) else np.nan,
                "radius_p95_m": r.quantile(0.95) if len(c) else np.nan,
                "radius_max_m": r.max() if len(c) else np.nan,
                "radius_median_leg_widths": rw.median() if len(c) else np.nan})
    return pd.DataFrame(rows)


def _category_counts(s: pd.DataFrame, col: str) -> dict:
    out = {}
    for g, stick in GROUPS:
        d = s[s["stick"].astype(bool) == stick]
        out[f"n_trials_{g}"] = int(len(d))
        out[f"lost_{g}"] = int((d[col] == "lost").sum())
        out[f"false_{g}"] = int(d[col].astype(str).str.startswith("false").sum())
        out[f"false_other_object_{g}"] = int((d[col] == "false_other").sum())
    out["n_success"] = int((s[col] == "success").sum())
    out["n_trials"] = int(len(s))
    return out


#: Columns of the persistent-swap rule in Table 3 (after the paper rule's and published).
PERSISTENT = ("lost_no_stick", "false_no_stick", "lost_stick", "false_stick", "success_pct",
              "success")
PS = "_persistent_swap"


def _persistent_columns(d: pd.DataFrame, ref: str) -> dict:
    """The persistent-swap rule's Table 3 cells of one method and reference: the mocap
    verdicts only (the rater rule is persistent already); blank otherwise."""
    col = "category_mocap" + PS
    if ref != "mocap" or col not in d or d.empty:
        return {c + PS: (np.nan if c != "success" else "") for c in PERSISTENT}
    c = _category_counts(d, col)
    return {"lost_no_stick" + PS: c["lost_no_stick"], "false_no_stick" + PS: c["false_no_stick"],
            "lost_stick" + PS: c["lost_stick"], "false_stick" + PS: c["false_stick"],
            "success_pct" + PS: 100.0 * c["n_success"] / c["n_trials"],
            "success" + PS: _pct(c["n_success"], c["n_trials"])}


def table3(summary: pd.DataFrame, methods: list[str]) -> pd.DataFrame:
    """Table 3: per method and reference, lost / false tracks and success, by the paper's
    rule, its published values, then by the persistent-swap rule (``*_persistent_swap``)."""
    rows = []
    for m in methods:
        s = summary[summary["method"] == m]
        refs = [("mocap", "category_mocap", s[s["has_mocap"].astype(bool)]),
                ("rater events", "category_annotations", s[s["has_annotations"].astype(bool)])]
        fsu, rval = P.TABLE3_DEFINITIONS.get(m, ("", ""))
        pub = P.TABLE3.get(m)
        for ref, col, d in refs:
            if d.empty:
                continue
            c = _category_counts(d, col)
            rows.append({
                "method": m, "label": _label(m), "fs_u": fsu, "r_val": rval, "reference": ref,
                **{k: c[k] for k in ("n_trials_no_stick", "lost_no_stick", "false_no_stick",
                                     "n_trials_stick", "lost_stick", "false_stick")},
                "false_other_object": c["false_other_object_no_stick"]
                + c["false_other_object_stick"],
                "success_pct": 100.0 * c["n_success"] / c["n_trials"],
                "success": _pct(c["n_success"], c["n_trials"]),
                "lost_no_stick_published": pub[0] if pub else None,
                "false_no_stick_published": pub[1] if pub else None,
                "lost_stick_published": pub[2] if pub else None,
                "false_stick_published": pub[3] if pub else None,
                "success_pct_published": 100.0 * pub[4] / P.N_TRIALS["total"] if pub else None,
                "success_published": pub[5] if pub else "",
                **_persistent_columns(d, ref)})
    out = pd.DataFrame(rows)
    for c in PERSISTENT[:4]:                  # counts: "12", blank where there is no rule
        if c + PS in out:
            out[c + PS] = pd.Series([None if pd.isna(v) else int(v) for v in out[c + PS]],
                                    dtype=object)
    return out


def judging_rules_note(t3: pd.DataFrame) -> str:
    """The note that names Table 3's two judging rules, with the success of each method
    under both (mocap rows)."""
    text = ("Two judging rules side by side, fixed before the results: the "
            "columns without suffix use the paper's rule (any swap or lost track of >= "
            "0.20 s against the mocap truth, or two consecutive rater contacts; primary, "
            "compared with the published values); the *_persistent_swap columns count a "
            "left/right swap only when it lasts > 0.5 s (shorter swaps that recover are "
            "forgiven; lost and other-object tracks as before; mocap rows only: the rater "
            "rule's two consecutive contacts already span about a stride).")
    if t3.empty or "success_pct" + PS not in t3:
        return text
    mo = t3[t3["reference"] == "mocap"]
    parts = [f"{m} {r['success_pct']:.1f} % -> {r['success_pct' + PS]:.1f} %"
             for m, r in mo.set_index("method").iterrows()
             if pd.notna(r["success_pct" + PS])]
    return text + (" Success, paper rule -> persistent-swap rule: " + "; ".join(parts) + "."
                   if parts else "")


def table4_trials(summary: pd.DataFrame, method: str = "mtst_proposed") -> pd.DataFrame:
    """The trials Table 4 uses: those ``method`` tracked successfully (module notes)."""
    s = summary[(summary["method"] == method) & summary["has_annotations"].astype(bool)]
    ok = np.where(s["has_mocap"].astype(bool), s["category_mocap"] == "success",
                  s["category_annotations"] == "success")
    return s[ok]


def table4(summary: pd.DataFrame, method: str = "mtst_proposed") -> pd.DataFrame:
    """Table 4: target-step judgement and cross-step detection."""
    s = table4_trials(summary, method)
    st = s[s["has_targets"].astype(bool)]
    rows = []
    for row, d, n_col, non_col, mis_col, det_col in (
            ("target_step", st, "n_steps", "non_judgement", "misjudgement", "n_steps"),
            ("cross_step", s, "n_cross_ref", "non_detection", "false_detection",
             "n_cross_sys")):
        r = {"row": row, "n_trials": int(len(d))}
        tot = {"n": 0, "non": 0, "mis": 0, "det": 0}
        for g, stick in GROUPS:
            dd = d[d["stick"].astype(bool) == stick]
            vals = {k: int(dd[c].sum()) for k, c in (("n", n_col), ("non", non_col),
                                                     ("mis", mis_col), ("det", det_col))}
            r.update({f"n_steps_{g}": int(dd["n_steps"].sum()), f"n_cross_{g}":
                      int(dd["n_cross_ref"].sum()), f"non_{g}": vals["non"],
                      f"mis_or_false_{g}": vals["mis"]})
            tot = {k: tot[k] + vals[k] for k in tot}
        pub = P.TABLE4[row]
        r.update({
            "success_pct": 100.0 * (tot["n"] - tot["non"]) / tot["n"] if tot["n"] else np.nan,
            "success": _pct(tot["n"] - tot["non"], tot["n"]),
            "error_rate_pct": 100.0 * tot["mis"] / tot["det"] if tot["det"] else np.nan,
            "error_rate": _pct(tot["mis"], tot["det"]),
            "non_no_stick_published": pub[0], "mis_or_false_no_stick_published": pub[1],
            "non_stick_published": pub[2], "mis_or_false_stick_published": pub[3],
            "success_published": pub[4], "error_rate_published": pub[5]})
        rows.append(r)
    out = pd.DataFrame(rows)
    n_steps = int(s["n_steps"].sum())
    out["cross_per_100_steps"] = (100.0 * s["n_cross_ref"].sum() / n_steps if n_steps
                                  else np.nan)
    out["cross_per_100_steps_published"] = round(P.CROSS_PER_100, 1)
    return out


def mocap_notes(summary: pd.DataFrame) -> list[str]:
    """A note when some or all evaluated trials have no mocap (issue 11: a study with
    rater annotations only); none when every trial has mocap."""
    if summary.empty:
        return []
    has = summary.drop_duplicates("trial").set_index("trial")["has_mocap"].astype(bool)
    if has.all():
        return []
    if not has.any():
        return ["mocap truth: not available (no trial has mocap): every row is against the "
                "rater annotations ('rater events'); a trial counts as tracked by its rater "
                "verdict."]
    return [f"mocap truth: available for {int(has.sum())} of {len(has)} trials; the 'mocap' "
            "rows count those only, the 'rater events' rows every trial with annotations."]


def table4_external(summary: pd.DataFrame, t4: pd.DataFrame, external: list[str]
                    ) -> pd.DataFrame:
    """Table 4 with a ``method`` column: the proposed method's rows, then each external
    method's (tracking.external) on the trials *it* tracked successfully, without
    published values (they are the proposed method's)."""
    out = [t4.assign(method="mtst_proposed")]
    for m in external:
        e = table4(summary, m).assign(method=m)
        for c in e.columns:
            if c.endswith("_published"):
                e[c] = np.nan
        out.append(e)
    df = pd.concat(out, ignore_index=True)
    return df[["method"] + [c for c in df.columns if c != "method"]]


def write_mtst_tables(data: dict[str, pd.DataFrame], tables_dir, *,
                      methods: list[str], shown: dict[str, str] | None = None,
                      external: list[str] = (), left_out: dict[str, str] | None = None
                      ) -> list[Path]:
    """Write ``mtst_table1``, ``mtst_table3``, ``mtst_table4`` (csv, md, tex) from the
    concatenated per-trial tables ``data`` (``summary``, ``gates``).  ``shown``: method ->
    the name the tables print (a method run with overrides,
    :func:`gaitval.methods.display_name`).  ``external``: external methods,
    which get rows in Tables 3 and 4 (Table 4 then has a ``method`` column).
    ``left_out``: trial -> why it is not in the tables (a refused registration with
    nothing else to place it); Tables 3 and 4 say so in a note."""
    td = Path(tables_dir)
    summary = data.get("summary", pd.DataFrame())
    if summary.empty:
        summary = pd.DataFrame(columns=["trial", "method", "stick", "has_mocap",
                                        "has_annotations", "has_targets", "category_mocap",
                                        "category_annotations", "n_steps", "n_cross_ref"])
    t1 = table1(data.get("gates", pd.DataFrame()))
    t3 = table3(summary, methods)
    t4 = table4(summary)
    gone = ([f"{len(left_out)} trial(s) left out of every row: "
             + "; ".join(f"{t} ({why})" for t, why in left_out.items())
             + " -- the registration table gives each reason; with no mocap truth, no "
             "mtst.poles_m pose or no trial-sheet clock_offset_s nothing else places the "
             "trial's tracks or rater contacts."] if left_out else [])
    notes3 = gone + mocap_notes(summary) + [judging_rules_note(t3)] + table3_notes(
        t3, data.get("events"), data.get("track_field"))
    if shown:                                  # a method run with overrides says so
        t1, t3 = (t.assign(method=t["method"].map(lambda m: shown.get(m, m)))
                  for t in (t1, t3))
    paths = write_table(t1, td / "mtst_table1", caption=(
        "Yorozu et al. 2015b Table 1: radius r_val of the variable validation region by the leg's gait "
        "phase at k-1 and whether it was observable (H = consecutive unobservable scans; "
        f"v_sw = {P.V_SW_MPS} m/s, v_st = {P.V_ST_MPS} m/s, dt = 0.05 s), with how often "
        "the proposed method used each cell (leg-scans) and the radii it realised."), notes=[
        "The formulas are the paper's Table 1; the counts and radii are reproduced (the "
        "paper gives none). Radii are recomputed from each track exactly as the tracker "
        "built them (gaitval.evaluate.mtst_tracking.gate_usage)."])
    paths += write_table(t3, td / "mtst_table3", caption=(
        "Yorozu et al. 2015b Table 3: lost and false tracks per trial (a failed trial counted once) "
        "for Methods 1-3 and the proposed method, participants without / with a stick, "
        "and the tracking success rate; published values beside. Reference 'mocap': the "
        "track against the mocap leg points (stands in for the paper's video check); "
        "'rater events': from the rater's contacts only (what a study without mocap "
        "has)."), notes=notes3)
    notes4 = gone + mocap_notes(summary) + table4_notes(t4, table4_trials(summary))
    if external:
        t4 = table4_external(summary, t4, list(external))
        notes4.append(f"External method{'s' * (len(external) > 1)} {', '.join(external)}: "
                      "another tracker's tracks (tracking.external), judged on the trials it "
                      "tracked successfully; no published values (the paper's are the "
                      "proposed method's).")
    paths += write_table(t4, td / "mtst_table4", caption=(
        "Yorozu et al. 2015b Table 4: target-step judgement and cross-step detection against the "
        "rater annotations on the trials the proposed method tracked successfully; "
        "success = (N - non-judgements or non-detections) / N, error rate = "
        "misjudgements / steps or false detections / detected cross steps; published "
        "values beside."), notes=notes4)
    return paths
