"""Seed 003 Tables 2-8, C1, the figures, built from a synthetic gait-parameter table.

The synthetic table has known differences: subject s's system value is its reference
value +/- 0.01*s on alternating strides, so the RMSE of subject s is exactly 0.01*s and
the mean difference is 0 (an even number of strides).
"""
from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats import anova_oneway
from gaitval.tables import _published_qi2014 as pub
from gaitval.tables.ultrasonic import (PARAMETERS, build_ultrasonic_tables, table2,
                                       table7, table8, tableC1, write_ultrasonic_tables)

BASE = {"stride_length": 1.2, "stride_length_norm": 0.05, "stride_duration": 1.1,
        "stride_velocity": 1.0, "stride_velocity_norm": 0.04, "cadence": 0.9,
        "h_symmetry": 1.0, "v_symmetry": 1.0}
SPEED_FACTOR = {"slow": 0.6, "normal": 1.0, "fast": 1.3}
N_SUBJECTS, N_STRIDES = 5, 12


def make_gait_params(seed: int = 0, fast_error_factor: float = 1.0) -> pd.DataFrame:
    """Synthetic gait-parameter table (the contract with the ultrasonic tracking step)."""
    rng = np.random.default_rng(seed)
    rows = []
    for s in range(1, N_SUBJECTS + 1):
        for speed, f in SPEED_FACTOR.items():
            delta = 0.01 * s * (fast_error_factor if speed == "fast" else 1.0)
            for k in range(N_STRIDES):
                for p, b in BASE.items():
                    ref = b * f + 0.02 * rng.normal()
                    d = 0.0 if p == "cadence" else (delta if k % 2 == 0 else -delta)
                    rows.append(dict(study="synthetic", trial=f"S{s}_{speed}",
                                     subject=f"S{s}", speed=speed, stride=k, parameter=p,
                                     unit="-", reference=ref, system=ref + d))
    return pd.DataFrame(rows)


@pytest.fixture(scope="module")
def gait_params():
    return make_gait_params()


def test_table2_known_rmse_average_and_peak(gait_params):
    t = table2(gait_params).set_index("subject")
    subjects = [f"S{s}" for s in range(1, N_SUBJECTS + 1)]
    assert list(t.index) == subjects + ["average", "peak"]
    np.testing.assert_allclose(t.loc[subjects, "rmse_m"], 0.01 * np.arange(1, 6), atol=1e-12)
    np.testing.assert_allclose(t.loc[subjects, "diff_mean_m"], 0.0, atol=1e-12)
    np.testing.assert_allclose(t.loc["average", "rmse_m"], 0.03, atol=1e-12)   # mean(.01...05)
    np.testing.assert_allclose(t.loc["peak", "rmse_m"], 0.05, atol=1e-12)
    assert t.loc["average", "n_strides"] == N_SUBJECTS * N_STRIDES
    sub = gait_params[(gait_params.parameter == "stride_length")
                      & (gait_params.speed == "normal") & (gait_params.subject == "S3")]
    np.testing.assert_allclose(t.loc["S3", "ref_std_m"], sub["reference"].std(ddof=1))
    np.testing.assert_allclose(t.loc["S3", "pro_mean_m"], sub["system"].mean())
    # published values beside the reproduced ones (paper subject k <-> k-th subject)
    assert t.loc["average", "rmse_m_published"] == 0.027
    assert t.loc["S1", "ref_mean_m_published"] == 1.147


@pytest.mark.slow
def test_tables_3_to_6_cover_the_papers_parameters(gait_params):
    tabs = build_ultrasonic_tables(gait_params)
    assert "rmse_s" in tabs["table3"] and "rmse_mps" in tabs["table4"]
    assert "rmse" in tabs["table5"] and "rmse" in tabs["table6"]
    assert tabs["table5"].iloc[-2]["rmse_published"] == 0.013        # Table 5 average
    assert tabs["table6"].iloc[-1]["rmse_published"] == 0.079        # Table 6 peak


@pytest.mark.slow
def test_table8_paired_tests_over_subjects():
    g = make_gait_params(seed=1, fast_error_factor=2.0)
    t = table8(g).set_index(["parameter", "quantity"])
    assert set(t.index.get_level_values(0)) == set(PARAMETERS)
    row = t.loc[("stride_length", "rmse")]
    # per-subject RMSE is 0.01 s at slow/normal and 0.02 s at fast
    np.testing.assert_allclose(row["normal_mean"], 0.03, atol=1e-12)
    np.testing.assert_allclose(row["fast_mean"], 0.06, atol=1e-12)
    np.testing.assert_allclose(row["normal_std"], np.std(0.01 * np.arange(1, 6), ddof=1))
    assert row["fast_significant"] and not row["slow_significant"]
    assert np.isnan(row["slow_p"])          # identical RMSE at slow and normal: p undefined
    # scipy reference call on the per-subject means of the reference
    sub = g[g.parameter == "stride_duration"].groupby(["subject", "speed"])["reference"].mean()
    ref = sps.ttest_rel(sub.xs("slow", level="speed"), sub.xs("normal", level="speed"))
    np.testing.assert_allclose(t.loc[("stride_duration", "ref"), "slow_p"], ref.pvalue)
    assert t.loc[("stride_duration", "ref"), "slow_significant"]
    # cadence has zero error: the paper prints NaN for its RMSE p, so do we
    assert np.isnan(t.loc[("cadence", "rmse"), "fast_p"])
    assert t.loc[("stride_length", "pro"), "fast_mean_published"] == 1.409
    assert t.loc[("stride_duration", "rmse"), "fast_p_published"] == 0.019


def test_tableC1_is_anova_across_subjects(gait_params):
    t = tableC1(gait_params)
    assert list(t["source"][:3]) == ["between", "within", "total"]
    assert list(t["grouping"][:6]) == ["subject"] * 3 + ["stride_index"] * 3
    sub = gait_params[(gait_params.parameter == "stride_velocity")
                      & (gait_params.speed == "normal")]
    ref = anova_oneway(sub, "system", "subject")
    got = t[(t.parameter == "stride_velocity")
            & (t.grouping == "subject")].set_index("source")
    np.testing.assert_allclose(got.loc[["between", "within", "total"], "SS"], ref["SS"])
    np.testing.assert_allclose(got.loc["total", "SS"],
                               (len(sub) - 1) * sub["system"].var(ddof=1))
    assert got.loc["between", "df"] == N_SUBJECTS - 1
    assert got.loc["within", "SS_published"] == 0.23895
    t10 = tableC1(gait_params, max_strides_per_subject=10)
    assert t10[(t10.parameter == "stride_length") & (t10.grouping == "subject")].set_index(
        "source").loc["total", "df"] == N_SUBJECTS * 10 - 1
    # the other reading: groups = stride position within each subject (12 strides each)
    by_k = t[(t.parameter == "stride_velocity")
             & (t.grouping == "stride_index")].set_index("source")
    ref_k = anova_oneway(sub.assign(k=sub["stride"]), "system", "k")
    np.testing.assert_allclose(by_k.loc[["between", "within", "total"], "SS"], ref_k["SS"])
    assert by_k.loc["between", "df"] == N_STRIDES - 1
    assert by_k.loc["within", "SS_published"] == 0.23895


@pytest.mark.slow
def test_sample_strides_draws_the_papers_n_reproducibly(gait_params):
    from gaitval.tables.ultrasonic import sample_strides

    a = sample_strides(gait_params, 10, seed=7)
    assert a.equals(sample_strides(gait_params, 10, seed=7))
    assert not a.equals(sample_strides(gait_params, 10, seed=8))
    per = a.groupby(["subject", "speed", "parameter"]).size()
    assert (per == 10).all()
    assert sorted(a["stride_index"].unique()) == list(range(10))
    # the per-stride parameters share their strides (one draw for S, NS, T, V, NV, C)
    s_idx = a[a.parameter == "stride_length"].set_index(["trial", "stride"]).index
    t_idx = a[a.parameter == "stride_duration"].set_index(["trial", "stride"]).index
    assert s_idx.equals(t_idx)
    # NS = S / n and NV = V / n with n = 10 (seed003 eq. (18), (21))
    s = a[a.parameter == "stride_length"].set_index(["trial", "stride"])
    ns = a[a.parameter == "stride_length_norm"].set_index(["trial", "stride"])
    np.testing.assert_allclose(ns["system"], s.loc[ns.index, "system"] / 10)
    # "all": every stride, NS with n = all strides (the gait table's own n)
    every = sample_strides(gait_params, "all")
    assert len(every) == len(gait_params)
    s = every[every.parameter == "stride_length"].set_index(["trial", "stride"])
    ns = every[every.parameter == "stride_length_norm"].set_index(["trial", "stride"])
    np.testing.assert_allclose(ns["reference"], s.loc[ns.index, "reference"] / N_STRIDES)
    # more than a subject has: all of them
    assert (sample_strides(gait_params, 50).groupby(["subject", "speed", "parameter"])
            .size() == N_STRIDES).all()
    with pytest.raises(GaitvalError, match="strides_per_subject"):
        sample_strides(gait_params, 0)


@pytest.mark.slow
def test_table8_gives_n_beside_ns_and_nv(gait_params):
    tabs = build_ultrasonic_tables(gait_params, 10)
    t8 = tabs["table8"].set_index(["parameter", "quantity"])
    assert t8.loc[("stride_length_norm", "pro"), "normal_n"] == "10"
    assert t8.loc[("stride_velocity_norm", "rmse"), "slow_n"] == "10"
    assert t8.loc[("stride_length", "pro"), "normal_n"] == ""
    t8all = build_ultrasonic_tables(gait_params, "all")["table8"].set_index(
        ["parameter", "quantity"])
    assert t8all.loc[("stride_length_norm", "pro"), "fast_n"] == str(N_STRIDES)
    cols = list(tabs["table8"].columns)
    assert cols.index("normal_std") + 1 == cols.index("normal_n")


@pytest.mark.slow
def test_table7_is_marked_not_comparable(gait_params):
    t = build_ultrasonic_tables(gait_params)["table7"]
    assert t["comparability"].str.startswith("not comparable: ").all()
    assert "not a normality test" in t["comparability"].iloc[0]
    assert (t["n"] == N_SUBJECTS * 10).all()            # the paper's 10 per subject


def test_table7_normality_columns(gait_params):
    t = table7(gait_params).set_index("parameter")
    assert list(t.index) == ["stride_length", "stride_duration", "stride_velocity",
                             "h_symmetry", "v_symmetry"]
    sub = gait_params[(gait_params.parameter == "stride_length")
                      & (gait_params.speed == "normal")]["system"]
    assert t.loc["stride_length", "n"] == len(sub)
    np.testing.assert_allclose(t.loc["stride_length", "mean"], sub.mean())
    assert set(t["H"]) <= {0.0, 1.0}
    assert t.loc["stride_length", "mean_published"] == 1.147


@pytest.mark.slow
def test_write_tables_files_captions_and_determinism(gait_params, tmp_path):
    paths = write_ultrasonic_tables(gait_params, tmp_path / "a")
    names = sorted({p.stem for p in paths})
    assert names == sorted([f"ultrasonic_table{k}" for k in range(2, 9)]
                           + ["ultrasonic_tableC1"])
    assert len(paths) == 24 and all(p.is_file() for p in paths)
    md = (tmp_path / "a" / "ultrasonic_table7.md").read_text()
    assert "Table 7 of Qi et al. 2014" in md and "not a normality test" in md
    assert "stride index" in (tmp_path / "a" / "ultrasonic_tableC1.md").read_text()
    again = write_ultrasonic_tables(gait_params, tmp_path / "b")
    for p, q in zip(paths, again):
        assert p.read_bytes() == q.read_bytes()


def test_bad_gait_parameter_tables_raise_one_clear_error(gait_params):
    with pytest.raises(GaitvalError, match="lacks column"):
        table2(gait_params.drop(columns=["system"]))
    bad = gait_params.copy()
    bad.loc[0, "parameter"] = "step_width"
    with pytest.raises(GaitvalError, match="unknown parameter"):
        table2(bad)
    with pytest.raises(GaitvalError, match="no rows for parameter 'stride_length'"):
        table2(gait_params[gait_params.parameter != "stride_length"])


@pytest.mark.slow
def test_figures_are_written_and_deterministic(gait_params, tmp_path):
    from gaitval.report.stats_figures import bland_altman_figure, write_ultrasonic_figures
    paths = write_ultrasonic_figures(gait_params, tmp_path)
    names = {p.name for p in paths}
    assert {"ultrasonic_figA1.png", "ultrasonic_figB1.png", "ultrasonic_fig5.png",
            "ultrasonic_bland_altman_stride_length.png"} <= names
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in paths)
    sub = gait_params[(gait_params.parameter == "stride_length")
                      & (gait_params.speed == "normal")]
    a = bland_altman_figure(sub, "reference", "system", tmp_path / "ba1.png")
    b = bland_altman_figure(sub, "reference", "system", tmp_path / "ba2.png")
    assert a.read_bytes() == b.read_bytes()


# --------------------------------------------------------------------------- transcription
def test_published_tables_match_the_seed_text():
    """The dict in _published_qi2014 is the seed text's numbers (Tables 2-6, C1)."""
    from conftest import SEEDS
    path = SEEDS / "003_d657a7031a2bc1de.txt"
    if not path.is_file():
        pytest.skip(f"seed text {path} absent")
    text = path.read_text(encoding="utf-8")
    order = ["ref_mean", "ref_std", "pro_mean", "pro_std", "rmse"]
    for k, param in {2: "stride_length", 3: "stride_duration", 4: "stride_velocity",
                     5: "h_symmetry", 6: "v_symmetry"}.items():
        block = text.split(f"\nTable {k}. ")[1].split("\n\n", 2)[1]
        rows = [ln for ln in block.splitlines() if re.search(r"\d\.\d{3}", ln)]
        assert len(rows) == 5
        for stat, ln in zip(order, rows):
            nums = [float(x) for x in re.findall(r"\d+\.\d+", ln)]
            assert nums == pub.TABLES_2_6[param][stat], (k, stat)
    c1 = text.split("Table C1. Summary")[-1]
    between = [float(x) for x in re.findall(r"Between groups\t([\d.]+)", c1)]
    assert between == [pub.TABLE_C1[p]["between"][0] for p in
                       ("stride_length", "stride_duration", "stride_velocity",
                        "h_symmetry", "v_symmetry")]
    t8 = text.split("Speed\t\t\tSlow")[1].split("Table 8.")[0]
    rows = [ln for ln in t8.splitlines() if re.search(r"\t(Ref|Pro|RMSE)\t", ln)]
    params = ["stride_length", "stride_length_norm", "stride_duration", "stride_velocity",
              "stride_velocity_norm", "cadence", "h_symmetry", "v_symmetry"]
    keys = [(p, q) for p in params for q in ("ref", "pro", "rmse")]
    assert len(rows) == len(keys) == 24
    for key, ln in zip(keys, rows):
        nums = [float(x) for x in re.findall(r"\d+\.\d+|NaN", ln.split("\t", 2)[2])]
        np.testing.assert_array_equal(nums, pub.TABLE_8[key], err_msg=str(key))
