"""The verdict page: one row per published comparison — reproduced, not reproduced or not
comparable — with the data it rests on and why.

Each row states a comparison one of the seed papers makes (a ranking of methods, the
direction of an effect, or a value with its published spread), the published numbers, the
reproduced numbers *with the numbers the criterion used* (the 95 % interval when the
criterion is an interval), the outcome and, in ``why``, the cause in one sentence taken
from the table's own evidence.  Everything is read from the tables' CSVs and notes
(``<reports>/tables/*.csv``, ``*.md``), which carry the published values beside the
reproduced ones, so no number here is typed by hand and a rerun updates the page.

Outcomes (column ``outcome``):

* ``reproduced`` / ``not reproduced`` — the criterion holds / fails;
* ``not comparable`` — the comparison cannot be scored, and ``why`` says why: the table
  itself says its numbers are not comparable with the paper's (ultrasonic Table 7's test
  of another hypothesis, Table C1's grouping, NS/NV's definition of n — recognised by the
  table's note, so a table that stops saying so is scored again), or the study is too
  small for the comparison (a statistic undefined, or a 95 % interval wider than half
  the range: too wide to test a published value with);
* ``not run`` — the run has no study with the paper's protocol.

One primary reading per comparison.  TUG's Methods run under two readings of Yorozu et al. 2015a
eq. (3)–(4) (:mod:`gaitval.gait.phases`); the primary one is gaitval's default
(``swing_first``: the reading that gives Table 2's v_sw_th and the "unlikely" Phase 5 of
the paper's text a role, docs/tracking.md); the other is shown beside it in
``alternative`` with its own outcome and is not counted.

Criteria (column ``criterion``): ranking — every pair the paper ranks strictly is ranked
the same way; direction — the sign of the published difference holds; published inside
the reproduced 95% CI (Wilson) — for a proportion; value inside published mean ± SD.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (Yorozu et al. 2015a, TUG).
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (Yorozu et al. 2015b, MTST).
Chalvatzaki, G. et al. ICRA 2017 (Chalvatzaki et al. 2017, robotic rollator).
Qi, Y. et al. Sensors 2014, 14(8), 15434–15457 (Qi et al. 2014, ultrasonic).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.report.robustness_share import share_column
from gaitval.report.verdicts_common import (  # noqa: F401  (re-exported)
    MAX_CI_WIDTH, MIN_SUBJECTS_CELLS, MIN_SUBJECTS_T, MIN_SUCCESS_TRIALS, NOT_COMPARABLE_NOTE,
    SHORT, _broken_pairs, _ci, _order, _pct, _proportion_verdict, _ranking, _row,
    _same_ranking, wilson)
from gaitval.report.verdicts_occlusion import tug_occlusion_verdicts
from gaitval.report.verdicts_ultrasonic import (  # noqa: F401  (re-exported)
    PAPER_SUBJECTS_US, sd_interval, ultrasonic_verdicts)

#: Columns of :func:`build_verdicts`.
VERDICT_COLUMNS = ("study", "data", "comparison", "source", "table", "published",
                   "reproduced", "criterion", "outcome", "why", "alternative", "robustness")
OUTCOMES = ("reproduced", "not reproduced", "not comparable", "not run")
STUDIES = {"tug": "TUG leg tracking (Yorozu et al. 2015a)", "mtst": "MTST (Yorozu et al. 2015b)",
           "rollator": "Robotic rollator (Chalvatzaki et al. 2017)", "ultrasonic": "Ultrasonic (Qi et al. 2014)"}
#: The table each study's verdicts need; absent → one ``not run`` row.
REQUIRED = {"tug": "tug_table3", "mtst": "mtst_table3", "rollator": "rollator_table1",
            "ultrasonic": "ultrasonic_table8"}
#: The papers' methods, the only rows a published comparison can be made for.
PAPER_METHODS = {"tug": ("tug_m1", "tug_m2", "tug_m3"),
                 "mtst": ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed")}
#: TUG: the primary reading of seed000 eq. (3)-(4) (module notes).
PRIMARY_READING = "swing_first"
# -- TUG (Yorozu et al. 2015a) ------------------------------------------------------------------------
_TUG_FAIL = (("ft_turning", "false tracking in turning"), ("ft_return",
             "false tracking on return"), ("ft_forward", "false tracking forward"),
             ("sf_turning", "stance failures in turning"), ("sf_other", "other stance failures"))


def _tug_failures(r) -> str:
    parts = [f"{label} {int(r[c])}" for c, label in _TUG_FAIL
             if c in r and np.isfinite(r[c]) and int(r[c])]
    return ", ".join(parts) if parts else "none"


def _tug_reading_rows(g: pd.DataFrame) -> dict[str, dict]:
    """The Table 3 verdicts of one reading, keyed by comparison."""
    st, out = "tug", {}
    g = g.set_index("base_method")
    pub = {m: float(g.loc[m, "success_rate_published"]) for m in g.index}
    rep = {m: float(g.loc[m, "success_rate"]) for m in g.index}
    n = {m: float(g.loc[m, "n_trials"]) for m in g.index}
    small = [m for m in g.index if (lambda lo_hi: lo_hi[1] - lo_hi[0])(
        wilson(g.loc[m, "n_success"], n[m])) > MAX_CI_WIDTH or not n[m]]
    ok = _same_ranking(pub, rep)
    if small:
        why = (f"too small: {int(max(n.values()))} trials per method; the 95% CIs of the "
               "success rates overlap almost entirely")
        ok = None
    elif ok:
        why = "same order as the paper's: " + _ranking(rep, _pct) + "."
    else:
        worst = max(g.index, key=lambda m: pub[m] - rep[m])
        why = (_broken_pairs(pub, rep, _pct) + f"; {SHORT.get(worst, worst)}'s failures: "
               + _tug_failures(g.loc[worst]) + " (tug_failures: the first failure of each).")
    out["ranking"] = _row(st, "Tracking success ranking of Methods 1-3", "Table 3",
                          _ranking(pub, _pct), _ranking(rep, _pct), "ranking", ok, why,
                          "tug_table3")
    for m in g.index:
        r = g.loc[m]
        text, ok, small = _proportion_verdict(r["n_success"], r["n_trials"],
                                              r["success_rate_published"])
        pub_text = (f"{_pct(r['success_rate_published'])} ({int(r['n_success_published'])}/"
                    f"{int(r['n_trials_published'])})")
        if small:
            why = small
        elif ok:
            why = f"the paper's {_pct(r['success_rate_published'])} lies inside the interval."
        else:
            side = "below" if r["success_rate"] < r["success_rate_published"] else "above"
            why = (f"{int(r['n_success'])} of {int(r['n_trials'])} trials tracked, {side} "
                   f"the paper's {int(r['n_success_published'])}; failures: "
                   + _tug_failures(r) + ".")
        out[m] = _row(st, f"Success rate {SHORT.get(m, m)}", "Table 3", pub_text, text,
                      "paper inside our 95% CI", ok, why, "tug_table3",
                      not_comparable=small)
    return out


def tug_verdicts(t: dict[str, pd.DataFrame], notes: dict | None = None,
                 physics: list[Path] | None = None) -> list[dict]:
    """Yorozu et al. 2015a: success ranking and per-method success (Table 3; primary reading of
    eq. (3)–(4), the other beside); Method 3 below Method 2 in turning-phase (Table 4) and
    unobservable (Table 5) RMSE; Method 2's occluded leg-scans per phase, tracker-counted
    as the paper's, the truth beside (``physics``: the studies' ``physics.csv``)."""
    st = "tug"
    t3 = t["tug_table3"]
    if "phase_reading" not in t3:
        t3 = t3.assign(phase_reading=PRIMARY_READING, base_method=t3["method"])
    # the paper's methods only: an extra row (the people tracker, an external tracker) has
    # no published value to be compared with
    t3 = t3[t3["base_method"].isin(PAPER_METHODS["tug"])]
    readings = {r: _tug_reading_rows(g) for r, g in t3.groupby("phase_reading", sort=False)}
    primary = PRIMARY_READING if PRIMARY_READING in readings else next(iter(readings))
    rows = []
    for key, row in readings[primary].items():
        row["comparison"] += f" (reading {primary})"
        row["alternative"] = "; ".join(
            f"reading {r}: {rr[key]['reproduced']} ({rr[key]['outcome']})"
            for r, rr in readings.items() if r != primary and key in rr)
        rows.append(row)
    for name, key, val, label in (("tug_table4", "tug_phase", "turning",
                                   "Turning-phase RMSE M3 < M2 (x and y)"),
                                  ("tug_table5", "observation_state", "unobservable",
                                   "Unobservable-step RMSE M3 < M2 (x and y)")):
        d = t.get(name)
        if d is None:
            continue
        d = d[(d[key] == val) & (d.get("phase_reading", PRIMARY_READING) == primary)]
        # a method run with tracking.overrides is named "tug_m3 (occlusion.max_n = 10)"
        shown = dict(zip(d["method"].astype(str).str.split(" (", n=1, regex=False).str[0],
                         d["method"].astype(str)))
        d = d.assign(method=d["method"].astype(str).str.split(" (", n=1, regex=False).str[0])
        d = d.set_index("method")
        if not {"tug_m2", "tug_m3"} <= set(d.index):
            continue
        a, b = d.loc["tug_m3"], d.loc["tug_m2"]
        modified = [shown[m] for m in ("tug_m2", "tug_m3") if shown.get(m, m) != m]

        def fmt(x3, x2, y3, y2):
            return f"x {x3:.3f} vs {x2:.3f} m, y {y3:.3f} vs {y2:.3f} m"
        finite = np.isfinite([a.rmse_x_m, b.rmse_x_m, a.rmse_y_m, b.rmse_y_m]).all()
        g3 = t3[t3["phase_reading"] == primary].set_index("base_method")
        n_ok = {m: int(g3.loc[m, "n_success"]) for m in ("tug_m2", "tug_m3") if m in g3.index}
        if finite and n_ok and min(n_ok.values()) < MIN_SUCCESS_TRIALS:
            ok, rep = None, fmt(a.rmse_x_m, b.rmse_x_m, a.rmse_y_m, b.rmse_y_m)
            why = (f"too small: an RMSE over {min(n_ok.values())} tracking-success trial(s) "
                   f"(M2 {n_ok.get('tug_m2', 0)}, M3 {n_ok.get('tug_m3', 0)}; the paper: 25 "
                   "and 27) compares single walks, not the methods")
        elif finite:
            ok = bool(a.rmse_x_m < b.rmse_x_m and a.rmse_y_m < b.rmse_y_m)
            lower = [ax for ax in ("x", "y") if a[f"rmse_{ax}_m"] < b[f"rmse_{ax}_m"]]
            n_steps = ("time_steps" if "time_steps" in d else "n_steps")
            steps = (f" over {int(a[n_steps])} (M3) and {int(b[n_steps])} (M2) time steps"
                     if n_steps in d else "")
            why = (f"M3 lower in {' and '.join(lower) or 'neither axis'}{steps}"
                   + ("." if ok else f"; not in {' and '.join(ax for ax in ('x', 'y') if ax not in lower)}."))
            rep = fmt(a.rmse_x_m, b.rmse_x_m, a.rmse_y_m, b.rmse_y_m)
        else:
            ok, rep = None, "no successful trial of M2 or M3"
            why = "too small: no tracking-success trial of M2 or M3 to compute an RMSE"
        if modified:
            why = (f"{' and '.join(modified)} ran with tracking.overrides, not as the paper "
                   f"defines it; {why}")
        rows.append(_row(st, f"{label} (reading {primary})", f"Table {name[-1]}",
                         fmt(a.rmse_x_m_published, b.rmse_x_m_published,
                             a.rmse_y_m_published, b.rmse_y_m_published), rep,
                         "direction", ok, why, name))
    if t.get("tug_table4") is not None:
        rows += tug_occlusion_verdicts(t["tug_table4"], primary, physics)
    return rows


# -- MTST (Yorozu et al. 2015b) -----------------------------------------------------------------------
def _k_n(s: str) -> tuple[float, float] | None:
    """``(k, n)`` of a ``"x% (k/n)"`` string."""
    try:
        k, n = s.split("(")[1].split(")")[0].split("/")
        return float(k), float(n)
    except (IndexError, ValueError):
        return None


def _pct_of(s: str) -> float:
    try:
        return float(s.split("%")[0])
    except ValueError:
        return np.nan


def _mtst_failures(r) -> str:
    parts = []
    for col, label in (("lost_no_stick", "lost"), ("false_no_stick", "false")):
        if col in r and np.isfinite(r[col]):
            pub = r.get(f"{col}_published", np.nan)
            parts.append(f"{label} {int(r[col])}/{int(r['n_trials_no_stick'])} without a "
                         f"stick" + (f" (paper {int(pub)})" if np.isfinite(pub) else ""))
    return ", ".join(parts)


def mtst_verdicts(t: dict[str, pd.DataFrame], notes: dict | None = None) -> list[dict]:
    """Yorozu et al. 2015b: success ranking of Methods 1-3 and the proposed method (Table 3, mocap
    reference; the rater events' where no trial has mocap), each method's success and
    target-step judgement success (Table 4), each with its 95 % interval."""
    st = "mtst"
    rows = []
    t3 = t["mtst_table3"]
    ref = "mocap reference"
    if "reference" in t3:
        if not (t3["reference"] == "mocap").any() and len(t3):
            ref = "rater events reference; mocap truth: not available"
            t3 = t3[t3["reference"] == "rater events"]
        else:
            t3 = t3[t3["reference"] == "mocap"]
    t3 = t3.drop_duplicates("method").set_index("method")
    t3 = t3[t3.index.isin(PAPER_METHODS["mtst"])]          # extra rows: no published value
    pub = {m: float(t3.loc[m, "success_pct_published"]) / 100 for m in t3.index}
    rep = {m: float(t3.loc[m, "success_pct"]) / 100 for m in t3.index}
    kn = {m: _k_n(str(t3.loc[m, "success"])) for m in t3.index}
    if not rep or not all(kn.values()):
        rows.append(_row(st, "Tracking success ranking", "Table 3", "see the paper",
                         "no evaluated trials", "ranking", None,
                         "too small: no evaluated trials", "mtst_table3"))
    else:
        small = any(wilson(*kn[m])[1] - wilson(*kn[m])[0] > MAX_CI_WIDTH for m in kn)
        ok = None if small else _same_ranking(pub, rep)
        why = ("too small: the 95% CIs of the success rates span more than half the range"
               if small else "same order as the paper's." if ok else
               _broken_pairs(pub, rep, _pct) + ".")
        rows.append(_row(st, f"Tracking success ranking ({ref})", "Table 3",
                         _ranking(pub, _pct), _ranking(rep, _pct), "ranking", ok, why,
                         "mtst_table3"))
    for m in t3.index:
        r = t3.loc[m]
        k, n = kn[m] or (0, 0)
        text, ok, small = _proportion_verdict(k, n, pub[m])
        why = small or (f"the paper's {_pct(pub[m])} lies inside the interval." if ok else
                        f"{int(k)} of {int(n)} trials tracked; " + _mtst_failures(r)
                        + " (mtst_table3 notes: where the failures began).")
        rows.append(_row(st, f"Success {SHORT.get(m, m)} ({ref.split(';')[0]})", "Table 3",
                         str(r["success_published"]), text,
                         "paper inside our 95% CI", ok, why, "mtst_table3",
                         not_comparable=small))
    t4 = t.get("mtst_table4")
    if t4 is not None and "method" in t4:              # external rows: no published value
        t4 = t4[t4["method"] == "mtst_proposed"]
    if t4 is not None:
        for r in t4.itertuples(index=False):
            pp = _pct_of(str(r.success_published)) / 100
            got = _k_n(str(r.success))
            if got is None:
                rows.append(_row(st, f"{r.row.replace('_', ' ')} judged correctly", "Table 4",
                                 str(r.success_published), "no steps",
                                 "paper inside our 95% CI", None,
                                 "too small: no steps on tracked trials", "mtst_table4"))
                continue
            text, ok, small = _proportion_verdict(*got, pp)
            why = small or (f"the paper's {_pct(pp)} lies inside the interval." if ok else
                            f"{int(got[0])} of {int(got[1])} judged correctly; "
                            f"non-judgements {int(r.non_no_stick + r.non_stick)}, "
                            f"misjudgements {int(r.mis_or_false_no_stick + r.mis_or_false_stick)}"
                            " (mtst_table4 notes).")
            rows.append(_row(st, f"{r.row.replace('_', ' ')} judged correctly", "Table 4",
                             str(r.success_published), text,
                             "paper inside our 95% CI", ok, why, "mtst_table4",
                             not_comparable=small))
    return rows


# -- Rollator (Chalvatzaki et al. 2017) -------------------------------------------------------------------
def rollator_verdicts(t: dict[str, pd.DataFrame], notes: dict | None = None) -> list[dict]:
    """Chalvatzaki et al. 2017: the PF beats the KF — lower RMSE and MAD per quantity in most subject ×
    scenario cells (Table I, in the paper's cm and cm/s) and fewer error frames
    (Table II)."""
    st = "rollator"
    rows = []
    t1 = t["rollator_table1"]
    for p in dict.fromkeys(t1["parameter"]):
        d = t1[t1["parameter"] == p]
        unit = {"m": "cm", "m/s": "cm/s"}.get(str(d["unit"].iloc[0]), str(d["unit"].iloc[0]))
        for stat in ("rmse", "mad"):
            pk, pp = d[f"{stat}_kf_published"] * 100, d[f"{stat}_pf_published"] * 100
            rk, rp = d[f"{stat}_kf"] * 100, d[f"{stat}_pf"] * 100
            mp, mr = pk.notna() & pp.notna(), rk.notna() & rp.notna()
            n_pub, n_rep = int((pp < pk)[mp].sum()), int((rp < rk)[mr].sum())
            nr = int(mr.sum())
            ok = ((n_rep * 2 > nr) == (n_pub * 2 > int(mp.sum()))) if nr else None
            n_subj = int(d.loc[mr, "subject_no"].nunique())
            if not nr:
                why = "too small: no cell with both trackers' errors"
            elif n_subj < MIN_SUBJECTS_CELLS:
                ok = None
                why = (f"too small: {nr} cell(s) of {n_subj} subject; the paper's majority "
                       "is over 4 subjects × 2 scenarios")
            else:
                worse = d[mr & (rp >= rk)]
                why = (f"PF lower in {n_rep} of {nr} cells (paper {n_pub} of {int(mp.sum())})"
                       + ("; PF not lower for subject/scenario "
                          + ", ".join(f"{int(a)}/{int(b)}" for a, b in
                                      zip(worse["subject_no"], worse["scenario_no"].fillna(0)))
                          if len(worse) and not ok else "") + ".")
            rows.append(_row(
                st, f"PF {stat.upper()} < KF {stat.upper()}, {p}", "Table I",
                f"{n_pub}/{int(mp.sum())} cells; mean KF {pk[mp].mean():.2f}, PF "
                f"{pp[mp].mean():.2f} {unit}", f"{n_rep}/{nr} cells; mean KF "
                f"{rk[mr].mean():.2f}, PF {rp[mr].mean():.2f} {unit}" if nr else "no cells",
                "direction (PF lower in most cells)", ok, why, "rollator_table1"))
    t2 = t.get("rollator_table2")
    if t2 is not None:
        s = t2.groupby("tracker")[["error_frames", "error_frames_published",
                                   "evaluated_frames"]].sum()
        if {"KF", "PF"} <= set(s.index):
            pub_ok = s.loc["PF", "error_frames_published"] < s.loc["KF", "error_frames_published"]
            rep_ok = s.loc["PF", "error_frames"] < s.loc["KF", "error_frames"]
            why = (f"PF {int(s.loc['PF', 'error_frames'])} of "
                   f"{int(s.loc['PF', 'evaluated_frames'])} evaluated frames, KF "
                   f"{int(s.loc['KF', 'error_frames'])} of {int(s.loc['KF', 'evaluated_frames'])}"
                   " (rollator_table2 notes: the error-frame rule).")
            rows.append(_row(st, "PF fewer error frames than KF (all cells)", "Table II",
                             f"KF {int(s.loc['KF', 'error_frames_published'])}, PF "
                             f"{int(s.loc['PF', 'error_frames_published'])}",
                             f"KF {int(s.loc['KF', 'error_frames'])}, PF "
                             f"{int(s.loc['PF', 'error_frames'])}", "direction",
                             rep_ok == pub_ok, why, "rollator_table2"))
    return rows


BUILDERS = {"tug": tug_verdicts, "mtst": mtst_verdicts, "rollator": rollator_verdicts,
            "ultrasonic": ultrasonic_verdicts}


def _notes(md: Path) -> list[str]:
    if not md.is_file():
        return []
    return [ln[2:] for ln in md.read_text(encoding="utf-8").splitlines()[1:]
            if ln.startswith("- ")]


def build_verdicts(tables_dir: str | Path, data: dict[str, str] | None = None,
                   physics: list[Path] | None = None) -> pd.DataFrame:
    """Every verdict of the studies whose tables are in ``tables_dir`` (see module notes).

    Parameters
    ----------
    tables_dir : path
        ``<reports>/tables``.
    data : mapping, optional
        Paper (``tug``, ``mtst``, ``rollator``, ``ultrasonic``) → what its data are
        (:func:`gaitval.report.datakind.paper_data`); the ``data`` column.
    physics : list of path, optional
        The run's simulated studies' ``physics.csv``: the TUG occlusion verdicts show the
        twin's truth occlusion beside the tracker-counted one they compare.

    Returns
    -------
    DataFrame
        Columns :data:`VERDICT_COLUMNS`; ``table`` is the stem of the table whose notes
        explain a difference (its anchor in the report).  A study whose tables are absent
        has one row with outcome ``not run``.
    """
    td = Path(tables_dir)
    tables = {p.stem: pd.read_csv(p) for p in sorted(td.glob("*.csv"))}
    notes = {stem: _notes(td / f"{stem}.md") for stem in NOT_COMPARABLE_NOTE}
    rows = []
    for study, need in REQUIRED.items():
        if need not in tables:
            rows.append(_row(study, "all comparisons of the paper", need, "see the paper",
                             "not run", "study not in `run`", None,
                             "no study of the run has this protocol", ""))
            rows[-1]["outcome"] = "not run"
            continue
        if tables[need].empty:        # every trial of the protocol refused at registration
            rows.append(_row(study, "all comparisons of the paper", need, "see the paper",
                             "no trial analysed", None, None,
                             "no trial of this protocol was analysed: every one was refused "
                             "at registration (the report's top box says why)", ""))
            rows[-1]["data"] = (data or {}).get(study, "")
            continue
        got = (BUILDERS[study](tables, notes, physics) if study == "tug"
               else BUILDERS[study](tables, notes))
        for r in got:
            r["data"] = (data or {}).get(study, "")
        rows += got
    out = pd.DataFrame(rows, columns=list(VERDICT_COLUMNS))
    out["robustness"] = share_column(out, td)
    return out


def summary_lines(v: pd.DataFrame) -> list[str]:
    """One sentence per study: reproduced of the comparable comparisons, and how many were
    not comparable (never counted as not reproduced)."""
    out = []
    for study, g in v.groupby("study", sort=False):
        name = STUDIES.get(study, study)
        if (g["outcome"] == "not run").all():
            out.append(f"{name}: not run.")
            continue
        c = g["outcome"].value_counts()
        yes, no, nc = (int(c.get(k, 0)) for k in ("reproduced", "not reproduced",
                                                   "not comparable"))
        data = str(g["data"].iloc[0])
        line = (f"{name}: {yes} of {yes + no} comparable comparisons reproduced"
                if yes + no else f"{name}: no comparison could be scored")
        line += f"; {nc} not comparable" if nc else ""
        line += f" — on {data}." if data else "."
        out.append(line)
    return out
