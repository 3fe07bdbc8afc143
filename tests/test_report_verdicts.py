"""The verdict page (gaitval.report.verdicts) and the HTML rendered from the same content
as index.md (gaitval.report.index)."""
from __future__ import annotations

import pandas as pd

from gaitval.report.index import build_index, display_table
from gaitval.report.verdicts import build_verdicts, wilson
from gaitval.tables import write_table


def _tug_t3():
    return pd.DataFrame({
        "method": ["tug_m1", "tug_m2", "tug_m3"], "base_method": ["tug_m1", "tug_m2", "tug_m3"],
        "phase_reading": ["swing_first"] * 3, "n_trials": [28] * 3, "n_success": [7, 1, 3],
        "n_trials_published": [28] * 3, "n_success_published": [14, 25, 27],
        "success_rate": [0.25, 1 / 28, 3 / 28],
        "success_rate_published": [0.5, 25 / 28, 27 / 28]})


def test_wilson_interval_textbook():
    # Agresti & Coull (1998): 0 of 10 -> Wilson 95% upper bound 0.2775
    lo, hi = wilson(0, 10)
    assert lo == 0 and abs(hi - 0.2775) < 1e-4


def test_verdicts_from_table_csvs_with_missing_studies(tmp_path):
    write_table(_tug_t3(), tmp_path / "tug_table3", caption="T3")
    v = build_verdicts(tmp_path)
    rank = v[v["comparison"].str.startswith("Tracking success ranking")].iloc[0]
    assert rank["published"] == "M3 0.96 > M2 0.89 > M1 0.50"
    assert rank["reproduced"] == "M1 0.25 > M3 0.11 > M2 0.04"
    assert rank["reproduced_in_direction"] == "no" and rank["note"] == "tug_table3"
    m1 = v[v["comparison"] == "Success rate M1, reading swing_first"].iloc[0]
    assert m1["reproduced_in_direction"] == "no"        # 0.50 outside 7/28's CI 0.13-0.43
    for study in ("mtst", "rollator", "ultrasonic"):
        row = v[v["study"] == study]
        assert len(row) == 1 and row.iloc[0]["reproduced_in_direction"] == "not run"


def test_html_has_verdicts_notes_toc_and_published_beside(tmp_path):
    rd = tmp_path / "reports"
    write_table(_tug_t3(), rd / "tables" / "tug_table3", caption="Success",
                notes=["Method 3 `differs` from the paper"])
    md, html = build_index(rd, study_names=["tiny"])
    h, m = html.read_text(), md.read_text()
    assert h.index("id=\"verdicts\"") < h.index("id=\"tug_table3\"")
    assert "<code>differs</code>" in h and "`differs`" in m          # the notes, both
    assert "href=\"#tug_table3\"" in h and "(#tug_table3)" in m       # verdict -> note link
    assert "4.848580e-09" not in h
    assert (rd / "verdicts.csv").is_file()
    header, rows = display_table(pd.read_csv(rd / "tables" / "tug_table3.csv", dtype=str,
                                             keep_default_na=False))
    names = [c for c, _ in header]
    assert names.index("success_rate_published") == names.index("success_rate") + 1
    assert rows[0][names.index("success_rate")] == "0.2500"
