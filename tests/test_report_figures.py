"""Figures reviewers expect (issue 14, scope 6): Bland–Altman with transparency for many
points and the paper's values where given; TUG trajectories of a successful and a failed
trial."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.report import stats_figures as sf


def test_many_points_are_transparent_few_are_not():
    assert sf.point_alpha(20) == 0.9 and sf.point_alpha(2483) == 0.2
    assert sf.point_alpha(300) == 0.5


def test_published_bias_comes_from_the_papers_table_averages():
    from gaitval.tables._published_qi2014 import TABLES_2_6
    t = TABLES_2_6["stride_length"]
    pub = sf.published_bias("stride_length")
    assert pub["bias"] == t["pro_mean"][10] - t["ref_mean"][10]
    assert "Table 2" in pub["label"] and "loa_low" not in pub
    assert sf.published_bias("cadence") == {}          # not in Tables 2-6


def test_bland_altman_draws_the_published_line_and_transparent_points(tmp_path, monkeypatch):
    rng = np.random.default_rng(0)
    n = 600
    df = pd.DataFrame({"subject": [f"S{i % 6}" for i in range(n)],
                       "ref": rng.normal(1.0, 0.05, n)})
    df["pro"] = df["ref"] + rng.normal(0.01, 0.02, n)
    seen = {}
    real = sf.save_figure

    def spy(fig, path):
        ax = fig.axes[0]
        from matplotlib.collections import PathCollection
        seen["alphas"] = {c.get_alpha() for c in ax.collections
                          if isinstance(c, PathCollection)}          # the scatter points
        from matplotlib.legend import Legend
        legends = [a for a in ax.findobj(Legend)]
        seen["labels"] = [t.get_text() for leg in legends for t in leg.get_texts()]
        seen["title"] = ax.get_title()

        return real(fig, path)

    monkeypatch.setattr(sf, "save_figure", spy)
    sf.bland_altman_figure(df, "ref", "pro", tmp_path / "ba.png", subject="subject",
                           published={"bias": 0.002, "label": "published bias (Table X)"})
    assert (tmp_path / "ba.png").stat().st_size > 1000
    assert seen["alphas"] == {sf.point_alpha(n)}
    assert "published bias (Table X)" in seen["labels"]
    assert {"S0", "S5", "repeated-measures bias"} <= set(seen["labels"])
    assert "no published limits of agreement" in seen["title"]


def test_bland_altman_in_display_unit_with_legends_below(tmp_path, monkeypatch):
    """Issue 35: limits in the quantity's display unit (mm for a length in m), fixed
    decimals in the title (no 0.00907-style metres), legends below the plot; pooled and
    repeated-measures lines in different styles."""
    rng = np.random.default_rng(1)
    n = 200
    df = pd.DataFrame({"subject": [f"S{i % 5}" for i in range(n)],
                       "ref": rng.normal(1.3, 0.05, n)})
    df["pro"] = df["ref"] + rng.normal(0.017, 0.013, n)          # metres
    seen = {}
    real = sf.save_figure

    def spy(fig, path):
        ax = fig.axes[0]
        from matplotlib.legend import Legend
        seen["title"], seen["ylabel"] = ax.get_title(), ax.get_ylabel()
        seen["legends"] = [leg for leg in ax.findobj(Legend)]
        seen["styles"] = {ln.get_label(): (ln.get_linestyle(), ln.get_color())
                          for ln in ax.get_lines()}
        return real(fig, path)

    monkeypatch.setattr(sf, "save_figure", spy)
    sf.bland_altman_figure(df, "ref", "pro", tmp_path / "ba.png", subject="subject",
                           unit="m")
    assert seen["ylabel"] == "system - reference (mm)"
    bias = float(seen["title"].split("pooled: bias ")[1].split(" mm")[0])
    assert 10 < bias < 25 and "e-0" not in seen["title"]           # mm, not 0.017 m
    assert len(seen["legends"]) == 2
    for leg in seen["legends"]:                                    # below the axes
        assert leg.get_bbox_to_anchor().transformed(
            seen["legends"][0].axes.transAxes.inverted()).y0 < 0
    pooled = seen["styles"]["pooled limits (strides independent)"]
    rm = seen["styles"]["repeated-measures limits (subjects random)"]
    assert pooled != rm


def test_tug_figure_picks_a_successful_and_a_failed_trial():
    from gaitval.report.tug_figures import main_methods, pick_trials
    s = pd.DataFrame({"trial": ["t1", "t1", "t2", "t2", "t3", "t3", "t2"],
                      "method": ["m1", "m2"] * 3 + ["m1_stance_first"],
                      "success": [False, True, True, True, False, False, False]})
    assert main_methods(s["method"]) == ["m1", "m2"]
    assert pick_trials(s) == ("t2", "t3")            # t3: both methods failed
    assert pick_trials(s[s["trial"] == "t2"]) == ("t2", None)   # the variant is ignored
    assert pick_trials(s[s["trial"] == "t3"]) == (None, "t3")
    assert pick_trials(s[s["trial"] == "t1"]) == ("t1", None)   # one trial, one row


def _mtst_summary(rows):
    return pd.DataFrame([{"trial": t, "method": m, "has_mocap": mocap,
                          "category_mocap": cat if mocap else "",
                          "category_annotations": "" if mocap else cat}
                         for t, m, cat, mocap in rows])


def test_mtst_figure_picks_a_successful_and_a_failed_trial():
    from gaitval.report.mtst_figures import pick_trials
    s = _mtst_summary([("e1", "mtst_m1", "lost", True), ("e1", "mtst_proposed", "success", True),
                       ("e2", "mtst_m1", "false_swap", True),
                       ("e2", "mtst_proposed", "success", True),
                       ("e3", "mtst_m1", "success", False),          # the rater's verdict
                       ("e3", "mtst_proposed", "false_other", False)])
    contacts = pd.DataFrame({"trial": ["e2"], "method": ["mtst_proposed"], "cross": [True]})
    ms = ["mtst_m1", "mtst_proposed"]
    # success: the proposed method's first success with a cross step; failure: the proposed
    # method's own failed trial (the rater's verdict where there is no mocap)
    assert pick_trials(s, contacts, ms) == (("e2", "mtst_proposed"), ("e3", "mtst_proposed"))
    # the proposed method never fails: the method with the most failures, another trial
    s2 = s[s["trial"] != "e3"]
    assert pick_trials(s2, contacts, ms) == (("e2", "mtst_proposed"), ("e1", "mtst_m1"))
    # one trial: the same trial, the method that failed on it
    s3 = s[s["trial"] == "e1"]
    assert pick_trials(s3, contacts.iloc[:0], ms) == (("e1", "mtst_proposed"), ("e1", "mtst_m1"))
    ok = _mtst_summary([("e1", "mtst_proposed", "success", True)])
    assert pick_trials(ok, contacts, ms) == (("e1", "mtst_proposed"), None)
    bad = _mtst_summary([("e1", "mtst_proposed", "lost", True)])
    assert pick_trials(bad, contacts, ms) == (None, ("e1", "mtst_proposed"))


def test_mtst_figure_draws_both_rows_with_the_truth(tmp_path, monkeypatch):
    import gaitval.report.mtst_figures as mf
    s = _mtst_summary([("e1", "mtst_proposed", "success", True),
                       ("e2", "mtst_proposed", "lost", True)])
    k = np.arange(20)
    tf = pd.concat([pd.DataFrame({"trial": t, "method": "mtst_proposed", "k": k,
                                  "t_sensor_s": k * 0.05, "side": side,
                                  "x_m": k * 0.3, "y_m": y, "pattern": "FS", "swing": False,
                                  "x_true_m": k * 0.3, "y_true_m": y + 0.01})
                    for t in ("e1", "e2") for side, y in (("L", 0.1), ("R", -0.1))])
    contacts = pd.DataFrame({"trial": ["e1"], "method": ["mtst_proposed"], "side": ["L"],
                             "x_m": [1.0], "y_m": [0.1], "target": ["T1"], "cross": [False]})
    titles, widths = [], []
    orig = mf._trial_panel

    def spy(ax, *a):
        orig(ax, *a)
        titles.append(ax.get_title())
        widths.append(sorted({ln.get_linewidth() for ln in ax.get_lines()}))
    monkeypatch.setattr(mf, "_trial_panel", spy)
    paths = mf.write_mtst_figure({"summary": s, "track_field": tf, "contacts": contacts},
                                 tmp_path)
    assert paths == [tmp_path / "mtst_trial.png"] and paths[0].stat().st_size > 0
    assert titles == ["e1, mtst_proposed: success (mocap)",
                      "e2, mtst_proposed: FAILED: lost (mocap)"]
    assert all(max(w) > 2 * min(w) for w in widths)           # truth thick, tracked thin


def test_mtst_truth_in_field_is_the_mocap_leg_in_the_field_frame():
    from gaitval.evaluate.mtst_trial import truth_in_field
    track = pd.DataFrame({"t_sensor_s": [0.0, 0.05, 0.05], "side": ["L", "L", "R"],
                          "x_m": [1.0, 1.1, 1.2], "y_m": [0.0, 0.0, 0.2]})
    truth = pd.DataFrame({"t_sensor_s": [0.0, 0.1, 0.0, 0.1], "side": ["L", "L", "R", "R"],
                          "xs_m": [1.0, 1.2, 1.0, 1.2], "ys_m": [0.0, 0.0, 0.3, 0.3],
                          "valid": [True, True, False, False]})
    x, y = truth_in_field(track, truth, (5.0, 1.0, np.pi / 2))   # field = R(90°) p + t
    np.testing.assert_allclose(x[:2], [5.0, 5.0], atol=1e-12)
    np.testing.assert_allclose(y[:2], [2.0, 2.1], atol=1e-12)
    assert np.isnan(x[2]) and np.isnan(y[2])                    # invalid truth
    assert np.isnan(truth_in_field(track, None, (0, 0, 0))[0]).all()


def _rollator_frames(spec, n=10):
    """Evaluation frames (both trackers) of trials ``{trial: (scenario, errors, restarts)}``
    for the KF; the PF never errs."""
    rows = []
    for trial, (scenario, n_err, n_rs) in spec.items():
        for tracker in ("kf", "pf"):
            k = np.arange(n)
            kf = tracker == "kf"
            d = {"trial": trial, "tracker": tracker, "scan": k, "t_sensor_s": k * 0.028,
                 "status": "evaluated", "error": kf & (k < n_err),
                 "restart": kf & (k >= n - n_rs), "subject": "P01", "scenario": scenario}
            for side, y in (("L", 0.1), ("R", -0.1)):
                d.update({f"x_true_m_{side}": -0.6 + 0 * k, f"y_true_m_{side}": y + 0 * k,
                          f"x_m_{side}": -0.6 + 0.01 * k, f"y_m_{side}": y + 0 * k})
            rows.append(pd.DataFrame(d))
    return pd.concat(rows, ignore_index=True)


def test_rollator_figure_picks_a_successful_and_a_failed_trial():
    from gaitval.report.rollator_figures import pick_trials, trial_outcomes
    f = _rollator_frames({"r_obst": ("obstacle", 0, 0), "r_str": ("straight", 0, 0),
                          "r_err": ("straight", 3, 0), "r_rs": ("obstacle", 0, 1)})
    o = trial_outcomes(f, "kf").set_index("trial")
    assert o.loc["r_err", "error_pct"] == 30.0 and o.loc["r_rs", "restarts"] == 1
    assert list(o["failed"]) == [True, False, True, False]     # r_err, r_obst, r_rs, r_str
    # success: no KF error frame nor re-initialisation, a straight (turning) trial first;
    # failure: the most KF error frames
    assert pick_trials(f, "kf") == ("r_str", "r_err")
    assert pick_trials(f, "kf", trial="r_rs") == ("r_str", "r_rs")   # figure_trial, failed
    assert pick_trials(f, "kf", trial="r_obst") == ("r_obst", "r_err")
    assert pick_trials(f[f["trial"] == "r_str"], "kf") == ("r_str", None)
    bad = f[f["trial"].isin(["r_err", "r_rs"])]
    assert pick_trials(bad, "kf") == ("r_rs", "r_err")      # every trial failed: best, worst
    assert pick_trials(f[f["trial"] == "r_err"], "kf") == (None, "r_err")


@pytest.mark.slow
def test_rollator_figure_draws_both_trials(tmp_path, monkeypatch):
    from gaitval.report import rollator_figures as rf
    f = _rollator_frames({"r_str": ("straight", 0, 0), "r_err": ("straight", 3, 1)})
    seen = {}
    orig = rf.save_figure

    def spy(fig, path):
        seen["titles"] = [ax.get_title() for ax in fig.axes]
        seen["suptitle"] = fig._suptitle.get_text()
        return orig(fig, path)
    monkeypatch.setattr(rf, "save_figure", spy)
    paths = rf.write_rollator_figure(f, tmp_path, kf="kf", pf="pf")
    assert paths == [tmp_path / "rollator_turning_trial.png"] and paths[0].stat().st_size
    assert len(seen["titles"]) == 8
    assert seen["titles"][0].startswith("r_str: success: KF 0.0 % error frames, "
                                        "0 re-initialisations; PF 0.0 %")
    assert seen["titles"][4].startswith("r_err: FAILED: KF 30.0 % error frames, "
                                        "1 re-initialisation;")
    assert seen["suptitle"].startswith("a successful and a failed trial")
