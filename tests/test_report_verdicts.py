"""The verdict page (gaitval.report.verdicts), the data kind on top of the report
(gaitval.report.datakind) and the HTML rendered from the same content as index.md
(gaitval.report.index)."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from gaitval.report.datakind import headline, paper_data, run_data
from gaitval.report.index import build_index, display_table
from gaitval.report.verdicts import build_verdicts, summary_lines, wilson
from gaitval.tables import write_table


def _tug_t3(n=28, success=(7, 1, 3), readings=("swing_first",)):
    rows = []
    for reading in readings:
        sfx = "" if reading == "swing_first" else "_" + reading
        for m, k, pub in zip(("tug_m1", "tug_m2", "tug_m3"), success, (14, 25, 27)):
            rows.append({"method": m + sfx, "base_method": m, "phase_reading": reading,
                         "n_trials": n, "n_success": k, "n_trials_published": 28,
                         "n_success_published": pub, "ft_turning": n - k, "ft_return": 0,
                         "success_rate": k / n, "success_rate_published": pub / 28})
    return pd.DataFrame(rows)


def _table7(H=(1, 1), H_pub=(0, 0)):
    return pd.DataFrame({"symbol": ["S", "T"], "H": list(H), "p": [0.001, 0.002],
                         "H_published": list(H_pub), "p_published": [1.0, 1.0]})


def test_wilson_interval_textbook():
    # Agresti & Coull (1998): 0 of 10 -> Wilson 95% upper bound 0.2775
    lo, hi = wilson(0, 10)
    assert lo == 0 and abs(hi - 0.2775) < 1e-4


def test_verdicts_from_table_csvs_with_missing_studies(tmp_path):
    write_table(_tug_t3(), tmp_path / "tug_table3", caption="T3")
    v = build_verdicts(tmp_path, {"tug": "simulated replica (x, seed 1)"})
    rank = v[v["comparison"].str.startswith("Tracking success ranking")].iloc[0]
    assert rank["published"] == "M3 96.4% > M2 89.3% > M1 50.0%"
    assert rank["reproduced"] == "M1 25.0% > M3 10.7% > M2 3.6%"
    assert rank["outcome"] == "not reproduced" and rank["table"] == "tug_table3"
    assert "M3 10.7% is not above M1 25.0%" in rank["why"]            # the cause, not a link
    assert rank["data"] == "simulated replica (x, seed 1)"
    m1 = v[v["comparison"].str.startswith("Success rate M1")].iloc[0]
    assert m1["outcome"] == "not reproduced"        # 0.50 outside 7/28's Wilson CI
    # Wilson by hand: c = (0.25 + 1.96²/56)/(1 + 1.96²/28) = 0.2802, h = 0.1534
    assert "95% CI 12.7–43.4%" in m1["reproduced"]   # the numbers the criterion used
    assert "7 of 28 trials tracked" in m1["why"]
    for study in ("mtst", "rollator", "ultrasonic"):
        row = v[v["study"] == study]
        assert len(row) == 1 and row.iloc[0]["outcome"] == "not run"


def test_the_other_reading_is_shown_beside_and_not_counted(tmp_path):
    write_table(_tug_t3(readings=("swing_first", "stance_first")), tmp_path / "tug_table3",
                caption="T3")
    v = build_verdicts(tmp_path)
    tug = v[v["study"] == "tug"]
    assert len(tug) == 4                                # ranking + 3 methods, once each
    assert tug["comparison"].str.contains("reading swing_first").all()
    assert tug["alternative"].str.startswith("reading stance_first: ").all()
    assert "TUG leg tracking (Yorozu et al. 2015a): 0 of 4 comparable" in summary_lines(v)[0]


def test_rows_the_table_calls_not_comparable_are_not_comparable(tmp_path):
    """Ultrasonic Table 7 says its H and p are not comparable with the paper's: its rows
    are "not comparable" with the reason, not "not reproduced"; counted apart."""
    t8 = pd.DataFrame({"parameter": ["stride_length"], "symbol": ["S"], "unit": ["m"],
                       "quantity": ["pro"], **{f"{s}_{q}": [v] for s, v in
                                               (("slow", 1.0), ("normal", 1.2), ("fast", 1.4))
                                               for q in ("mean",)},
                       **{f"{s}_std": [0.1] for s in ("slow", "normal", "fast")},
                       **{f"{s}_p": [0.0001] for s in ("slow", "fast")},
                       **{f"{s}_mean_published": [v] for s, v in
                          (("slow", 0.9), ("normal", 1.17), ("fast", 1.41))},
                       **{f"{s}_std_published": [0.1] for s in ("slow", "normal", "fast")},
                       **{f"{s}_p_published": [0.0] for s in ("slow", "fast")}})
    write_table(t8, tmp_path / "ultrasonic_table8", caption="T8")
    write_table(_table7(), tmp_path / "ultrasonic_table7", caption="T7",
                notes=["gaitval applies Lilliefors, so its p and H are not comparable "
                       "with the published ones."])
    v = build_verdicts(tmp_path)
    t7 = v[v["source"] == "Table 7"]
    assert (t7["outcome"] == "not comparable").all() and len(t7) == 2
    assert t7["why"].str.contains("not normality").all()
    line = [s for s in summary_lines(v) if s.startswith("Ultrasonic")][0]
    assert "2 of 2 comparable comparisons reproduced; 2 not comparable" in line
    # the same table without that note is scored again
    write_table(_table7(), tmp_path / "ultrasonic_table7", caption="T7", notes=["other"])
    v2 = build_verdicts(tmp_path)
    assert (v2[v2["source"] == "Table 7"]["outcome"] == "not reproduced").all()


def test_a_study_too_small_says_so_instead_of_scoring(tmp_path):
    """The tiny study: 2 TUG trials (a 95% CI spanning most of 0-100 %) and an ANOVA
    with F undefined are "not comparable: too small", never reproduced."""
    write_table(_tug_t3(n=2, success=(1, 2, 2)), tmp_path / "tug_table3", caption="T3")
    c1 = pd.DataFrame({"symbol": ["S"], "source": ["between"], "df": [0.0], "F": [np.nan],
                       "p": [np.nan], "df_published": [9], "F_published": [0.14],
                       "p_published": [0.9984]})
    write_table(c1, tmp_path / "ultrasonic_tableC1", caption="C1")
    v = build_verdicts(tmp_path)
    tug = v[v["study"] == "tug"]
    assert (tug["outcome"] == "not comparable").all()
    assert tug["why"].str.startswith("too small").all()
    assert "TUG leg tracking (Yorozu et al. 2015a): no comparison could be scored; 4 not " \
           "comparable" in summary_lines(v)[0]
    # build_verdicts needs ultrasonic_table8 for the ultrasonic builder: C1 alone is not run
    from gaitval.report.verdicts import ultrasonic_verdicts
    t8 = pd.DataFrame(columns=["quantity"])
    rows = ultrasonic_verdicts({"ultrasonic_table8": t8, "ultrasonic_tableC1": c1}, {})
    assert rows[0]["outcome"] == "not comparable" and rows[0]["why"].startswith("too small")
    assert rows[0]["reproduced"] == "F undefined" and "nan" not in rows[0]["why"]


def test_mtst_rows_show_the_interval_they_test(tmp_path):
    t3 = pd.DataFrame({"method": ["mtst_m1", "mtst_proposed"], "reference": ["mocap"] * 2,
                       "success_pct": [27.0833, 62.5], "success": ["27.1% (13/48)",
                                                                   "62.5% (30/48)"],
                       "success_pct_published": [70.8333, 95.8333],
                       "success_published": ["70.8% (34/48)", "95.8% (46/48)"],
                       "n_trials_no_stick": [42, 42], "lost_no_stick": [21, 0],
                       "false_no_stick": [12, 17], "lost_no_stick_published": [6, 0],
                       "false_no_stick_published": [5, 0]})
    write_table(t3, tmp_path / "mtst_table3", caption="T3")
    v = build_verdicts(tmp_path)
    m1 = v[v["comparison"].str.startswith("Success M1")].iloc[0]
    assert m1["reproduced"] == "27.1% (13/48); 95% CI 16.6–41.0%"
    assert m1["criterion"] == "paper inside our 95% CI" and m1["outcome"] == "not reproduced"
    assert "lost 21/42 without a stick (paper 6)" in m1["why"]


def _provenance_config(rd, data_dir, preset="tiny", seed=7, sheet_rows=()):
    (rd / "provenance").mkdir(parents=True, exist_ok=True)
    cfg = {"run": ["tiny"], "data_dir": str(data_dir),
           "studies": {"tiny": {"simulate": {"preset": preset, "seed": seed}}}}
    (rd / "provenance" / "config.yaml").write_text(yaml.safe_dump(cfg))
    (data_dir / "tiny").mkdir(parents=True, exist_ok=True)
    pd.DataFrame(list(sheet_rows), columns=["study", "protocol", "subject", "trial"]).to_csv(
        data_dir / "tiny" / "trials.csv", index=False)


def test_data_kind_from_the_resolved_config_and_the_trial_sheet(tmp_path):
    rd = tmp_path / "reports" / "tiny"
    _provenance_config(rd, tmp_path / "data", sheet_rows=[
        ("tiny", "tug", "Y01", "tug_Y01_t1"), ("tiny", "tug", "Y01", "tug_Y01_t2")])
    studies = run_data(rd, ["tiny"])
    assert studies[0].kind == "simulated"
    assert studies[0].label == "simulated replica (tiny, seed 7)"
    text = paper_data(studies, "tug")
    assert text == ("simulated replica (tiny, seed 7); smaller than the paper: 1 subject, "
                    "2 trials analysed (paper 7, 28)")
    assert paper_data(studies, "mtst") == "no study of the run has this protocol"
    # the replay preset is a replay of real mocap; a trial sheet is real recordings
    _provenance_config(rd, tmp_path / "data", preset="replay", seed=11)
    assert run_data(rd, ["tiny"])[0].label == "replay of real mocap (replay, seed 11)"
    (rd / "provenance" / "config.yaml").write_text(yaml.safe_dump(
        {"run": ["lab"], "studies": {"lab": {"trial_sheet": "nowhere/trials.csv"}}}))
    assert run_data(rd, ["lab"])[0].kind == "real"


def test_html_top_says_what_the_data_are_then_verdicts_with_reasons(tmp_path):
    rd = tmp_path / "reports" / "tiny"
    _provenance_config(rd, tmp_path / "data", sheet_rows=[
        ("tiny", "tug", "Y01", "tug_Y01_t1"), ("tiny", "tug", "Y01", "tug_Y01_t2")])
    write_table(_tug_t3(), rd / "tables" / "tug_table3", caption="Success",
                notes=["Method 3 `differs` from the paper"])
    write_table(pd.DataFrame({"trial": ["t1"], "pole_residual_m": [2.71e-05]}),
                rd / "tables" / "study_registration_tiny", caption="Registration")
    md, html = build_index(rd, study_names=["tiny"])
    h, m = html.read_text(), md.read_text()
    top = h[:h.index('id="verdicts"')]
    assert "simulated replica (tiny, seed 7)" in top
    assert "cannot confirm or refute the paper" in top
    assert h.index('id="verdicts"') < h.index('id="tug_table3"') \
        < h.index('id="study_registration_tiny"')        # results before the appendix
    assert "<code>differs</code>" in h and "`differs`" in m          # the notes, both
    assert "href=\"#tug_table3\"" in h and "(#tug_table3)" in m       # verdict -> table
    assert "7 of 28 trials tracked" in h and "7 of 28 trials tracked" in m   # the why
    assert 'class="notreproduced"' in h
    assert (rd / "verdicts.csv").is_file()
    header, rows = display_table(pd.read_csv(rd / "tables" / "tug_table3.csv"), "tug_table3")
    names = [c for c, _ in header]
    assert names.index("Success (%), published") == names.index("Success (%)") + 1
    assert rows[0][names.index("Success (%)")] == "25.0"            # a rate in per cent


def test_table_c1_primary_reading_is_the_papers_words_and_stride_index_stands_beside():
    """Issue 34/35: Table C1 in both readings of its groups; the verdict scores grouping by
    subject (the paper's words) and shows the stride-index reading beside it, uncounted.
    When C1's note finds the published numbers inconsistent with subject groups, the
    primary row is not comparable."""
    from gaitval.report.verdicts import ultrasonic_verdicts
    c1 = pd.DataFrame({"symbol": ["S", "S"], "source": ["between", "between"],
                       "grouping": ["subject", "stride_index"], "df": [9.0, 9.0],
                       "F": [15.9, 0.27], "p": [1e-6, 0.98], "df_published": [9, 9],
                       "F_published": [0.14, 0.14], "p_published": [0.998, 0.998]})
    t8 = pd.DataFrame(columns=["quantity"])
    rows = ultrasonic_verdicts({"ultrasonic_table8": t8, "ultrasonic_tableC1": c1}, {})
    assert len(rows) == 1 and rows[0]["outcome"] == "not reproduced"
    assert rows[0]["alternative"].startswith("groups = stride index: F 0.27")
    assert "reproduced, not counted" in rows[0]["alternative"]
    note = {"ultrasonic_tableC1": ["Finding: the published table is not consistent with "
                                   "subjects as groups."]}
    rows = ultrasonic_verdicts({"ultrasonic_table8": t8, "ultrasonic_tableC1": c1}, note)
    assert rows[0]["outcome"] == "not comparable" and "stride index" in rows[0]["why"]


def test_table7_marked_not_comparable_by_its_own_column(tmp_path):
    from gaitval.report.verdicts import ultrasonic_verdicts
    t7 = _table7().assign(comparability="not comparable: the published Table 7 is not a "
                                        "normality test")
    rows = ultrasonic_verdicts({"ultrasonic_table8": pd.DataFrame(columns=["quantity"]),
                                "ultrasonic_table7": t7}, {})
    assert [r["outcome"] for r in rows] == ["not comparable"] * 2


def test_a_method_run_with_overrides_keeps_its_table4_verdict_and_says_so():
    """Issue 35: with tracking.overrides the tables name the method with its changes
    ("tug_m3 (occlusion.max_n = 10)"); its Table 4/5 verdicts stay, saying so."""
    from gaitval.report.verdicts import tug_verdicts
    t3 = _tug_t3(success=(20, 20, 20))
    t4 = pd.DataFrame({"method": ["tug_m2", "tug_m3 (occlusion.max_n = 10)"],
                       "tug_phase": ["turning", "turning"],
                       "phase_reading": ["swing_first", "swing_first"],
                       "rmse_x_m": [0.04, 0.03], "rmse_y_m": [0.03, 0.02],
                       "rmse_x_m_published": [0.069, 0.055],
                       "rmse_y_m_published": [0.062, 0.049], "n_steps": [100, 90]})
    rows = tug_verdicts({"tug_table3": t3, "tug_table4": t4})
    r = [x for x in rows if x["source"] == "Table 4"]
    assert len(r) == 1 and r[0]["outcome"] == "reproduced"
    assert r[0]["why"].startswith("tug_m3 (occlusion.max_n = 10) ran with tracking.overrides")


def test_the_top_says_how_the_twin_fares_on_its_physical_checks(tmp_path):
    """A simulated study's report says, before any verdict, how many of the twin's
    physical checks (``physics.csv`` beside its trial sheet) pass, how many have no
    reference, and names each one that fails; a study without the file says nothing."""
    rd = tmp_path / "reports" / "tiny"
    _provenance_config(rd, tmp_path / "data", sheet_rows=[
        ("tiny", "tug", "Y01", "tug_Y01_t1"), ("tiny", "tug", "Y01", "tug_Y01_t2")])
    assert run_data(rd, ["tiny"])[0].checks is None
    assert not any("physical checks" in ln for ln in headline(run_data(rd, ["tiny"])))
    pd.DataFrame({"check": ["tug_occlusion", "tug_occlusion", "cadence", "tug_turn_radius"],
                  "protocol": ["tug", "tug", "tug", "tug"],
                  "phase": ["forward", "turning", None, None],
                  "passed": [True, False, True, None]}).to_csv(
        tmp_path / "data" / "tiny" / "physics.csv", index=False)
    c = run_data(rd, ["tiny"])[0].checks
    assert (c["n"], c["passed"], c["unchecked"]) == (4, 2, 1)
    assert c["failed"] == ["tug_occlusion (tug, turning)"]
    write_table(_tug_t3(), rd / "tables" / "tug_table3", caption="Success")
    md, html = build_index(rd, study_names=["tiny"])
    h = html.read_text()
    top = h[:h.index('id="verdicts"')]
    assert "passes 2 of its 4 physical checks" in top
    assert "1 has no reference and is shown only" in top
    assert "1 fail</strong>: tug_occlusion (tug, turning)" in top
    assert "passes 2 of its 4 physical checks" in md.read_text()


def test_a_mean_sd_verdict_checks_the_sd_by_an_f_test():
    """Table 8's rows compare the SD over subjects too: two SDs of ten subjects each are
    told apart by the two-sided F-test at 95 % only outside about 0.50-2.01 x (F(9, 9)
    quantiles 0.248 and 4.03, NIST/SEMATECH e-Handbook, F distribution table)."""
    from gaitval.report.verdicts import sd_interval

    lo, hi = sd_interval(0.1, 10, 10)
    assert lo == pytest.approx(0.1 * 0.2484 ** 0.5, rel=2e-3)
    assert hi == pytest.approx(0.1 * 4.026 ** 0.5, rel=2e-3)
