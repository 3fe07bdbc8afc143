"""Seed 001 Table 3 (gaitval.tables.mtst): the paper's judging rule and the
persistent-swap rule side by side (issue 34)."""
from __future__ import annotations

import pandas as pd
import pytest

from gaitval.tables.mtst import judging_rules_note, table3


def _summary(rows):
    return pd.DataFrame([{"trial": t, "method": "mtst_proposed", "stick": stick,
                          "has_mocap": True, "has_annotations": True, "category_mocap": c,
                          "category_annotations": a, "category_mocap_persistent_swap": p}
                         for t, stick, c, a, p in rows])


def test_table3_counts_each_rule_separately():
    s = _summary([("a", False, "false_swap", "success", "success"),
                  ("b", False, "false_swap", "false_swap", "false_swap"),
                  ("c", True, "lost", "lost", "lost"),
                  ("d", False, "success", "success", "success")])
    t = table3(s, ["mtst_proposed"]).set_index("reference")
    mo, ra = t.loc["mocap"], t.loc["rater events"]
    assert (mo["false_no_stick"], mo["success_pct"]) == (2, 25.0)
    assert (mo["false_no_stick_persistent_swap"], mo["success_pct_persistent_swap"]) == (1, 50.0)
    assert mo["lost_stick_persistent_swap"] == 1 and mo["success_persistent_swap"] == "50.0% (2/4)"
    # the rater rule is persistent already: no second reading
    assert pd.isna(ra["success_pct_persistent_swap"]) and ra["success_persistent_swap"] == ""
    cols = list(t.columns)
    assert cols.index("success_published") < cols.index("lost_no_stick_persistent_swap")
    note = judging_rules_note(t.reset_index())
    assert "mtst_proposed 25.0 % -> 50.0 %" in note


def test_table3_without_the_second_rule_in_the_summaries():
    s = _summary([("a", False, "success", "success", "success")]).drop(
        columns="category_mocap_persistent_swap")
    t = table3(s, ["mtst_proposed"])
    assert t["success_pct_persistent_swap"].isna().all()
    assert t["success_pct"].tolist() == [pytest.approx(100.0)] * 2     # mocap, rater
