"""The ultrasonic verdicts (Qi et al. 2014; :mod:`gaitval.report.verdicts`): the pendulum's
error per axis (Table 1), the stride parameters at normal speed (Table 8), the speed
effects, normality and the subject effect.

References
----------
Qi, Y. et al. Sensors 2014, 14(8), 15434–15457 (Qi et al. 2014, ultrasonic).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from gaitval.report.verdicts_common import (MIN_SUBJECTS_T, NOT_COMPARABLE_NOTE, _row)
from gaitval.tables.numbers import number, p_value

# -- Ultrasonic (Qi et al. 2014) -----------------------------------------------------------------
_SPEED_ORDER = ("slow", "normal", "fast")


def _says(notes: dict | None, table: str) -> bool:
    """Does ``table``'s notes call its numbers not comparable (:data:`NOT_COMPARABLE_NOTE`)?"""
    phrase = NOT_COMPARABLE_NOTE[table].lower()
    return any(phrase in n.lower() for n in (notes or {}).get(table, []))


def _pm(mean: float, sd: float, unit: str = "") -> str:
    """``mean ± sd`` with decimals that give the SD two significant figures (at least the
    paper's three), never e-notation."""
    dec = 3
    if np.isfinite(sd) and sd > 0:
        dec = min(max(3, 1 - math.floor(math.log10(abs(sd)))), 8)
    u = f" {unit}" if unit and unit != "-" else ""
    return f"{mean:.{dec}f} ± {sd:.{dec}f}{u}".replace("-0.000 ", "0.000 ")


def _ns_nv_reason(t8: pd.DataFrame, sym: str) -> str:
    """NS, NV divide S, V by the number of strides n: the n each side implies."""
    base = {"NS": "S", "NV": "V"}[sym]
    pro = t8[t8["quantity"] == "pro"].set_index("symbol")
    if base not in pro.index or sym not in pro.index:
        return "NS and NV compare definitions of n, not accuracy (Table 8 note)."
    n_rep = f"{pro.loc[base, 'normal_mean'] / pro.loc[sym, 'normal_mean']:.0f}"
    if "normal_n" in pro.columns:
        # one number, or a range ("9-10") where the subjects' stride counts differ
        given = str(pro.loc[sym, "normal_n"]).strip()
        num = pd.to_numeric(given, errors="coerce")
        n_rep = f"{float(num):.0f}" if np.isfinite(num) else (given or n_rep)
    n_pub = pro.loc[base, "normal_mean_published"] / pro.loc[sym, "normal_mean_published"]
    return (f"{sym} = {base}/n: gaitval divides by the {n_rep} strides per subject it "
            f"samples (the paper's Tables 2-6 sample size), the paper's values imply "
            f"n ≈ {n_pub:.0f} at normal speed; the rows compare definitions of n, not "
            "accuracy (Table 8 note).")


#: Qi et al. 2014: ten subjects walked on the treadmill (Table 8's SDs are over them).
PAPER_SUBJECTS_US = 10


def sd_interval(sd_paper: float, n_paper: int, n_ours: int, level: float = 0.95
                ) -> tuple[float, float]:
    """The SDs of ``n_ours`` values that the two-sided F-test of two variances (``level``)
    does not tell apart from the paper's ``sd_paper`` of ``n_paper`` values: both are
    sample SDs, so neither is the population's."""
    from scipy import stats

    a = (1 - level) / 2
    lo = stats.f.ppf(a, n_ours - 1, n_paper - 1)
    hi = stats.f.ppf(1 - a, n_ours - 1, n_paper - 1)
    return float(sd_paper * np.sqrt(lo)), float(sd_paper * np.sqrt(hi))


#: Table 1's SD per axis: the reproduced within this factor of the paper's, either way.
#: The paper gives no count of independent samples (the errors are autocorrelated along
#: the swing), so no sampling interval of its SD exists; 1.5 is the twin's tolerance for
#: the same SD in physics.csv (``pendulum_error_sd``), stated before the twin was changed.
PENDULUM_SD_FACTOR = 1.5


def _pendulum_row(r) -> dict:
    """One axis of Table 1: the mean error within the paper's ± SD, and the SD within
    :data:`PENDULUM_SD_FACTOR` of the paper's."""
    dev = abs(r.mean_mm - r.mean_mm_published)
    mean_ok = dev <= r.std_mm_published
    lo, hi = r.std_mm_published / PENDULUM_SD_FACTOR, r.std_mm_published * PENDULUM_SD_FACTOR
    sd_ok = bool(lo <= r.std_mm <= hi)
    return _row("ultrasonic", f"Pendulum error, {r.axis} axis: mean and SD", "Table 1",
                f"{r.mean_mm_published:.2f} ± {r.std_mm_published:.2f} mm",
                f"{r.mean_mm:.2f} ± {r.std_mm:.2f} mm",
                f"mean inside published mean ± SD; SD within a factor {PENDULUM_SD_FACTOR}",
                mean_ok and sd_ok,
                f"mean differs from the paper's by {dev:.2f} mm, "
                f"{'within' if mean_ok else 'more than'} its SD {r.std_mm_published:.2f} mm; "
                f"the SD {r.std_mm:.2f} mm is {'inside' if sd_ok else 'outside'} "
                f"{lo:.2f}–{hi:.2f} mm.", "ultrasonic_table1")


def ultrasonic_verdicts(t: dict[str, pd.DataFrame], notes: dict | None = None) -> list[dict]:
    """Qi et al. 2014: pendulum bias within its spread and its SD (Table 1); the system's stride parameters
    at normal speed within the published mean ± SD (Table 8); the direction of the speed
    effects (Table 8); normality (Table 7) and no subject effect (Table C1)."""
    st = "ultrasonic"
    rows = []
    t1 = t.get("ultrasonic_table1")
    if t1 is not None:
        rows += [_pendulum_row(r) for r in t1.itertuples(index=False)]
    t8 = t["ultrasonic_table8"]
    ns_nv = _says(notes, "ultrasonic_table8")
    pro = t8[t8["quantity"] == "pro"]
    for r in pro.itertuples(index=False):
        unit = str(r.unit)
        nc = _ns_nv_reason(t8, r.symbol) if ns_nv and r.symbol in ("NS", "NV") else None
        small = None if np.isfinite(r.normal_std) else \
            "too small: fewer than two subjects, no standard deviation"
        dev = abs(r.normal_mean - r.normal_mean_published)
        mean_ok = dev <= r.normal_std_published
        # the SD over subjects too: not told apart from the published one by an F-test
        n_us = int(getattr(r, "n_subjects", PAPER_SUBJECTS_US))
        lo, hi = (sd_interval(r.normal_std_published, PAPER_SUBJECTS_US, n_us)
                  if n_us >= 2 else (np.nan, np.nan))
        sd_ok = bool(lo <= r.normal_std <= hi) if np.isfinite(r.normal_std) else False
        ok = mean_ok and sd_ok
        u = "" if unit == "-" else " " + unit
        rows.append(_row(st, f"{r.symbol} ({r.parameter}) at normal speed", "Table 8",
                         _pm(r.normal_mean_published, r.normal_std_published, unit),
                         _pm(r.normal_mean, r.normal_std, unit),
                         "mean inside published mean ± SD; SDs equal by an F-test "
                         "(95 %)", ok,
                         f"mean differs from the paper's by {number(dev)}{u}, "
                         f"{'within' if mean_ok else 'more than'} its SD "
                         f"{number(r.normal_std_published)}; the SD over subjects "
                         f"{number(r.normal_std)}{u} is {'inside' if sd_ok else 'outside'} "
                         f"{number(lo)}–{number(hi)}{u} (F-test of the two SDs, "
                         f"{n_us} and 10 subjects).", "ultrasonic_table8",
                         not_comparable=nc or small))
        pub = {s: getattr(r, f"{s}_mean_published") for s in _SPEED_ORDER}
        rep = {s: getattr(r, f"{s}_mean") for s in _SPEED_ORDER}
        p_pub = {s: getattr(r, f"{s}_p_published") for s in ("slow", "fast")}
        p_rep = {s: getattr(r, f"{s}_p") for s in ("slow", "fast")}

        def trend(v, p):
            return ", ".join(f"{s} {'<' if v[s] < v['normal'] else '>'} normal"
                             f"{'*' if p[s] < 0.05 else ''} (p {p_value(p[s])})"
                             for s in ("slow", "fast"))
        same = all((np.sign(pub[s] - pub["normal"]) == np.sign(rep[s] - rep["normal"]))
                   and ((p_pub[s] < 0.05) == (p_rep[s] < 0.05)) for s in ("slow", "fast"))
        n_subj = int(getattr(r, "n_subjects", MIN_SUBJECTS_T))
        small_t = (None if np.isfinite(list(p_rep.values())).all()
                   and n_subj >= MIN_SUBJECTS_T else
                   f"too small: a paired t-test on {n_subj} subject(s) has "
                   f"{max(n_subj - 1, 0)} degree(s) of freedom (the paper: 10 subjects)")
        differ = [s for s in ("slow", "fast")
                  if not ((np.sign(pub[s] - pub["normal"]) == np.sign(rep[s] - rep["normal"]))
                          and ((p_pub[s] < 0.05) == (p_rep[s] < 0.05)))]
        why = ("direction and significance as the paper's at both speeds." if same else
               "differs at " + " and ".join(differ) + " speed: "
               + "; ".join(f"{s} {number(rep[s])} vs normal {number(rep['normal'])}, "
                           f"p {p_value(p_rep[s])} (paper {number(pub[s])} vs "
                           f"{number(pub['normal'])}, p {p_value(p_pub[s])})"
                           for s in differ) + ".")
        rows.append(_row(st, f"{r.symbol}: effect of speed (* p < 0.05)", "Table 8",
                         trend(pub, p_pub), trend(rep, p_rep), "direction and significance",
                         same, why, "ultrasonic_table8", not_comparable=nc or small_t))
    t7 = t.get("ultrasonic_table7")
    if t7 is not None:
        nc7 = _says(notes, "ultrasonic_table7")
        for r in t7.itertuples(index=False):
            known = np.isfinite([r.H, r.H_published]).all()
            said = str(getattr(r, "comparability", "") or "")
            if said.lower().startswith("not comparable"):         # the table's own word
                nc7 = True
            reason = (f"the paper's H = {r.H_published:.0f}, p = {r.p_published:.3f} test "
                      "'mean is zero', not normality; gaitval's Lilliefors test gives "
                      f"H = {r.H:.0f}, p {p_value(r.p)} (Table 7 note)." if nc7 and known
                      else None if known else "too small: too few strides for the test")
            rows.append(_row(st, f"{r.symbol} normally distributed (Lilliefors)", "Table 7",
                             f"H = {r.H_published:.0f}", f"H = {r.H:.0f} (p {p_value(r.p)})"
                             if known else "too few strides", "same test decision",
                             int(r.H) == int(r.H_published) if known else None,
                             f"H = {r.H:.0f} against the paper's {r.H_published:.0f}."
                             if known else "", "ultrasonic_table7", not_comparable=reason))
    c1 = t.get("ultrasonic_tableC1")
    if c1 is not None:
        ncc = _says(notes, "ultrasonic_tableC1")
        between = c1[c1["source"] == "between"]
        if "grouping" not in between.columns:
            between = between.assign(grouping="subject")
        # one primary reading, the paper's words ("between subjects"); the other reading of
        # its groups (the stride index, which its numbers imply) beside it, not counted
        alt = {r.symbol: r for r in between[between["grouping"] != "subject"]
               .itertuples(index=False)}
        for r in between[between["grouping"] == "subject"].itertuples(index=False):
            known = np.isfinite(r.p) and np.isfinite(r.F)
            reason = (f"the paper says it groups by subject, but its numbers cannot come "
                      f"from that grouping (its own Tables 2-4 imply F >> 1; gaitval: F "
                      f"{r.F:.2f}); they match grouping by stride index (Table C1 note)."
                      if ncc and known else None if known else
                      f"too small: F is undefined with {int(r.df) + 1 if np.isfinite(r.df) else 'too few'} "
                      "subject group(s)")
            ok = (r.p < 0.05) == (r.p_published < 0.05) if known else None
            row = _row(st, f"{r.symbol}: no difference between subjects (ANOVA)",
                       "Table C1", f"F {r.F_published:.2f}, p {p_value(r.p_published)}",
                       f"F {r.F:.2f}, p {p_value(r.p)}" if known else "F undefined",
                       "same test decision at 0.05", ok,
                       f"p {p_value(r.p)} against the paper's {p_value(r.p_published)}.",
                       "ultrasonic_tableC1", not_comparable=reason)
            a = alt.get(r.symbol)
            if a is not None and np.isfinite(a.p) and np.isfinite(a.F):
                a_ok = (a.p < 0.05) == (a.p_published < 0.05)
                row["alternative"] = (f"groups = stride index: F {a.F:.2f}, p {p_value(a.p)} "
                                      f"({'reproduced' if a_ok else 'not reproduced'}, "
                                      "not counted)")
            rows.append(row)
    return rows
