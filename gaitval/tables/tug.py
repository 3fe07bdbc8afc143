"""Yorozu et al. 2015a Tables 2–5 from per-trial TUG evaluations, with the published values beside.

Inputs are the outputs of :func:`gaitval.evaluate.tug.evaluate_tug_trial` concatenated
over trials and methods: ``summaries`` (one row per trial and method) and ``frames``
(one row per scan and side).  Nothing is recomputed from raw data here; every number is
a count or an RMSE over those per-trial files.

Published values (transcribed from Yorozu, Moriguchi & Takahashi, Sensors 2015, 15,
22451–22472): Table 2 (parameters, :data:`PUBLISHED_T2`), Table 3 (false tracking and
success counts of 28 trials, :data:`PUBLISHED_T3`), Table 4 (occlusion rate and RMSE per
TUG phase, tracking-success data of Methods 2 and 3, :data:`PUBLISHED_T4`), Table 5 (RMSE
per leg observation state, :data:`PUBLISHED_T5`).  Method 1 has no published Table 4/5 values (NaN).
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.methods import (METHOD_DEFINITIONS, METHODS, changed_parameters, display_name,
                             get_method)
from gaitval.stats.summary import rmse
from gaitval.tables.render import write_table
from gaitval.tables.tug_evidence import DEFAULT_READING, failure_evidence, method_reading

CITATION = ("Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait "
            "Phase and Spline-Based Interpolation during Turning Motion in Walk Tests. "
            "Sensors 2015, 15, 22451-22472")

#: Yorozu et al. 2015a Table 2
PUBLISHED_T2 = {"dt_s": 0.025, "q_accel_sd_mps2": 15.0, "r_sd_m": 0.04, "v_st_th_mps": 0.47,
                "v_sw_th_mps": 0.93, "gate_g": 13.82, "n_ac": 40}

#: Yorozu et al. 2015a Table 3 (28 trials)
PUBLISHED_T3 = {
    "tug_m1": {"ft_turning": 12, "ft_return": 0, "sf_turning": 2, "n_success": 14,
               "n_trials": 28},
    "tug_m2": {"ft_turning": 0, "ft_return": 2, "sf_turning": 1, "n_success": 25,
               "n_trials": 28},
    "tug_m3": {"ft_turning": 0, "ft_return": 1, "sf_turning": 0, "n_success": 27,
               "n_trials": 28},
}

#: Yorozu et al. 2015a Table 4: (n_uo, n_steps, rmse_x, rmse_y) per TUG phase
PUBLISHED_T4 = {
    "tug_m2": {"forward": (225, 6364, 0.042, 0.018), "turning": (255, 2264, 0.069, 0.062),
               "return": (344, 6686, 0.053, 0.028), "total": (824, 15314, 0.051, 0.032)},
    "tug_m3": {"forward": (264, 6912, 0.042, 0.019), "turning": (304, 2462, 0.055, 0.049),
               "return": (402, 7294, 0.047, 0.025), "total": (970, 16668, 0.047, 0.028)},
}
PUBLISHED_T4_SUCCESS = {"tug_m2": 25, "tug_m3": 27}

#: Yorozu et al. 2015a Table 5: (time steps, rmse_x, rmse_y) per leg observation state
PUBLISHED_T5 = {
    "tug_m2": {"observable": (14490, 0.047, 0.027), "unobservable": (824, 0.102, 0.081)},
    "tug_m3": {"observable": (15698, 0.045, 0.025), "unobservable": (970, 0.066, 0.052)},
}

PHASES = ("forward", "turning", "return")


def _int_or_blank(values) -> pd.Series:
    """Counts with gaps as Python ints / None (renders as "25" and "", not "25.000")."""
    return pd.Series([None if v is None or (isinstance(v, float) and np.isnan(v)) else int(v)
                      for v in values], dtype=object)


def _tidy_counts(df: pd.DataFrame, cols) -> pd.DataFrame:
    for c in cols:
        if c in df:
            df[c] = _int_or_blank(df[c].tolist())
    return df


#: Table 4's and Table 5's columns (so a run whose every trial was refused at
#: registration still gets the tables, with no row)
T4_COLUMNS = ["method", "base_method", "phase_reading", "label", "tug_phase",
              "n_success_trials", "n_success_trials_published", "n_uo", "n_steps",
              "occlusion_rate", "n_uo_published", "n_steps_published",
              "occlusion_rate_published", "rmse_x_m", "rmse_x_m_published", "rmse_y_m",
              "rmse_y_m_published"]
T5_COLUMNS = ["method", "label", "observation_state", "time_steps", "time_steps_published",
              "rmse_x_m", "rmse_x_m_published", "rmse_y_m", "rmse_y_m_published"]


def _concat(x) -> pd.DataFrame:
    if isinstance(x, pd.DataFrame):
        return x
    x = [d for d in x if d is not None and len(d)]
    return pd.concat(x, ignore_index=True) if x else pd.DataFrame()


def _methods(summaries: pd.DataFrame) -> list[str]:
    names = list(dict.fromkeys(summaries["method"].astype(str)))
    order = [m for m in METHODS if m in names]
    return order + sorted(m for m in names if m not in order)


def _label(m: str, definitions: Mapping | None = None) -> str:
    base, reading = method_reading(m, definitions)
    label = METHODS[base]["label"] if base in METHODS else base
    return label if reading == DEFAULT_READING else f"{label}, eq. (3)-(4) {reading}"


def _rmse(e: pd.Series) -> float:
    """The one RMSE (:func:`gaitval.stats.summary.rmse`) over the finite errors."""
    e = e.to_numpy(float)
    return rmse(e[np.isfinite(e)])


def _spec(part) -> dict:
    """A role's registry spec as a dict: a bare name -> ``{"name": name}``; absent -> {}."""
    if part is None:
        return {}
    return dict(part) if isinstance(part, dict) else {"name": part}


def tug_table2(methods=("tug_m1", "tug_m2", "tug_m3"), dt_measured_s: float | None = None
               ) -> pd.DataFrame:
    """Table 2: the parameters used, one row per parameter and method.

    Parameters
    ----------
    methods : sequence of str, or mapping of str to dict
        Names of built-in methods (:data:`gaitval.methods.METHODS`), or name -> the
        definition actually run: a method of the config's ``tracking.methods`` or a
        built-in, with its ``tracking.overrides`` applied
        (``set_params(get_method(...), overrides)``).  A parameter the method does not
        have is left blank.
    dt_measured_s : float, optional
        The sampling time shown when a method does not fix ``tracker.dt_s``.

    Returns
    -------
    DataFrame
        ``parameter, symbol, unit, method, value, value_published``.
    """
    if not isinstance(methods, Mapping):
        methods = {name: get_method(name) for name in methods}
    rows = []
    for name, m in methods.items():
        filt, motion, phase, gate = (_spec(m.get(r)) for r in ("filter", "motion", "phase",
                                                                 "gate"))
        occ, det = _spec(m.get("occlusion")), _spec(m.get("detector"))
        bg = _spec(det.get("background", "percentile"))
        dt = (m.get("tracker") or {}).get("dt_s") or dt_measured_s
        cr = occ.get("name") == "catmull_rom"
        items = [
            ("sampling time", "Δt", "s", dt, PUBLISHED_T2["dt_s"]),
            ("motion covariance Q (sd per axis)", "√Q", "m/s²",
             filt.get("q_accel_sd_mps2"), PUBLISHED_T2["q_accel_sd_mps2"]),
            ("observation covariance R (sd per axis)", "√R", "m", filt.get("r_sd_m"),
             PUBLISHED_T2["r_sd_m"]),
            ("speed threshold, stance", "v_st_th", "m/s", phase.get("v_st_th"),
             PUBLISHED_T2["v_st_th_mps"]),
            ("speed threshold, swing", "v_sw_th", "m/s", phase.get("v_sw_th"),
             PUBLISHED_T2["v_sw_th_mps"]),
            ("gate (P_G = 0.999)", "G", "", gate.get("g"), PUBLISHED_T2["gate_g"]),
            ("steps for the acceleration function", "N_ac", "steps", motion.get("n_ac"),
             PUBLISHED_T2["n_ac"]),
            ("gait-phase reading of eq. (3)–(4)", "", "",
             phase.get("reading", DEFAULT_READING) if phase else None, None),
            ("Catmull–Rom points before occlusion", "N_bo", "steps",
             occ.get("n_bo") if cr else None, None),
            ("Catmull–Rom points after occlusion", "N_ao", "steps",
             occ.get("n_ao") if cr else None, None),
            ("background percentile", "", "%", bg.get("q"), None),
            ("background margin", "", "m", bg.get("margin_m"), None),
        ]
        # a parameter changed by tracking.overrides that has no row above gets one
        shown = {"tracker.dt_s", "filter.q_accel_sd_mps2", "filter.r_sd_m", "phase.v_st_th",
                 "phase.v_sw_th", "gate.g", "motion.n_ac", "occlusion.n_bo",
                 "occlusion.n_ao", "detector.background.q", "detector.background.margin_m"}
        base = method_reading(name.split(" (")[0], {name.split(" (")[0]: m})[0]
        items += [(f"{k} (changed; built in: {_builtin(base, k)})", "", "", v, None)
                  for k, v in changed_parameters(m, base).items() if k not in shown]
        for p, sym, unit, v, pub in items:
            rows.append({"parameter": p, "symbol": sym, "unit": unit,
                         "method": display_name(name, m, base),
                         "value": "" if v is None else str(v),
                         "value_published": "" if pub is None else str(pub)})
    return pd.DataFrame(rows)


#: Table 3's counts repeated under the persistent-swap rule, after the paper rule's.
PS = "_persistent_swap"
PERSISTENT_COUNTS = ("ft_turning", "ft_return", "ft_forward", "sf_turning", "sf_other",
                     "n_success")


def _counts(cat: pd.Series) -> dict:
    """Failed trials per first-failure category and successes (Table 3 cells)."""
    return {"ft_turning": int((cat == "false_tracking_turning").sum()),
            "ft_return": int((cat == "false_tracking_return").sum()),
            "ft_forward": int((cat == "false_tracking_forward").sum()),
            "sf_turning": int((cat == "stance_failure_turning").sum()),
            "sf_other": int(cat.isin(["stance_failure_forward",
                                      "stance_failure_return"]).sum()),
            "n_success": int((cat == "success").sum())}


def _persistent_columns(d: pd.DataFrame) -> dict:
    """The persistent-swap rule's Table 3 cells of one method's summaries."""
    if "category" + PS not in d or d["category" + PS].isna().any():
        return {**{c + PS: np.nan for c in PERSISTENT_COUNTS}, "success_rate" + PS: np.nan}
    c = _counts(d["category" + PS].astype(str))
    return {**{k + PS: c[k] for k in PERSISTENT_COUNTS},
            "success_rate" + PS: c["n_success"] / len(d) if len(d) else np.nan}


def _builtin(base: str, key: str):
    """The built-in method's value of ``role.param`` (``—`` when it has none)."""
    v = METHODS.get(base, {})
    for k in key.split("."):
        v = v.get(k) if isinstance(v, dict) else None
    return "—" if v is None else v


def tug_table3(summaries, definitions: Mapping | None = None) -> pd.DataFrame:
    """Table 3: method definitions, false tracking, stance failures, success rate.

    Each failed trial is counted once, in the category of its first failure (see
    :mod:`gaitval.evaluate.tug`).  A method run under the other reading of seed000
    eq. (3)–(4) (``<method>_stance_first``, config ``tug.phase_readings``) has its own row,
    with the published values of its base method beside it.

    Returns
    -------
    DataFrame
        One row per method, results first and the method's definition last:
        ``method, label, phase_reading, success_rate, n_success, n_trials, ft_turning,
        ft_return, ft_forward, sf_turning, sf_other, base_method, gait_phase_association,
        catmull_rom_interpolation`` and the ``*_published`` columns (each after its
        quantity, the paper's judging rule), then the same counts under the
        persistent-swap rule (a swap is false tracking only when it lasts > 0.5 s;
        :mod:`gaitval.evaluate.tug`): ``ft_turning_persistent_swap`` …
        ``success_rate_persistent_swap`` (NaN when the summaries predate it).
    """
    s = _concat(summaries)
    rows = []
    for m in _methods(s):
        d = s[s["method"].astype(str) == m]
        cat = d["category"].astype(str)
        base, reading = method_reading(m, definitions)
        pub = PUBLISHED_T3.get(base, {})
        defs = METHOD_DEFINITIONS.get(base, {})
        n = len(d)
        c = _counts(cat)
        ns = c["n_success"]
        rows.append({
            "method": m, "base_method": base, "phase_reading": reading,
            "label": _label(m, definitions),
            "gait_phase_association": defs.get("gait_phase_association"),
            "catmull_rom_interpolation": defs.get("catmull_rom_interpolation"),
            "n_trials": n,
            "ft_turning": c["ft_turning"],
            "ft_turning_published": pub.get("ft_turning", np.nan),
            "ft_return": c["ft_return"],
            "ft_return_published": pub.get("ft_return", np.nan),
            "ft_forward": c["ft_forward"],
            "sf_turning": c["sf_turning"],
            "sf_turning_published": pub.get("sf_turning", np.nan),
            "sf_other": c["sf_other"],
            "n_success": ns, "n_success_published": pub.get("n_success", np.nan),
            "n_trials_published": pub.get("n_trials", np.nan),
            "success_rate": ns / n if n else np.nan,
            "success_rate_published": (pub["n_success"] / pub["n_trials"]) if pub else np.nan,
            **_persistent_columns(d),
        })
    order = ["method", "label", "phase_reading", "success_rate", "success_rate_published",
             "n_success", "n_success_published", "n_trials", "n_trials_published",
             "ft_turning", "ft_turning_published", "ft_return", "ft_return_published",
             "ft_forward", "sf_turning", "sf_turning_published", "sf_other"]
    order += [c + PS for c in ("success_rate",) + PERSISTENT_COUNTS]
    order += ["base_method", "gait_phase_association", "catmull_rom_interpolation"]
    return _tidy_counts(pd.DataFrame(rows, columns=order),
                        ["ft_turning_published", "ft_return_published",
                         "sf_turning_published", "n_success_published",
                         "n_trials_published"] + [c + PS for c in PERSISTENT_COUNTS])


def _success_frames(frames: pd.DataFrame, summaries: pd.DataFrame) -> pd.DataFrame:
    ok = summaries[summaries["success"].astype(bool)][["trial", "method"]]
    f = frames.merge(ok, on=["trial", "method"], how="inner")
    return f[f["valid"].astype(bool)]


def tug_table4(frames, summaries, definitions: Mapping | None = None) -> pd.DataFrame:
    """Table 4: occlusion rate and RMSE per TUG phase over tracking-success trials.

    Methods run under the other reading of eq. (3)–(4) have their own rows, as in
    :func:`tug_table3`.

    Returns
    -------
    DataFrame
        One row per method and TUG phase (forward, turning, return, total):
        ``method, phase_reading, label, tug_phase, n_success_trials, n_uo, n_steps,
        occlusion_rate, rmse_x_m, rmse_y_m``, the ``*_published`` columns and
        ``base_method`` last.
    """
    f, s = _concat(frames), _concat(summaries)
    good = _success_frames(f, s)
    rows = []
    for m in _methods(s):
        d = good[good["method"].astype(str) == m]
        n_ok = int(s[(s["method"].astype(str) == m) & s["success"].astype(bool)].shape[0])
        base, reading = method_reading(m, definitions)
        for ph in PHASES + ("total",):
            e = d if ph == "total" else d[d["tug_phase"].astype(str) == ph]
            n = len(e)
            uo = int((e["pattern"].astype(str) == "UO").sum())
            pub = PUBLISHED_T4.get(base, {}).get(ph)
            rows.append({
                "method": m, "base_method": base, "phase_reading": reading,
                "label": _label(m, definitions), "tug_phase": ph, "n_success_trials": n_ok,
                "n_success_trials_published": PUBLISHED_T4_SUCCESS.get(base, np.nan),
                "n_uo": uo, "n_steps": n, "occlusion_rate": uo / n if n else np.nan,
                "n_uo_published": pub[0] if pub else np.nan,
                "n_steps_published": pub[1] if pub else np.nan,
                "occlusion_rate_published": pub[0] / pub[1] if pub else np.nan,
                "rmse_x_m": _rmse(e["err_x_m"]), "rmse_x_m_published": pub[2] if pub else np.nan,
                "rmse_y_m": _rmse(e["err_y_m"]), "rmse_y_m_published": pub[3] if pub else np.nan,
            })
    t = _tidy_counts(pd.DataFrame(rows, columns=T4_COLUMNS),
                     ["n_success_trials_published", "n_uo_published",
                                          "n_steps_published"])
    # results first, the method's base (a definition) last
    return t[[c for c in t.columns if c != "base_method"] + ["base_method"]]


def tug_table5(frames, summaries, definitions: Mapping | None = None) -> pd.DataFrame:
    """Table 5: time steps and RMSE per leg observation state (tracking-success trials).

    Returns
    -------
    DataFrame
        One row per method and state (observable, unobservable): ``method, label,
        observation_state, time_steps, rmse_x_m, rmse_y_m`` and ``*_published``.
    """
    f, s = _concat(frames), _concat(summaries)
    good = _success_frames(f, s)
    rows = []
    for m in _methods(s):
        d = good[good["method"].astype(str) == m]
        uo = d["pattern"].astype(str) == "UO"
        base = method_reading(m, definitions)[0]
        for state, e in (("observable", d[~uo]), ("unobservable", d[uo])):
            pub = PUBLISHED_T5.get(base, {}).get(state)
            rows.append({
                "method": m, "label": _label(m, definitions), "observation_state": state,
                "time_steps": len(e), "time_steps_published": pub[0] if pub else np.nan,
                "rmse_x_m": _rmse(e["err_x_m"]), "rmse_x_m_published": pub[1] if pub else np.nan,
                "rmse_y_m": _rmse(e["err_y_m"]), "rmse_y_m_published": pub[2] if pub else np.nan,
            })
    return _tidy_counts(pd.DataFrame(rows, columns=T5_COLUMNS), ["time_steps_published"])


#: The legend of the leg-pattern and gait-phase codes of the evidence sentences.
PATTERN_LEGEND = ("Codes: leg patterns (Yorozu et al. 2015b §2.3, gaitval.detect.legpatterns) SL one leg "
                  "alone, LT two legs together, FS_O a leg partly hidden but observable, "
                  "FS_U only a sliver of a leg visible, UO unobservable (no observation); "
                  "`SL×6 → LT×2` reads 6 scans SL, then 2 scans LT. Gait phases (Yorozu et al. 2015a "
                  "Fig. 6) 0 both legs in stance, 1/2 left leg swinging (accelerating/"
                  "decelerating), 3/4 right leg swinging, 5 both swinging.")


def _ordering_notes(t3: pd.DataFrame, t4: pd.DataFrame, t5: pd.DataFrame) -> list[str]:
    """Success-rate ordering per reading of eq. (3)–(4) against the paper's, and whether
    Method 3 beats Method 2 in the turning phase and when unobservable (paper: it does)."""
    notes = []
    paper_order = ("tug_m3", "tug_m2", "tug_m1")
    for reading, g in t3.groupby("phase_reading", sort=False):
        g = g[g["base_method"].isin(paper_order)].set_index("base_method")
        ms = [m for m in ("tug_m1", "tug_m2", "tug_m3") if m in g.index]
        if len(ms) < 2:
            continue
        rate = g["success_rate"]
        got = sorted(ms, key=lambda m: (-rate[m], ms.index(m)))
        paper = [m for m in paper_order if m in ms]
        counts = ", ".join(f"{m} {int(g.loc[m, 'n_success'])}/{int(g.loc[m, 'n_trials'])}"
                           f" (paper {g.loc[m, 'n_success_published']}/"
                           f"{g.loc[m, 'n_trials_published']})" for m in ms)
        verdict = ("matches the paper's" if got == paper else
                   "differs from the paper's (" + " > ".join(paper) + ")")
        notes.append(f"Reading {reading} of eq. (3)-(4): success {counts}; ordering "
                     + " ≥ ".join(got) + f" {verdict}.")
    for t, key, label in ((t4, ("tug_phase", "turning"), "turning-phase RMSE"),
                          (t5, ("observation_state", "unobservable"), "unobservable RMSE")):
        d = t[t[key[0]] == key[1]].set_index("method")
        if {"tug_m2", "tug_m3"} <= set(d.index):
            a, b = d.loc["tug_m3"], d.loc["tug_m2"]
            if np.isfinite(a.rmse_x_m) and np.isfinite(b.rmse_x_m):
                better = a.rmse_x_m <= b.rmse_x_m and a.rmse_y_m <= b.rmse_y_m
                notes.append(f"{label}: Method 3 {'≤' if better else 'not ≤'} Method 2 in "
                             f"both x and y (paper: Method 3 lower).")
    return notes


def _evidence_notes(ev: pd.DataFrame, t3: pd.DataFrame, per_method: int = 3) -> list[str]:
    """Where each method failed (category counts) and the first failures' evidence."""
    notes = []
    for m in t3["method"]:
        e = ev[ev["method"] == m]
        if not len(e):
            continue
        cats = e["category"].value_counts()
        notes.append(f"{m} failed {len(e)} trial(s): "
                     + ", ".join(f"{c} {n}" for c, n in cats.items())
                     + ". First failures (tug_failures lists every one): "
                     + " | ".join(e["evidence"].head(per_method)) + ".")
    return notes


def write_tug_tables(frames, summaries, out_dir: str | Path, *,
                     methods=("tug_m1", "tug_m2", "tug_m3"),
                     dt_measured_s: float | None = None,
                     evaluation: dict | None = None) -> list[Path]:
    """Write ``tug_table2..5`` and ``tug_failures`` (``.csv, .md, .tex``) into ``out_dir``.

    Parameters
    ----------
    frames, summaries : DataFrame or list of DataFrame
        Per-trial ``frames`` and ``summary`` of :func:`evaluate_tug_trial`.
    out_dir : path
        Usually ``reports/tables``.
    methods : sequence of str, or mapping of str to dict
        The methods of Table 2: names, or name -> the definition actually run (see
        :func:`tug_table2`); the definitions also tell which reading of eq. (3)–(4) each
        method ran.
    evaluation : dict, optional
        The evaluation rules the trials were evaluated with (``evaluation.tug``), for the
        stance-failure evidence.
    """
    out = Path(out_dir)
    f, s = _concat(frames), _concat(summaries)
    defs = methods if isinstance(methods, Mapping) else None
    t2 = tug_table2(methods, dt_measured_s)
    t3, t4, t5 = tug_table3(s, defs), tug_table4(f, s, defs), tug_table5(f, s, defs)
    ev = failure_evidence(f, s, defs, evaluation)
    legend = [PATTERN_LEGEND]
    common = [f"Source: {CITATION}.",
              "Reproduced values from gaitval's evaluation of each trial; *_published "
              "columns transcribed from the paper."]
    rules = ("Two judging rules side by side, fixed before the results: the "
             "columns without suffix use the paper's rule (every swap or lost event of >= "
             "0.20 s is false tracking; primary, compared with the published values); the "
             "*_persistent_swap columns count a left/right swap only when it lasts > 0.5 s "
             "(shorter swaps that recover are forgiven; lost events and stance failures "
             "as before).")
    if "success_rate" + PS in t3 and t3["success_rate" + PS].notna().any():
        rules += " Successes, paper rule -> persistent-swap rule: " + "; ".join(
            f"{r.method} {int(r.n_success)} -> {int(getattr(r, 'n_success' + PS))} of "
            f"{int(r.n_trials)}" for r in t3.itertuples(index=False)
            if pd.notna(getattr(r, "n_success" + PS))) + "."
    readings = ("Rows with phase_reading stance_first ran the same method with seed000 "
                "eq. (3) tested before eq. (4) (the slower leg is in stance first; "
                "gaitval.gait.phases); the paper's text allows both readings, its "
                "published values are shown beside both.")
    notes = _ordering_notes(t3, t4, t5)
    if defs:                          # a method run with overrides is named with them
        shown = {m: display_name(m, d, method_reading(m, defs)[0]) for m, d in defs.items()}
        for t in (t3, t4, t5, ev):
            if "method" in t:
                t["method"] = t["method"].map(lambda m: shown.get(m, m))
    paths = []
    paths += write_table(t2, out / "tug_table2", caption="TUG leg tracking: parameters used "
                         "(Yorozu et al. 2015a Table 2). N_bo, N_ao, the background model and the reading "
                         "of eq. (3)–(4) are not given in the paper.", notes=common)
    paths += write_table(t3, out / "tug_table3", caption="TUG leg tracking: method "
                         "definitions and tracking results per method (Yorozu et al. 2015a Table 3). "
                         "Each failed trial counted once, in the TUG phase of its first "
                         "failure; ft_forward and sf_other have no published counterpart.",
                         notes=common + [rules, readings] + notes
                         + _evidence_notes(ev, t3) + legend)
    paths += write_table(t4, out / "tug_table4", caption="TUG leg tracking: occlusion rate "
                         "and RMSE of the leg trajectory per TUG phase over tracking-success "
                         "trials (Yorozu et al. 2015a Table 4; sensor frame x/y).",
                         notes=common + [readings] + notes)
    paths += write_table(t5, out / "tug_table5", caption="TUG leg tracking: time steps and "
                         "RMSE per leg observation state over tracking-success trials "
                         "(Yorozu et al. 2015a Table 5).", notes=common + notes)
    paths += write_table(ev, out / "tug_failures", caption="TUG leg tracking: the first "
                         "failure of every trial a method did not track, with what the "
                         "tracker saw in the 0.5 s before (leg patterns, unobservable scans, "
                         "gait phases of eq. (3)–(5)); evidence for Table 3.",
                         notes=common + legend)
    return paths
