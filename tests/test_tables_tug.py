"""Seed 000 Tables 2–5 from per-trial evaluation frames (gaitval.tables.tug)."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.tables.tug import (PUBLISHED_T3, tug_table2, tug_table3, tug_table4,
                                tug_table5, write_tug_tables)


def summary(trial, method, category):
    return {"trial": trial, "method": method, "category": category,
            "success": category == "success"}


def frames(trial, method, errs, phases, patterns):
    n = len(errs)
    return pd.DataFrame({"trial": trial, "method": method, "k": np.arange(n),
                         "t_sensor_s": np.arange(n) * 0.025, "side": "L",
                         "err_x_m": errs, "err_y_m": np.asarray(errs) / 2, "valid": True,
                         "tug_phase": phases, "pattern": patterns})


@pytest.fixture
def data():
    s = pd.DataFrame([summary("a", "tug_m2", "success"), summary("b", "tug_m2", "success"),
                      summary("a", "tug_m1", "false_tracking_turning"),
                      summary("b", "tug_m1", "stance_failure_turning")])
    f = pd.concat([
        frames("a", "tug_m2", [0.03, 0.04], ["forward", "turning"], ["SL", "UO"]),
        frames("b", "tug_m2", [0.0, 0.0], ["return", "turning"], ["SL", "SL"]),
        frames("a", "tug_m1", [1.0, 1.0], ["forward", "turning"], ["SL", "SL"]),
        frames("b", "tug_m1", [0.5, 0.5], ["forward", "turning"], ["SL", "SL"]),
    ], ignore_index=True)
    return f, s


def test_table3_counts_and_published(data):
    _, s = data
    t = tug_table3(s).set_index("method")
    assert t.loc["tug_m1", "ft_turning"] == 1 and t.loc["tug_m1", "sf_turning"] == 1
    assert t.loc["tug_m1", "n_success"] == 0 and t.loc["tug_m2", "success_rate"] == 1.0
    # seed 000 Table 3: 50.0 % (14/28), 89.3 % (25/28), 96.4 % (27/28)
    assert t.loc["tug_m1", "success_rate_published"] == pytest.approx(0.5)
    assert t.loc["tug_m2", "success_rate_published"] == pytest.approx(25 / 28)
    assert list(t.index) == ["tug_m1", "tug_m2"]


def test_table4_only_success_trials(data):
    f, s = data
    t = tug_table4(f, s)
    m2 = t[t.method == "tug_m2"].set_index("tug_phase")
    # turning: errors 0.04 (UO) and 0.0 → RMSE = sqrt((0.04² + 0)/2)
    assert m2.loc["turning", "rmse_x_m"] == pytest.approx(np.sqrt(0.04 ** 2 / 2))
    assert (m2.loc["turning", "n_uo"], m2.loc["turning", "n_steps"]) == (1, 2)
    assert m2.loc["total", "n_steps"] == 4 and m2.loc["total", "occlusion_rate"] == 0.25
    # published seed 000 Table 4, Method 2 turning: 11.3 % (255/2264), 0.069, 0.062
    assert m2.loc["turning", "occlusion_rate_published"] == pytest.approx(255 / 2264)
    assert m2.loc["turning", "rmse_y_m_published"] == 0.062
    m1 = t[t.method == "tug_m1"]
    assert (m1["n_steps"] == 0).all() and m1["rmse_x_m"].isna().all()


def test_table5_observation_states(data):
    f, s = data
    t = tug_table5(f, s)
    m2 = t[t.method == "tug_m2"].set_index("observation_state")
    assert m2.loc["unobservable", "time_steps"] == 1
    assert m2.loc["unobservable", "rmse_x_m"] == pytest.approx(0.04)
    assert m2.loc["observable", "time_steps_published"] == 14490


def test_table2_parameters():
    t = tug_table2(dt_measured_s=0.025)
    g = t[(t.symbol == "G") & (t.method == "tug_m1")].iloc[0]
    assert (g.value, g.value_published) == ("13.82", "13.82")
    nbo = t[(t.symbol == "N_bo")].set_index("method")["value"]
    assert nbo["tug_m1"] == "" and nbo["tug_m3"] == "match"


def test_table2_from_definitions_blank_where_a_method_has_no_such_part():
    """Definitions instead of names: what was run is shown, absent parts left blank (a
    raw-scan tracker kind has no per-scan roles)."""
    from gaitval.methods import METHODS, set_params

    m3 = set_params(METHODS["tug_m3"], {"phase__v_st_th": 0.4, "tracker__dt_s": 0.05})
    pf = {"label": "PF", "kind": {"name": "my_particle_filter", "n": 500}}
    t = tug_table2({"tug_m3": m3, "pf": pf}, dt_measured_s=0.025).set_index(
        ["method", "symbol"])["value"]
    m = "tug_m3 (phase.v_st_th = 0.4, tracker.dt_s = 0.05)"    # modified: says so (issue 35)
    assert t[m, "v_st_th"] == "0.4" and t[m, "Δt"] == "0.05"
    assert t["pf", "Δt"] == "0.025" and t["pf", "G"] == "" and t["pf", "v_st_th"] == ""
    assert t["pf", "N_bo"] == "" and t["pf", "√Q"] == ""


def test_write_tug_tables(tmp_path, data):
    f, s = data
    paths = write_tug_tables(f, s, tmp_path)
    names = sorted(p.name for p in paths)
    assert names == sorted([f"tug_table{i}.{e}" for i in range(2, 6) for e in ("csv", "md", "tex")]
                           + [f"tug_failures.{e}" for e in ("csv", "md", "tex")])
    md = (tmp_path / "tug_table3.md").read_text()
    assert "ordering" in md
    again = write_tug_tables(f, s, tmp_path / "again")
    assert [p.read_bytes() for p in paths] == [p.read_bytes() for p in again]


# -- end to end on the tiny simulated study ----------------------------------------------------
@pytest.fixture(scope="module")
def tiny_study(tiny_simulated):
    """The session's tiny preset (tests/conftest.py), read only here."""
    return tiny_simulated


@pytest.mark.slow
def test_tiny_study_tug_end_to_end(tiny_study, tmp_path):
    """All three methods on the tiny study's TUG trials: registration and ground truth from
    gaitval's own modules, then evaluation, Tables 2–5 and the figures."""
    from gaitval.evaluate.tug import evaluate_tug_trial
    from gaitval.groundtruth import ground_truth, sensor_leg_points
    from gaitval.io.c3d import read_c3d
    from gaitval.io.scanlog import read_scanlog
    from gaitval.methods import track_trial
    from gaitval.registration.trial import register_trial
    from gaitval.report.tug_figures import write_tug_figures

    trials = pd.read_csv(tiny_study / "trials.csv", dtype=str, keep_default_na=False)
    subs = pd.read_csv(tiny_study / "subjects.csv", dtype=str,
                       keep_default_na=False).set_index("subject")
    tug = trials[trials["protocol"] == "tug"]
    assert len(tug) >= 1
    fr, su, ev = [], [], []
    for row in tug.to_dict("records"):
        sub = {**subs.loc[row["subject"]].to_dict(), "subject": row["subject"]}
        scans = read_scanlog(tiny_study / row["sensor_file"])
        mocap = read_c3d(tiny_study / row["mocap_file"])
        legs = sensor_leg_points(mocap, scans, row, sub, None)
        reg = register_trial(mocap, scans, row, sub, None, legs=legs)
        gt = ground_truth(mocap, scans, reg, row, sub, None, legs=legs)
        for m in ("tug_m1", "tug_m2", "tug_m3"):
            track = track_trial(scans, m, float(sub["leg_width_m"]))
            e = evaluate_tug_trial(track, gt, trial=row["trial"], method=m)
            f = e["frames"]
            v = f[f["valid"]]
            # the tracks stay on a leg (either: swaps are what Table 3 counts) most of the time
            assert len(v) > 0.5 * len(f)
            other = v.assign(side=v["side"].map({"L": "R", "R": "L"}))[
                ["k", "side", "xs_m", "ys_m"]].merge(v[["k", "side", "x_m", "y_m"]],
                                                      on=["k", "side"])
            near_own = np.hypot(v.err_x_m, v.err_y_m).to_numpy() < 0.15
            near_other = np.hypot(other.x_m - other.xs_m, other.y_m - other.ys_m) < 0.15
            assert (near_own.mean() > 0.8) or (near_own.mean() + near_other.mean() > 0.9)
            fr.append(f)
            su.append(e["summary"])
            ev.append(e["events"])
    frames, summaries = pd.concat(fr), pd.concat(su)
    events = pd.concat(ev)
    paths = write_tug_tables(frames, summaries, tmp_path / "tables")
    assert len(paths) == 15                  # Tables 2-5 and tug_failures
    t3 = pd.read_csv(tmp_path / "tables" / "tug_table3.csv")
    assert t3["n_trials"].tolist() == [len(tug)] * 3
    figs = write_tug_figures(frames, summaries, events, tmp_path / "figures")
    assert figs and all(p.stat().st_size > 1000 for p in figs)


def test_published_table3_matches_the_seed_text():
    """The transcribed Table 3 against the paper's own text (not against itself)."""
    import re
    from pathlib import Path

    seeds = Path(__file__).resolve().parents[2] / "shared" / "seeds"
    paper = next(seeds.glob("000_*.txt"), None) if seeds.is_dir() else None
    if paper is None:
        pytest.skip(f"seed 000 text not found in {seeds}")
    text = paper.read_text(encoding="utf-8")
    table = text[text.index("**Table 3.**"):text.index("### 6.3.")]
    rows = {}
    for key, label in (("ft_turning", "During Turning Motion</u>\t"),
                       ("ft_return", "During Walking Back to Chair</u>\t"),
                       ("sf_turning", "Stance Phase Identification <u>During Turning Motion</u>\t")):
        line = next(ln for ln in table.splitlines() if label in ln)
        rows[key] = [int(v) for v in line.split(label)[1].split("\t")]
    succ = re.findall(r"\((\d+)/(\d+)\)", next(ln for ln in table.splitlines()
                                                if ln.startswith("Tracking Success Rate")))
    for i, m in enumerate(("tug_m1", "tug_m2", "tug_m3")):
        pub = PUBLISHED_T3[m]
        assert [pub[k] for k in rows] == [rows[k][i] for k in rows]
        assert (pub["n_success"], pub["n_trials"]) == tuple(int(v) for v in succ[i])


def test_table3_has_the_persistent_swap_rule_after_the_papers():
    s = pd.DataFrame([summary("a", "tug_m1", "false_tracking_turning"),
                      summary("b", "tug_m1", "false_tracking_return"),
                      summary("c", "tug_m1", "success")])
    s["category_persistent_swap"] = ["success", "stance_failure_turning", "success"]
    t = tug_table3(s).set_index("method")
    assert t.loc["tug_m1", "n_success"] == 1
    assert t.loc["tug_m1", "n_success_persistent_swap"] == 2
    assert t.loc["tug_m1", "sf_turning_persistent_swap"] == 1
    assert t.loc["tug_m1", "success_rate_persistent_swap"] == pytest.approx(2 / 3)
    cols = list(t.columns)
    assert cols.index("success_rate_published") < cols.index("ft_turning_persistent_swap")
    # summaries without the second rule: its columns are there and empty
    old = tug_table3(s.drop(columns="category_persistent_swap"))
    assert old["success_rate_persistent_swap"].isna().all()


def test_a_run_whose_every_tug_trial_was_refused_gets_empty_tables_and_says_so(tmp_path):
    """Every TUG trial refused at registration: the tables are written with their columns
    and no row, the trajectory figure states why it is empty, and the verdict is 'not
    comparable: no trial analysed' (the run used to stop with an internal error)."""
    from gaitval.evaluate.tug import FRAME_COLUMNS
    from gaitval.methods import get_method
    from gaitval.report.tug_figures import write_tug_figures
    from gaitval.report.verdicts import build_verdicts
    from gaitval.tables.tug import write_tug_tables

    frames = pd.DataFrame(columns=list(FRAME_COLUMNS))
    summ = pd.DataFrame(columns=["trial", "method", "success", "category"])
    events = pd.DataFrame(columns=["trial", "method", "side", "kind", "t_start_s",
                                   "t_end_s", "tug_phase"])
    paths = write_tug_tables(frames, summ, tmp_path / "tables",
                             methods={"tug_m1": get_method("tug_m1")})
    for n in (3, 4, 5):
        t = pd.read_csv(tmp_path / "tables" / f"tug_table{n}.csv")
        assert t.empty and "method" in t.columns
    assert len(paths) >= 12
    figs = write_tug_figures(frames, summ, events, tmp_path / "figures")
    assert [p.name for p in figs] == ["tug_trajectories.png"]
    v = build_verdicts(tmp_path / "tables")
    tug = v[v["study"] == "tug"]
    assert len(tug) == 1 and tug["outcome"].iloc[0] == "not comparable"
    assert "refused at registration" in tug["why"].iloc[0]
