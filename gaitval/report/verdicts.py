"""The verdict page: one row per published comparison, reproduced or not.

Each row states a comparison one of the seed papers makes — a ranking of methods, the
direction of an effect, or a value with its published spread — the published numbers, the
reproduced numbers, whether the reproduction goes the same way (``yes``/``no``; ``not run``
when the study's tables are absent) and the report anchor of the table whose notes explain
a difference.  Everything is read from the tables' CSVs (``<reports>/tables/*.csv``), which
already carry the published values beside the reproduced ones, so no number here is typed
by hand and a rerun updates the page.

Criteria (column ``criterion``):

* ranking — the reproduced order of the methods equals the published order;
* direction — the sign of the published difference holds in the reproduction;
* value with spread — the reproduced value lies within the published mean ± 1 SD (or, for
  a published proportion, inside the Wilson 95% interval of the reproduced proportion).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000, TUG).
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (seed 001, MTST).
Chalvatzaki, G. et al. ICRA 2017 (seed 002, robotic rollator).
Qi, Y. et al. Sensors 2014, 14(8), 15434–15457 (seed 003, ultrasonic).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

#: Columns of :func:`build_verdicts`.
VERDICT_COLUMNS = ("study", "comparison", "source", "published", "reproduced", "criterion",
                   "reproduced_in_direction", "note")
STUDIES = {"tug": "TUG leg tracking (seed 000)", "mtst": "MTST (seed 001)",
           "rollator": "Robotic rollator (seed 002)", "ultrasonic": "Ultrasonic (seed 003)"}
#: The table each study's verdicts need; absent → one ``not run`` row.
REQUIRED = {"tug": "tug_table3", "mtst": "mtst_table3", "rollator": "rollator_table1",
            "ultrasonic": "ultrasonic_table8"}
SHORT = {"tug_m1": "M1", "tug_m2": "M2", "tug_m3": "M3", "mtst_m1": "M1", "mtst_m2": "M2",
         "mtst_m3": "M3", "mtst_proposed": "proposed"}


def _yn(ok) -> str:
    if ok is None or (isinstance(ok, float) and math.isnan(ok)):
        return "undecided"
    return "yes" if bool(ok) else "no"


def wilson(k: float, n: float, z: float = 1.959964) -> tuple[float, float]:
    """Wilson score 95% interval of the proportion ``k/n`` (NaN, NaN when ``n`` is 0)."""
    if not n:
        return (np.nan, np.nan)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (c - h, c + h)


def _row(study, comparison, source, published, reproduced, criterion, ok, note=None) -> dict:
    return {"study": study, "comparison": comparison, "source": source,
            "published": published, "reproduced": reproduced, "criterion": criterion,
            "reproduced_in_direction": _yn(ok), "note": note or source}


def _order(values: dict[str, float], higher_first: bool = True) -> list[str]:
    keys = list(values)
    return sorted(keys, key=lambda m: ((-values[m] if higher_first else values[m]),
                                       keys.index(m)))


def _ranking(values: dict[str, float], fmt: str, higher_first=True) -> str:
    """``"M3 0.96 > M2 0.89 = M1 0.89"`` (ties, at the printed precision, as ``=``)."""
    order = _order(values, higher_first)
    out = ""
    for i, m in enumerate(order):
        if i:
            tie = format(values[m], fmt) == format(values[order[i - 1]], fmt)
            out += " = " if tie else (" > " if higher_first else " < ")
        out += f"{SHORT.get(m, m)} {format(values[m], fmt)}"
    return out


def _same_ranking(pub: dict[str, float], rep: dict[str, float]) -> bool:
    """Every pair the paper ranks strictly is ranked the same way, strictly."""
    ms = [m for m in pub if m in rep]
    return all(np.sign(pub[a] - pub[b]) == np.sign(rep[a] - rep[b])
               for i, a in enumerate(ms) for b in ms[i + 1:] if pub[a] != pub[b])


def tug_verdicts(t: dict[str, pd.DataFrame]) -> list[dict]:
    """Seed 000: success ranking and per-method success (Table 3, each reading of
    eq. (3)–(4)); Method 3 below Method 2 in turning-phase (Table 4) and unobservable
    (Table 5) RMSE."""
    st = "tug"
    rows = []
    t3 = t["tug_table3"]
    if "phase_reading" not in t3:
        t3 = t3.assign(phase_reading="swing_first", base_method=t3["method"])
    for reading, g in t3.groupby("phase_reading", sort=False):
        g = g.set_index("base_method")
        pub = {m: float(g.loc[m, "success_rate_published"]) for m in g.index}
        rep = {m: float(g.loc[m, "success_rate"]) for m in g.index}
        rows.append(_row(st, f"Tracking success ranking, reading {reading} of eq. (3)-(4)",
                         "Table 3", _ranking(pub, ".2f"), _ranking(rep, ".2f"),
                         "ranking", _same_ranking(pub, rep), "tug_table3"))
        for m in g.index:
            r = g.loc[m]
            lo, hi = wilson(r["n_success"], r["n_trials"])
            rows.append(_row(
                st, f"Success rate {SHORT.get(m, m)}, reading {reading}", "Table 3",
                f"{int(r['n_success_published'])}/{int(r['n_trials_published'])} = "
                f"{r['success_rate_published']:.2f}",
                f"{int(r['n_success'])}/{int(r['n_trials'])} = {r['success_rate']:.2f} "
                f"(95% CI {lo:.2f}-{hi:.2f})", "published inside reproduced 95% CI",
                lo <= r["success_rate_published"] <= hi, "tug_table3"))
    for name, key, val, label in (("tug_table4", "tug_phase", "turning",
                                   "Turning-phase RMSE M3 < M2 (x, y)"),
                                  ("tug_table5", "observation_state", "unobservable",
                                   "Unobservable-step RMSE M3 < M2 (x, y)")):
        d = t.get(name)
        if d is None:
            continue
        d = d[(d[key] == val) & (d.get("phase_reading", "swing_first") == "swing_first")]
        d = d.set_index("method")
        if not {"tug_m2", "tug_m3"} <= set(d.index):
            continue
        a, b = d.loc["tug_m3"], d.loc["tug_m2"]
        fmt = ("x {:.3f} vs {:.3f}, y {:.3f} vs {:.3f} m").format
        ok = (a.rmse_x_m < b.rmse_x_m and a.rmse_y_m < b.rmse_y_m
              if np.isfinite([a.rmse_x_m, b.rmse_x_m]).all() else None)
        rows.append(_row(st, label, f"Table {name[-1]}",
                         fmt(a.rmse_x_m_published, b.rmse_x_m_published,
                             a.rmse_y_m_published, b.rmse_y_m_published),
                         fmt(a.rmse_x_m, b.rmse_x_m, a.rmse_y_m, b.rmse_y_m)
                         if ok is not None else "no successful trial", "direction", ok,
                         name))
    return rows


def mtst_verdicts(t: dict[str, pd.DataFrame]) -> list[dict]:
    """Seed 001: success ranking of Methods 1-3 and the proposed method (Table 3, mocap
    reference; the rater events' where no trial has mocap), and target-step judgement
    success (Table 4)."""
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
    pub = {m: float(t3.loc[m, "success_pct_published"]) for m in t3.index}
    rep = {m: float(t3.loc[m, "success_pct"]) for m in t3.index}
    if not rep:
        rows.append(_row(st, "Tracking success ranking", "Table 3", "see the paper",
                         "no evaluated trials", "ranking", None, "mtst_table3"))
    else:
        rows.append(_row(st, f"Tracking success ranking ({ref})", "Table 3",
                         _ranking(pub, ".1f") + " %", _ranking(rep, ".1f") + " %", "ranking",
                         _same_ranking(pub, rep), "mtst_table3"))
    for m in t3.index:
        r = t3.loc[m]
        rows.append(_row(st, f"Success {SHORT.get(m, m)}", "Table 3",
                         str(r["success_published"]), str(r["success"]),
                         "published inside reproduced 95% CI",
                         _pct_inside(str(r["success"]), pub[m]), "mtst_table3"))
    t4 = t.get("mtst_table4")
    if t4 is not None:
        for r in t4.itertuples(index=False):
            pp = _pct_of(str(r.success_published))
            rows.append(_row(st, f"{r.row.replace('_', ' ')} judged correctly", "Table 4",
                             str(r.success_published), str(r.success) if str(r.success)
                             not in ("", "nan") else "no steps", "published inside "
                             "reproduced 95% CI", _pct_inside(str(r.success), pp),
                             "mtst_table4"))
    return rows


def _pct_of(s: str) -> float:
    try:
        return float(s.split("%")[0])
    except ValueError:
        return np.nan


def _pct_inside(s: str, published_pct: float):
    """Is ``published_pct`` inside the Wilson interval of a ``"x% (k/n)"`` string?"""
    try:
        k, n = s.split("(")[1].split(")")[0].split("/")
        lo, hi = wilson(float(k), float(n))
    except (IndexError, ValueError):
        return None
    return lo * 100 <= published_pct <= hi * 100


def rollator_verdicts(t: dict[str, pd.DataFrame]) -> list[dict]:
    """Seed 002: the PF beats the KF — lower RMSE and MAD per quantity (Table I, count of
    subject × scenario cells) and fewer error frames (Table II)."""
    st = "rollator"
    rows = []
    t1 = t["rollator_table1"]
    for p in dict.fromkeys(t1["parameter"]):
        d = t1[t1["parameter"] == p]
        for stat in ("rmse", "mad"):
            pk, pp = d[f"{stat}_kf_published"], d[f"{stat}_pf_published"]
            rk, rp = d[f"{stat}_kf"], d[f"{stat}_pf"]
            mp, mr = pk.notna() & pp.notna(), rk.notna() & rp.notna()
            n_pub, n_rep = int((pp < pk)[mp].sum()), int((rp < rk)[mr].sum())
            rows.append(_row(
                st, f"PF {stat.upper()} < KF {stat.upper()}, {p}", "Table I",
                f"{n_pub}/{int(mp.sum())} cells; mean KF {pk[mp].mean():.3f}, PF "
                f"{pp[mp].mean():.3f}", f"{n_rep}/{int(mr.sum())} cells; mean KF "
                f"{rk[mr].mean():.3f}, PF {rp[mr].mean():.3f}",
                "direction (PF lower in most cells)",
                (n_rep * 2 > int(mr.sum())) == (n_pub * 2 > int(mp.sum())) if mr.any()
                else None, "rollator_table1"))
    t2 = t.get("rollator_table2")
    if t2 is not None:
        s = t2.groupby("tracker")[["error_frames", "error_frames_published"]].sum()
        if {"KF", "PF"} <= set(s.index):
            pub_ok = s.loc["PF", "error_frames_published"] < s.loc["KF", "error_frames_published"]
            rep_ok = s.loc["PF", "error_frames"] < s.loc["KF", "error_frames"]
            rows.append(_row(st, "PF fewer error frames than KF (all cells)", "Table II",
                             f"KF {int(s.loc['KF', 'error_frames_published'])}, PF "
                             f"{int(s.loc['PF', 'error_frames_published'])}",
                             f"KF {int(s.loc['KF', 'error_frames'])}, PF "
                             f"{int(s.loc['PF', 'error_frames'])}", "direction",
                             rep_ok == pub_ok, "rollator_table2"))
    return rows


_SPEED_ORDER = ("slow", "normal", "fast")


def _p(p: float) -> str:
    if not np.isfinite(p):
        return "n/a"
    return "< 0.001" if p < 0.001 else f"{p:.3f}"


def ultrasonic_verdicts(t: dict[str, pd.DataFrame]) -> list[dict]:
    """Seed 003: pendulum bias within its spread (Table 1); the system's stride parameters
    at normal speed within the published mean ± SD (Table 8); the direction of the speed
    effects (Table 8); normality (Table 7) and no subject effect (Table C1)."""
    st = "ultrasonic"
    rows = []
    t1 = t.get("ultrasonic_table1")
    if t1 is not None:
        for r in t1.itertuples(index=False):
            rows.append(_row(st, f"Pendulum error, {r.axis} axis: mean within ± SD",
                             "Table 1", f"{r.mean_mm_published:.2f} ± "
                             f"{r.std_mm_published:.2f} mm", f"{r.mean_mm:.2f} ± "
                             f"{r.std_mm:.2f} mm", "value inside published mean ± SD",
                             abs(r.mean_mm - r.mean_mm_published) <= r.std_mm_published,
                             "ultrasonic_table1"))
    t8 = t["ultrasonic_table8"]
    pro = t8[t8["quantity"] == "pro"]
    for r in pro.itertuples(index=False):
        unit = "" if r.unit == "-" else f" {r.unit}"
        rows.append(_row(st, f"{r.symbol} ({r.parameter}) at normal speed", "Table 8",
                         f"{r.normal_mean_published:.3f} ± {r.normal_std_published:.3f}"
                         f"{unit}", f"{r.normal_mean:.3f} ± {r.normal_std:.3f}{unit}",
                         "value inside published mean ± SD",
                         abs(r.normal_mean - r.normal_mean_published)
                         <= r.normal_std_published, "ultrasonic_table8"))
        pub = {s: getattr(r, f"{s}_mean_published") for s in _SPEED_ORDER}
        rep = {s: getattr(r, f"{s}_mean") for s in _SPEED_ORDER}
        sig_pub = [getattr(r, f"{s}_p_published") < 0.05 for s in ("slow", "fast")]
        sig_rep = [getattr(r, f"{s}_p") < 0.05 for s in ("slow", "fast")]

        def trend(v, sig):
            out = []
            for s, ok in zip(("slow", "fast"), sig):
                rel = "<" if v[s] < v["normal"] else ">"
                out.append(f"{s} {rel} normal{'*' if ok else ''}")
            return ", ".join(out)
        same = all((np.sign(pub[s] - pub["normal"]) == np.sign(rep[s] - rep["normal"]))
                   and (a == b) for s, a, b in zip(("slow", "fast"), sig_pub, sig_rep))
        rows.append(_row(st, f"{r.symbol}: effect of speed (* p < 0.05)", "Table 8",
                         trend(pub, sig_pub), trend(rep, sig_rep),
                         "direction and significance", same, "ultrasonic_table8"))
    t7 = t.get("ultrasonic_table7")
    if t7 is not None:
        for r in t7.itertuples(index=False):
            known = np.isfinite([r.H, r.H_published]).all()
            rows.append(_row(st, f"{r.symbol} normally distributed (Lilliefors)", "Table 7",
                             f"H = {r.H_published:.0f}", f"H = {r.H:.0f} (p {_p(r.p)})"
                             if known else "too few strides", "same test decision",
                             int(r.H) == int(r.H_published) if known else None,
                             "ultrasonic_table7"))
    c1 = t.get("ultrasonic_tableC1")
    if c1 is not None:
        for r in c1[c1["source"] == "between"].itertuples(index=False):
            rows.append(_row(st, f"{r.symbol}: no difference between subjects (ANOVA)",
                             "Table C1", f"F {r.F_published:.2f}, p {r.p_published:.3f}",
                             f"F {r.F:.2f}, p {_p(r.p)}", "same test decision at 0.05",
                             (r.p < 0.05) == (r.p_published < 0.05) if np.isfinite(r.p) else None,
                             "ultrasonic_tableC1"))
    return rows


BUILDERS = {"tug": tug_verdicts, "mtst": mtst_verdicts, "rollator": rollator_verdicts,
            "ultrasonic": ultrasonic_verdicts}


def build_verdicts(tables_dir: str | Path) -> pd.DataFrame:
    """Every verdict of the studies whose tables are in ``tables_dir`` (see module notes).

    Returns
    -------
    DataFrame
        Columns :data:`VERDICT_COLUMNS`; ``note`` is the stem of the table whose notes
        explain a difference (its anchor in the report).  A study whose tables are absent
        has one row with ``reproduced = "not run"``.
    """
    td = Path(tables_dir)
    tables = {p.stem: pd.read_csv(p) for p in sorted(td.glob("*.csv"))}
    rows = []
    for study, need in REQUIRED.items():
        if need not in tables:
            rows.append(_row(study, "all comparisons of the paper", need, "see the paper",
                             "not run", "study not in `run`", None, ""))
            rows[-1]["reproduced_in_direction"] = "not run"
            continue
        rows += BUILDERS[study](tables)
    return pd.DataFrame(rows, columns=list(VERDICT_COLUMNS))


def summary_lines(v: pd.DataFrame) -> list[str]:
    """One sentence per study: how many comparisons were reproduced."""
    out = []
    for study, g in v.groupby("study", sort=False):
        if (g["reproduced_in_direction"] == "not run").all():
            out.append(f"{STUDIES.get(study, study)}: not run.")
            continue
        yes = int((g["reproduced_in_direction"] == "yes").sum())
        n = int(g["reproduced_in_direction"].isin(["yes", "no"]).sum())
        out.append(f"{STUDIES.get(study, study)}: {yes} of {n} comparisons reproduced.")
    return out
