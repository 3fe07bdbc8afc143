"""Figures reviewers expect (issue 14, scope 6): Bland–Altman with transparency for many
points and the paper's values where given; TUG trajectories of a successful and a failed
trial."""
from __future__ import annotations

import numpy as np
import pandas as pd

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
        seen["labels"] = [t.get_text() for t in ax.get_legend().get_texts()]
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
