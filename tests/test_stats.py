"""gaitval.stats against outside reference values (the source is quoted above each check)."""
from __future__ import annotations

import os
from decimal import Decimal
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats import (agreement, anova_oneway, bland_altman, error_summary, icc,
                           normality, paired_ttest)

NIST_DIR = Path(os.path.dirname(scipy.__file__)) / "stats" / "tests" / "data" / "nist_anova"


# --------------------------------------------------------------------------- NIST StRD ANOVA
def _read_nist(name: str, exact_offset: bool = False):
    """Parse a NIST StRD one-way ANOVA file: data table and the certified values.

    ``exact_offset``: subtract the data's constant leading digits as decimal text before
    converting to float (a study with such data would store them relative to an offset).
    """
    path = NIST_DIR / f"{name}.dat"
    if not path.is_file():
        pytest.skip(f"NIST StRD file {path} not shipped with this scipy wheel")
    lines = path.read_text().splitlines()
    cert = {}
    for line in lines[:60]:
        f = line.split()
        if line.strip().startswith("Between"):
            cert["df_b"], cert["SS_b"], cert["MS_b"], cert["F"] = (int(f[2]), *map(float, f[3:6]))
        elif line.strip().startswith("Within"):
            cert["df_w"], cert["SS_w"], cert["MS_w"] = (int(f[2]), *map(float, f[3:5]))
        elif "Certified R-Squared" in line:
            cert["R2"] = float(f[-1])
    start = next(i for i, ln in enumerate(lines) if ln.strip().startswith("Data:")
                 and i > 40) + 1
    rows = [ln.split() for ln in lines[start:] if ln.strip()]
    if exact_offset:
        offset = Decimal(rows[0][1].split(".")[0])
        y = [float(Decimal(r[1]) - offset) for r in rows]
    else:
        y = [float(r[1]) for r in rows]
    df = pd.DataFrame({"treatment": [r[0] for r in rows], "y": y})
    return df, cert


def _check_nist(out, cert, rtol):
    assert out.loc["between", "df"] == cert["df_b"]
    assert out.loc["within", "df"] == cert["df_w"]
    assert out.loc["total", "df"] == cert["df_b"] + cert["df_w"]
    np.testing.assert_allclose(out.loc["between", "SS"], cert["SS_b"], rtol=rtol)
    np.testing.assert_allclose(out.loc["within", "SS"], cert["SS_w"], rtol=rtol)
    np.testing.assert_allclose(out.loc["between", "MS"], cert["MS_b"], rtol=rtol)
    np.testing.assert_allclose(out.loc["within", "MS"], cert["MS_w"], rtol=rtol)
    np.testing.assert_allclose(out.loc["between", "F"], cert["F"], rtol=rtol)
    r2 = out.loc["between", "SS"] / out.loc["total", "SS"]
    np.testing.assert_allclose(r2, cert["R2"], rtol=rtol)


# NIST/ITL StRD certified values (scipy/stats/tests/data/nist_anova/*.dat, lines 41-47).
# Digits claimed (relative tolerance): SiRstv, SmLs01 1e-10; AtmWtAg (7 constant leading
# digits) 1e-8; SmLs09 (13 constant leading digits) read as float64: 5e-4, i.e. ~3-4
# significant digits (parsing 1000000000000.4 into float64 already rounds it by up to
# 6e-5); SmLs09 with the constant digits removed as text first: 1e-10.
@pytest.mark.parametrize("name, rtol", [("SiRstv", 1e-10), ("SmLs01", 1e-10),
                                        ("AtmWtAg", 1e-8), ("SmLs09", 5e-4)])
def test_anova_oneway_matches_nist_certified_values(name, rtol):
    df, cert = _read_nist(name)
    out = anova_oneway(df, "y", "treatment")
    assert list(out.index) == ["between", "within", "total"]
    assert list(out.columns) == ["SS", "df", "MS", "F", "p"]
    _check_nist(out, cert, rtol)
    # p: the F survival function at the certified F (NIST does not certify p)
    np.testing.assert_allclose(out.loc["between", "p"],
                               sps.f.sf(cert["F"], cert["df_b"], cert["df_w"]),
                               rtol=1e-3, atol=1e-300)
    assert out.loc[["within", "total"], "F"].isna().all()
    assert np.isnan(out.loc["total", "MS"])


def test_anova_oneway_smls09_full_digits_when_offset_removed_exactly():
    # NIST SmLs09 certified: SS_b = 1.6008e2, SS_w = 1.8e2, F = 2.001e3 (15 digits)
    df, cert = _read_nist("SmLs09", exact_offset=True)
    _check_nist(anova_oneway(df, "y", "treatment"), cert, 1e-10)


def test_anova_oneway_public_and_errors():
    import gaitval.stats
    assert gaitval.stats.anova_oneway is anova_oneway
    one_group = pd.DataFrame({"g": ["a"] * 4, "v": [1.0, 2, 3, 4]})
    with pytest.raises(GaitvalError, match="at least 2 groups"):
        anova_oneway(one_group, "v", "g")
    with pytest.raises(GaitvalError, match="not in the table"):
        anova_oneway(one_group, "value", "g")
    singletons = pd.DataFrame({"g": ["a", "b"], "v": [1.0, 2.0]})
    with pytest.raises(GaitvalError, match="no degrees of freedom"):
        anova_oneway(singletons, "v", "g")


# --------------------------------------------------------------------------- paired t-test
# Student's sleep data (Cushny & Peebles 1905), R datasets::sleep.
SLEEP_1 = [0.7, -1.6, -0.2, -1.2, -0.1, 3.4, 3.7, 0.8, 0.0, 2.0]
SLEEP_2 = [1.9, 0.8, 1.1, 0.1, -0.1, 4.4, 5.5, 1.6, 4.6, 3.4]


def test_paired_ttest_matches_r_sleep_example():
    df = pd.DataFrame({"id": list(range(10)) * 2, "group": [1] * 10 + [2] * 10,
                       "extra": SLEEP_1 + SLEEP_2})
    out = paired_ttest(df, "extra", pair_by="id", condition="group", a=1, b=2).iloc[0]
    # R: with(sleep, t.test(extra[group == 1], extra[group == 2], paired = TRUE))
    # t = -4.0621, df = 9, p-value = 0.002833
    # 95 percent confidence interval: -2.4598858 -0.7001142; mean difference -1.58
    assert round(out["t"], 4) == -4.0621
    assert out["df"] == 9 and out["n"] == 10
    assert round(out["p"], 6) == 0.002833
    assert round(out["ci_low"], 7) == -2.4598858
    assert round(out["ci_high"], 7) == -0.7001142
    assert round(out["mean_diff"], 2) == -1.58
    assert bool(out["significant"])
    # scipy: ttest_rel(SLEEP_1, SLEEP_2)
    ref = sps.ttest_rel(SLEEP_1, SLEEP_2)
    np.testing.assert_allclose([out["t"], out["p"]], [ref.statistic, ref.pvalue], rtol=1e-12)


def test_paired_ttest_by_group_unpaired_rows_and_duplicates():
    rng = np.random.default_rng(3)
    rows = []
    for param in ("a", "b"):
        for s in range(8):
            for cond in ("slow", "normal"):
                rows.append({"parameter": param, "subject": s, "speed": cond,
                             "v": rng.normal() + (1.0 if cond == "slow" else 0.0)})
    df = pd.DataFrame(rows)
    df = df.drop(index=df.index[(df.parameter == "b") & (df.subject == 0)
                                & (df.speed == "slow")])
    out = paired_ttest(df, "v", "subject", "speed", "slow", "normal", by="parameter")
    assert list(out["parameter"]) == ["a", "b"]
    assert list(out["n"]) == [8, 7]                  # subject 0 unpaired in "b": left out
    for param, row in out.set_index("parameter").iterrows():
        sub = df[df.parameter == param].pivot(index="subject", columns="speed", values="v")
        sub = sub.dropna()
        ref = sps.ttest_rel(sub["slow"], sub["normal"])      # scipy reference call
        np.testing.assert_allclose([row["t"], row["p"]], [ref.statistic, ref.pvalue])
    with pytest.raises(GaitvalError, match="more than one row"):
        paired_ttest(pd.concat([df, df]), "v", "subject", "speed", "slow", "normal")


def test_paired_ttest_zero_variance_gives_nan_not_error():
    # seed 003 Table 8 reports p = NaN for cadence errors that are all zero
    df = pd.DataFrame({"s": [0, 1, 2, 0, 1, 2], "c": ["x"] * 3 + ["y"] * 3,
                       "v": [0.0, 0, 0, 0, 0, 0]})
    out = paired_ttest(df, "v", "s", "c", "x", "y").iloc[0]
    assert np.isnan(out["p"]) and np.isnan(out["t"]) and not out["significant"]


# --------------------------------------------------------------------------- normality
def test_lilliefors_statistic_by_hand_and_published_critical_value():
    rng = np.random.default_rng(11)
    x = rng.normal(size=20)
    out = normality(pd.DataFrame({"v": x}), "v").iloc[0]
    # Lilliefors D by hand: KS distance to N(mean, std ddof=1)
    z = np.sort((x - x.mean()) / x.std(ddof=1))
    cdf = sps.norm.cdf(z)
    i = np.arange(1, 21)
    d = max(np.max(i / 20 - cdf), np.max(cdf - (i - 1) / 20))
    np.testing.assert_allclose(out["statistic"], d, rtol=1e-12)
    # Lilliefors (1967) JASA 62:399, Table 1: critical value for n = 20, alpha 0.05: 0.190
    assert out["H"] == float(d > 0.190)
    # a clearly non-normal sample (exponential, n = 200) is rejected; MATLAB lillietest
    # default alpha 0.05
    y = rng.exponential(size=200)
    assert normality(pd.DataFrame({"v": y}), "v").iloc[0]["H"] == 1.0
    # mean, std and t-based 95% CI of the mean, as seed 003 Table 7 lists them
    ci = sps.t.interval(0.95, 19, loc=x.mean(), scale=sps.sem(x))
    np.testing.assert_allclose([out["ci95_low"], out["ci95_high"]], ci)


def test_jarque_bera_against_formula_and_scipy():
    rng = np.random.default_rng(5)
    df = pd.DataFrame({"g": np.repeat(["a", "b"], 50),
                       "v": np.r_[rng.normal(size=50), rng.exponential(size=50)]})
    out = normality(df, "v", by="g", method="jarque_bera").set_index("g")
    for g, row in out.iterrows():
        x = df.loc[df.g == g, "v"].to_numpy()
        # JB = n/6 (S^2 + (K-3)^2/4), Jarque & Bera (1987), biased moments
        m = x - x.mean()
        s = np.mean(m ** 3) / np.mean(m ** 2) ** 1.5
        k = np.mean(m ** 4) / np.mean(m ** 2) ** 2
        jb = len(x) / 6 * (s ** 2 + (k - 3) ** 2 / 4)
        np.testing.assert_allclose(row["statistic"], jb, rtol=1e-10)
        ref = sps.jarque_bera(x)                          # scipy reference call
        np.testing.assert_allclose([row["statistic"], row["p"]],
                                   [ref.statistic, ref.pvalue], rtol=1e-10)
    with pytest.raises(GaitvalError, match="unknown method"):
        normality(df, "v", method="shapiro")


def test_normality_degenerate_groups_are_nan():
    out = normality(pd.DataFrame({"v": [1.0, 1.0, 1.0, 1.0, 1.0]}), "v").iloc[0]
    assert np.isnan(out["p"]) and np.isnan(out["H"]) and out["n"] == 5


# --------------------------------------------------------------------------- error summary
def test_error_summary_hand_computed():
    df = pd.DataFrame({"subject": ["s1"] * 4 + ["s2"] * 2,
                       "ref": [1.0, 2.0, 3.0, 4.0, 10.0, 10.0],
                       "pro": [1.1, 1.9, 3.2, 4.0, 10.0, np.nan]})
    out = error_summary(df, "ref", "pro", by="subject").set_index("subject")
    s1 = out.loc["s1"]
    d = np.array([0.1, -0.1, 0.2, 0.0])
    assert s1["n"] == 4
    np.testing.assert_allclose(s1["rmse"], np.sqrt(0.06 / 4))       # sqrt((.01+.01+.04)/4)
    np.testing.assert_allclose(s1["mad"], 0.1)                      # (.1+.1+.2+0)/4
    np.testing.assert_allclose(s1["diff_mean"], 0.05)
    np.testing.assert_allclose(s1["diff_std"], np.std(d, ddof=1))
    np.testing.assert_allclose(s1["peak_abs_error"], 0.2)
    np.testing.assert_allclose(s1["ref_mean"], 2.5)
    np.testing.assert_allclose(s1["ref_std"], np.sqrt(5 / 3))        # var of 1..4, ddof=1
    np.testing.assert_allclose(s1["rmse_pct"], 100 * np.sqrt(0.015) / 2.5)
    assert out.loc["s2", "n"] == 1 and out.loc["s2", "rmse"] == 0.0
    assert np.isnan(out.loc["s2", "ref_std"])


# --------------------------------------------------------------------------- agreement / ICC
# Shrout & Fleiss (1979) Psychol. Bull. 86:420, Table 2: 6 targets x 4 judges; Table 4
# reports ICC(2,1) = .29, ICC(3,1) = .71, ICC(2,4) = .62, ICC(3,4) = .91, which are
# McGraw & Wong's ICC(A,1), ICC(C,1), ICC(A,k), ICC(C,k).
SF_TABLE2 = np.array([[9, 2, 5, 8], [6, 1, 3, 2], [8, 4, 6, 8],
                      [7, 1, 2, 6], [10, 5, 6, 9], [6, 2, 4, 7]], dtype=float)


def test_icc_matches_shrout_fleiss_table():
    out = icc(SF_TABLE2)
    assert round(out.loc["ICC(A,1)", "icc"], 2) == 0.29
    assert round(out.loc["ICC(C,1)", "icc"], 2) == 0.71
    assert round(out.loc["ICC(A,k)", "icc"], 2) == 0.62
    assert round(out.loc["ICC(C,k)", "icc"], 2) == 0.91
    for t in out.index:
        assert out.loc[t, "ci_low"] < out.loc[t, "icc"] < out.loc[t, "ci_high"]
    # order of rows is not part of the contract: selection by name is
    assert set(out.index) == {"ICC(A,1)", "ICC(C,1)", "ICC(A,k)", "ICC(C,k)"}


def _icc_via_statsmodels(r: np.ndarray, p: np.ndarray):
    """ICC(A,1), ICC(C,1) from a two-way ANOVA fitted by statsmodels (independent route)."""
    from statsmodels.formula.api import ols
    from statsmodels.stats.anova import anova_lm
    n = len(r)
    long = pd.DataFrame({"y": np.r_[r, p], "target": np.r_[np.arange(n), np.arange(n)],
                         "rater": ["ref"] * n + ["pro"] * n})
    a = anova_lm(ols("y ~ C(target) + C(rater)", data=long).fit(), typ=2)
    msr = a.loc["C(target)", "sum_sq"] / a.loc["C(target)", "df"]
    msc = a.loc["C(rater)", "sum_sq"] / a.loc["C(rater)", "df"]
    mse = a.loc["Residual", "sum_sq"] / a.loc["Residual", "df"]
    k = 2
    c1 = (msr - mse) / (msr + (k - 1) * mse)
    a1 = (msr - mse) / (msr + (k - 1) * mse + k / n * (msc - mse))
    # consistency CI, Shrout & Fleiss (1979) eq. for ICC(3,1) via exact F
    f0 = msr / mse
    fl = f0 / sps.f.ppf(0.975, n - 1, n - 1)
    fu = f0 * sps.f.ppf(0.975, n - 1, n - 1)
    return a1, c1, ((fl - 1) / (fl + 1), (fu - 1) / (fu + 1))


PEER_PAIRS = ["step_length", "step_time", "stride_length", "stride_time", "velocity",
              "cadence"]


@pytest.mark.parametrize("name", PEER_PAIRS)
@pytest.mark.slow
def test_agreement_on_peer_data_against_independent_routes(realdata, name):
    df = pd.read_parquet(realdata / "peer-results" / "gailo_results.parquet")
    out = agreement(df, f"gt_{name}", f"us_{name}").iloc[0]
    ok = df[[f"gt_{name}", f"us_{name}"]].dropna()
    r, p = ok[f"gt_{name}"].to_numpy(), ok[f"us_{name}"].to_numpy()
    n = len(r)
    assert out["n"] == n == 90
    # Bland & Altman (1999) by hand: bias = mean(d), LoA = bias +- 1.96 s,
    # CI of a limit = limit +- t(0.975, n-1) sqrt(3 s^2 / n)
    d = p - r
    s = d.std(ddof=1)
    np.testing.assert_allclose(out["bias"], d.mean(), rtol=1e-12)
    np.testing.assert_allclose([out["loa_low"], out["loa_high"]],
                               [d.mean() - 1.959964 * s, d.mean() + 1.959964 * s], rtol=1e-6)
    tq = sps.t.ppf(0.975, n - 1)
    np.testing.assert_allclose(out["loa_high_ci_high"] - out["loa_high"],
                               tq * np.sqrt(3 * s ** 2 / n), rtol=1e-12)
    np.testing.assert_allclose([out["bias_ci_low"], out["bias_ci_high"]],
                               sps.t.interval(0.95, n - 1, loc=d.mean(), scale=sps.sem(d)))
    # scipy reference call for the paired test of bias
    ref = sps.ttest_rel(p, r)
    np.testing.assert_allclose([out["t"], out["p"]], [ref.statistic, ref.pvalue], rtol=1e-10)
    # ICC via statsmodels' two-way ANOVA mean squares (a different code path)
    a1, c1, (lo, hi) = _icc_via_statsmodels(r, p)
    np.testing.assert_allclose([out["icc_a1"], out["icc_c1"]], [a1, c1], rtol=1e-9)
    np.testing.assert_allclose([out["icc_c1_ci_low"], out["icc_c1_ci_high"]], [lo, hi],
                               rtol=1e-9)
    assert out["icc_a1_ci_low"] < out["icc_a1"] < out["icc_a1_ci_high"]
    np.testing.assert_allclose(out["rmse"], np.sqrt(np.mean(d ** 2)))
    np.testing.assert_allclose(out["mad"], np.mean(np.abs(d)))


def test_bland_altman_known_differences():
    ref = np.zeros(4)
    pro = np.array([1.0, 2.0, 3.0, 4.0])                  # d = 1..4: mean 2.5, s^2 = 5/3
    ba = bland_altman(ref, pro)
    s = np.sqrt(5 / 3)
    np.testing.assert_allclose(ba["bias"], 2.5)
    np.testing.assert_allclose(ba["loa_high"] - ba["loa_low"], 2 * 1.959963984540054 * s)
    assert np.isnan(bland_altman([1.0], [2.0])["loa_low"])


def test_agreement_by_group_and_missing_column():
    df = pd.DataFrame({"g": ["a"] * 5 + ["b"] * 5, "r": np.arange(10.0),
                       "p": np.arange(10.0) + [0.1, -0.1, 0.0, 0.2, -0.2] * 2})
    out = agreement(df, "r", "p", by="g")
    assert list(out["g"]) == ["a", "b"] and list(out["n"]) == [5, 5]
    with pytest.raises(GaitvalError, match="not in the table"):
        agreement(df, "ref", "p")


# --------------------------------------------------------------------------- peer table
def test_peer_agreement_table(realdata, tmp_path):
    from gaitval.tables.peer import peer_agreement_table, write_peer_table
    path = realdata / "peer-results" / "gailo_results.parquet"
    t = peer_agreement_table(path).set_index("parameter")
    assert list(t.index) == ["step_length", "step_time", "stride_length", "stride_time",
                             "velocity", "cadence"]
    assert t.loc["velocity", "unit"] == "cm/s" and t.loc["cadence", "unit"] == "steps/min"
    assert (t["n"] == 90).all()
    df = pd.read_parquet(path)
    a = agreement(df, "gt_cadence", "us_cadence").iloc[0]
    for stat in ("bias", "loa_high", "icc_a1", "p"):
        assert t.loc["cadence", stat] == a[stat]
    paths = write_peer_table(path, tmp_path / "peer_agreement")
    assert "Sensors 2024, 24(4), 1172" in paths[1].read_text()


def test_peer_table_bad_files_raise_file_format_error(tmp_path):
    from gaitval.errors import FileFormatError
    from gaitval.tables.peer import peer_agreement_table
    with pytest.raises(FileFormatError, match="not found"):
        peer_agreement_table(tmp_path / "missing.parquet")
    junk = tmp_path / "junk.parquet"
    junk.write_text("not parquet")
    with pytest.raises(FileFormatError, match="cannot read"):
        peer_agreement_table(junk)
    nopairs = tmp_path / "nopairs.parquet"
    pd.DataFrame({"a": [1.0], "gt_b": [2.0]}).to_parquet(nopairs)
    with pytest.raises(FileFormatError, match="no paired"):
        peer_agreement_table(nopairs)
