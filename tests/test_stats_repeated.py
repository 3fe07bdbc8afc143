"""gaitval.stats.repeated against published worked examples (source and call quoted above).

Sources
-------
- Bland & Altman (2007), J. Biopharm. Stat. 17(4):571-582, Tables 1-3: cardiac ejection
  fraction by radionuclide ventriculography (RV) and impedance cardiography (IC), 12
  subjects, 60 pairs (``tests/data/bland_altman_2007_ejection.csv``; R MethComp::cardiac).
  The paper prints Stata output; its values are quoted here as transcribed, with Stata's
  single-precision digits, in erenozen/opendose ``engine/tests/test_methodcomp_extras.py``
  (commit f73f9f00; "Stata ANOVA output (single-precision artefacts ~3e-8)").
- SimplyAgree 0.3.0 (Caldwell 2022, J. Open Source Softw. 7:4148), printed outputs of its
  vignettes ``agree_tests`` and ``agreement_analysis`` (arcaldwell49/SimplyAgree,
  ``docs/articles/*.html`` at commit 6d3094f9, also https://aaroncaldwell.us/SimplyAgree/)
  on its ``reps`` data, which is Zou's (2013) example: subjects 1-4 of the table above
  with the IC readings of rows 5 and 9 removed (x = RV, y = IC, difference x - y).
- SimplyAgree's own test expectations (``tests/testthat/test-agree_reps.R``, "examples
  from Zou"; ``test-agree_nest.R``) where the vignettes print nothing.

gaitval's differences are ``pro - ref``, so SimplyAgree's ``x - y`` is ``pro = x``,
``ref = y`` and Bland & Altman's RV - IC is ``pro = rv``, ``ref = ic``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from gaitval.errors import GaitvalError
from gaitval.stats import (anova_oneway, bland_altman, icc, icc_mixed, loa_nested,
                           loa_replicates, mover_limits, proportional_bias)
from gaitval.stats._mixed import _reml_pieces

DATA = Path(__file__).parent / "data" / "bland_altman_2007_ejection.csv"


@pytest.fixture(scope="module")
def ejection() -> pd.DataFrame:
    return pd.read_csv(DATA)


@pytest.fixture(scope="module")
def reps(ejection) -> pd.DataFrame:
    """SimplyAgree's ``reps``: subjects 1-4, IC of rows 5 and 9 (1-based) missing."""
    r = (ejection[ejection["subject"] <= 4].reset_index(drop=True)
         .rename(columns={"subject": "id", "rv": "x", "ic": "y"}))
    r.loc[[4, 8], "y"] = np.nan
    return r


def test_data_file_is_bland_altman_2007_table_1(ejection, reps):
    # Bland & Altman 2007: 12 subjects, 60 pairs, 3 to 6 pairs per subject;
    # SimplyAgree ?reps: "20 rows with 3 variables", two y missing
    assert len(ejection) == 60 and ejection["subject"].nunique() == 12
    m = ejection.groupby("subject").size()
    assert m.min() == 3 and m.max() == 6 and int((m ** 2).sum()) == 312
    assert len(reps) == 20 and int(reps["y"].isna().sum()) == 2


# --------------------------------------------------------------------------- replicates
def test_loa_replicates_matches_simplyagree_agree_reps_vignette(reps):
    # R: a2 = agree_reps(x = "x", y = "y", id = "id", data = reps, agree.level = .8)
    #    print(a2)   (SimplyAgree vignette "Agreement Tests")
    #              Estimate Lower CI Upper CI CI Level
    #    Bias        0.7152  -0.6667   2.0971     0.95
    #    Lower LoA  -1.2117  -4.7970   0.1054     0.90
    #    Upper LoA   2.6421   1.3250   6.2274     0.90
    b = loa_replicates(reps, "y", "x", "id", agree=0.8, alpha=0.05).iloc[0]
    assert round(b["bias"], 4) == 0.7152
    assert round(b["bias_ci_low"], 4) == -0.6667
    assert round(b["bias_ci_high"], 4) == 2.0971
    lo = loa_replicates(reps, "y", "x", "id", agree=0.8, alpha=0.10).iloc[0]
    assert round(lo["loa_low"], 4) == -1.2117
    assert round(lo["loa_low_ci_low"], 4) == -4.7970
    assert round(lo["loa_low_ci_high"], 4) == 0.1054
    assert round(lo["loa_high"], 4) == 2.6421
    assert round(lo["loa_high_ci_low"], 4) == 1.3250
    assert round(lo["loa_high_ci_high"], 4) == 6.2274
    assert (b["n_subjects"], b["n_ref"], b["n_pro"]) == (4, 18, 20)


def test_loa_replicates_matches_simplyagree_agreement_limit_reps(reps):
    # R: agreement_limit(x = "x", y = "y", id = "id", data = reps, data_type = "reps",
    #                    agree.level = .8)   (vignette "Agreement & Tolerance Limits")
    #       Bias           Bias CI Lower LoA Upper LoA           LoA CI
    #     0.7152 [-1.5287, 2.9591]    -1.212     2.642 [-4.797, 6.2274]
    #    SD of Differences = 1.5036
    # (LoA CI: the outer one-sided 95% limits, i.e. the 90% two-sided ones above; the
    # bias CI is emmeans on lm(d ~ 1) of the 4 subject means: t on 3 df)
    r = loa_replicates(reps, "y", "x", "id", agree=0.8, alpha=0.10).iloc[0]
    assert round(r["sd_total"], 4) == 1.5036
    assert round(r["loa_low"], 3) == -1.212 and round(r["loa_high"], 3) == 2.642
    assert round(r["loa_low_ci_low"], 3) == -4.797
    assert round(r["loa_high_ci_high"], 4) == 6.2274
    t3 = sps.t.ppf(0.975, 3) * r["bias_se"]
    assert round(r["bias"] - t3, 4) == -1.5287 and round(r["bias"] + t3, 4) == 2.9591


def test_loa_replicates_zou_example_at_95_percent(reps):
    # R: agree_reps(x = "x", y = "y", id = "id", data = reps, TOST = FALSE)
    #    SimplyAgree tests/testthat/test-agree_reps.R, "examples from Zou":
    #    estimate c(.7125, -2.23, 3.66); lower.ci[2:3] c(-9.76, 1.91);
    #    upper.ci[2:3] c(-.48, 11.20)  (expect_equivalent, tolerance 0.001 / 0.01)
    r = loa_replicates(reps, "y", "x", "id").iloc[0]
    assert round(r["loa_low"], 2) == -2.23 and round(r["loa_high"], 2) == 3.66
    assert round(r["loa_low_ci_high"], 2) == -0.48
    assert round(r["loa_high_ci_low"], 2) == 1.91
    assert round(r["loa_high_ci_high"], 2) == 11.20
    # -9.7686 is -9.77 to two decimals; the transcribed -9.76 passes SimplyAgree's own
    # test only through its tolerance (as does the bias .7125 for 0.7152, the value the
    # vignette prints).  The same formula reproduces every printed 4-decimal value above.
    assert abs(r["loa_low_ci_low"] - (-9.76)) < 0.01
    assert round(r["loa_low_ci_low"], 4) == -9.7686


def test_loa_replicates_bland_altman_2007_true_value_constant(ejection):
    # Bland & Altman 2007, true value constant (Stata output as quoted): within-subject
    # variances RV 0.107227795, IC 0.137874069; mean of subject differences 0.7092361,
    # their variance 0.91269114; multiplier 1 - 1/m_h = 0.7902778; total variance
    # 1.1063897, SD 1.0518506; limits -1.4594605 to 2.6637939 (1.96, centred on the mean
    # of all 60 differences, 0.6021667)
    r = loa_replicates(ejection, "ic", "rv", "subject").iloc[0]
    assert r["var_within_pro"] == pytest.approx(0.107227795, abs=5e-8)
    assert r["var_within_ref"] == pytest.approx(0.137874069, abs=5e-8)
    assert r["bias"] == pytest.approx(0.7092361, abs=1e-7)
    assert r["n_subjects"] * r["bias_se"] ** 2 == pytest.approx(0.91269114, rel=2e-7)
    assert 1 - 1 / r["m_harmonic_ref"] == pytest.approx(0.7902778, abs=1e-7)
    assert r["sd_total"] ** 2 == pytest.approx(1.1063897, abs=1e-7)
    assert r["sd_total"] == pytest.approx(1.0518506, abs=1e-7)
    # Bland & Altman centre these limits on the mean of all differences; gaitval (like
    # Zou 2013 and SimplyAgree) on the mean of the subject differences
    overall = float((ejection["rv"] - ejection["ic"]).mean())
    assert overall == pytest.approx(0.6021667, abs=1e-7)
    assert overall - 1.96 * r["sd_total"] == pytest.approx(-1.4594605, abs=1e-6)
    assert overall + 1.96 * r["sd_total"] == pytest.approx(2.6637939, abs=1e-6)
    z = sps.norm.ppf(0.975)
    assert r["loa_low"] == pytest.approx(r["bias"] - z * r["sd_total"], rel=1e-12)


def test_loa_replicates_unpaired_rows_and_unequal_numbers():
    # replicates need not be paired: 5 reference and 3 system readings of subject a
    df = pd.DataFrame({"s": ["a"] * 5 + ["b"] * 3,
                       "r": [1.0, 1.1, 0.9, 1.0, 1.0, 2.0, 2.1, np.nan],
                       "p": [1.2, np.nan, 1.3, np.nan, 1.1, 2.4, np.nan, 2.2]})
    r = loa_replicates(df, "r", "p", "s").iloc[0]
    assert (r["n_ref"], r["n_pro"]) == (7, 5)
    # by hand: subject means, d_i = ybar_i - xbar_i, bias = mean of d_i
    d = [np.mean([1.2, 1.3, 1.1]) - 1.0, np.mean([2.4, 2.2]) - 2.05]
    assert r["bias"] == pytest.approx(np.mean(d), rel=1e-12)
    assert r["m_harmonic_ref"] == pytest.approx(2 / (1 / 5 + 1 / 2))


# --------------------------------------------------------------------------- nested
def test_loa_nested_moments_matches_simplyagree_agree_nest_vignette(reps):
    # R: a3 = agree_nest(x = "x", y = "y", id = "id", data = reps, agree.level = .8)
    #    print(a3)   (SimplyAgree vignette "Agreement Tests")
    #              Estimate Lower CI Upper CI CI Level
    #    Bias        0.7101  -0.6824   2.1026     0.95
    #    Lower LoA  -1.1626  -4.8172   0.1811     0.90
    #    Upper LoA   2.5828   1.2390   6.2374     0.90
    b = loa_nested(reps, "y", "x", "id", agree=0.8, alpha=0.05, method="moments").iloc[0]
    assert round(b["bias"], 4) == 0.7101
    assert round(b["bias_ci_low"], 4) == -0.6824
    assert round(b["bias_ci_high"], 4) == 2.1026
    lo = loa_nested(reps, "y", "x", "id", agree=0.8, alpha=0.10, method="moments").iloc[0]
    assert round(lo["loa_low"], 4) == -1.1626
    assert round(lo["loa_low_ci_low"], 4) == -4.8172
    assert round(lo["loa_low_ci_high"], 4) == 0.1811
    assert round(lo["loa_high"], 4) == 2.5828
    assert round(lo["loa_high_ci_low"], 4) == 1.2390
    assert round(lo["loa_high_ci_high"], 4) == 6.2374
    assert (b["n_subjects"], b["n"]) == (4, 18)             # rows with a missing y dropped


def test_loa_nested_reml_matches_simplyagree_agreement_limit_nest(reps):
    # R: agreement_limit(x = "x", y = "y", id = "id", data = reps, data_type = "nest",
    #                    loa_calc = "mover", agree.level = .95)
    #    (vignette "Agreement & Tolerance Limits"; lme4 REML, emmeans Satterthwaite df)
    #       Bias           Bias CI Lower LoA Upper LoA            LoA CI
    #     0.7046 [-1.5572, 2.9664]    -2.153     3.562 [-7.4979, 8.9071]
    #    SD of Differences = 1.4581
    r = loa_nested(reps, "y", "x", "id").iloc[0]
    assert round(r["bias"], 4) == 0.7046
    assert round(r["bias_ci_low"], 4) == -1.5572
    assert round(r["bias_ci_high"], 4) == 2.9664
    assert round(r["sd_total"], 4) == 1.4581
    assert round(r["loa_low"], 3) == -2.153 and round(r["loa_high"], 3) == 3.562
    assert 2.9 < r["bias_df"] < 3.0                         # Satterthwaite, not n - 1 = 3
    # The LoA CI [-7.4979, 8.9071] is not compared: SimplyAgree's calc_loa_nest adds
    # MOVER terms for sigma2_b (n - 1 df) and (1 - 1/m_h) sigma2_w (N - n df) to the total
    # sigma2_b + sigma2_w, which they do not sum to, and counts the two rows with a
    # missing y in N and m_h.  gaitval's terms, sigma2_b + sigma2_w/m_h (the variance of a
    # subject mean) and (1 - 1/m_h) sigma2_w, sum to the total, as in Zou (2013).


def test_loa_nested_reml_bias_on_complete_subjects_1_to_4(ejection):
    # R: reps2 = reps; reps2$y[5] = 6.35; reps2$y[9] = 4.09
    #    agreement_limit(x = "x", y = "y", id = "id", data = reps2, data_type = "nest",
    #                    alpha = .025)$loa$bias
    #    SimplyAgree tests/testthat/test-agree_nest.R: expect_equal(..., 0.7234979,
    #    tolerance = .0001)
    sub = ejection[ejection["subject"] <= 4]
    r = loa_nested(sub, "ic", "rv", "subject").iloc[0]
    assert r["bias"] == pytest.approx(0.7234979, abs=1e-7)


def test_loa_nested_anova_matches_bland_altman_2007_true_value_varies(ejection):
    # Bland & Altman 2007, true value varies (Stata one-way ANOVA of RV - IC by subject,
    # as quoted): residual MS 0.170714026, subject MS 4.2090856, divisor 4.9818182,
    # total variance 0.98133606, SD 0.99062408, bias 0.6021667, limits -1.3394565 to
    # 2.5437899 (bias -/+ 1.96 SD)
    r = loa_nested(ejection, "ic", "rv", "subject", method="anova").iloc[0]
    assert r["var_within"] == pytest.approx(0.170714026, abs=5e-8)
    assert r["var_between"] == pytest.approx((4.2090856 - 0.170714026) / 4.9818182,
                                             rel=2e-7)
    assert r["sd_total"] ** 2 == pytest.approx(0.98133606, abs=1e-7)
    assert r["sd_total"] == pytest.approx(0.99062408, abs=1e-7)
    assert r["bias"] == pytest.approx(0.6021667, abs=1e-7)
    assert r["bias"] - 1.96 * r["sd_total"] == pytest.approx(-1.3394565, abs=1e-6)
    assert r["bias"] + 1.96 * r["sd_total"] == pytest.approx(2.5437899, abs=1e-6)
    assert np.isnan(r["loa_low_ci_low"]) and np.isnan(r["bias_ci_low"])
    # ignoring subjects (the paper's pooled analysis): SD 0.9610571
    assert bland_altman(ejection["ic"], ejection["rv"])["bias_sd"] == pytest.approx(
        0.9610571, abs=5e-8)


def test_pooled_vs_repeated_on_simplyagree_reps(reps):
    # R: agreement_limit(data = reps, x = "x", y = "y")   (18 complete pairs, pooled)
    #       Bias           Bias CI Lower LoA Upper LoA            LoA CI
    #     0.4383 [-0.1669, 1.0436]    -1.947     2.824 [-3.0117, 3.8884]
    #    SD of Differences = 1.217
    ok = reps.dropna()
    ba = bland_altman(ok["y"], ok["x"])
    assert round(ba["bias"], 4) == 0.4383
    assert round(ba["bias_ci_low"], 4) == -0.1669
    assert round(ba["bias_ci_high"], 4) == 1.0436
    assert round(ba["bias_sd"], 3) == 1.217
    assert round(ba["loa_low"], 3) == -1.947 and round(ba["loa_high"], 3) == 2.824
    # the printed LoA CI is MOVER with one variance term (s^2 on N - 1 df), one-sided
    # 95% (outer limits of the 90% interval), z quantile for the mean (calc_loa_simple)
    n, s = len(ok), ba["bias_sd"]
    half = sps.norm.ppf(0.95) * s / np.sqrt(n)
    mv = mover_limits(ba["bias"], (ba["bias"] - half, ba["bias"] + half),
                      [(s ** 2, n - 1)], agree=0.95, alpha=0.10)
    assert round(mv["loa_low_ci_low"], 4) == -3.0117
    assert round(mv["loa_high_ci_high"], 4) == 3.8884
    # the repeated-measures limits of the same pairs are wider (SD 1.4581 vs 1.217)
    rm = loa_nested(reps, "y", "x", "id").iloc[0]
    assert rm["loa_high"] - rm["loa_low"] > ba["loa_high"] - ba["loa_low"]


def _balanced(seed: int = 7, n: int = 6, m: int = 5) -> pd.DataFrame:
    """n subjects x m occasions, two raters: subject, occasion, subject x rater effects."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        s, sr = rng.normal(0, 1.0), rng.normal(0, 0.3, 2)
        for j in range(m):
            o = rng.normal(0, 0.5)
            y = [10 + s + o + sr[k] + 0.2 * k + rng.normal(0, 0.2) for k in range(2)]
            rows.append({"subject": f"s{i}", "occasion": j, "ref": y[0], "pro": y[1]})
    return pd.DataFrame(rows)


def test_balanced_design_reml_moments_and_anova_agree_with_one_way_anova():
    # Independent route: gaitval.stats.anova_oneway (checked against NIST StRD) of the
    # differences by subject.  With m pairs per subject, B&A 2007: sigma2_w = MS_within,
    # sigma2_b = (MS_between - MS_within)/m; REML equals these when sigma2_b > 0, and the
    # Satterthwaite df of the mean is exactly n - 1 (MS_between ~ chi2(n - 1)).
    df = _balanced()
    d = df.assign(d=df["pro"] - df["ref"])
    a = anova_oneway(d, "d", "subject")
    msb, msw = a.loc["between", "MS"], a.loc["within", "MS"]
    n, m = 6, 5
    for method in ("anova", "moments", "reml"):
        r = loa_nested(df, "ref", "pro", "subject", method=method).iloc[0]
        assert r["var_within"] == pytest.approx(msw, rel=1e-5), method
        assert r["var_between"] == pytest.approx((msb - msw) / m, rel=1e-5), method
        assert r["bias"] == pytest.approx(d["d"].mean(), rel=1e-9), method
    r = loa_nested(df, "ref", "pro", "subject").iloc[0]
    assert r["bias_df"] == pytest.approx(n - 1, rel=1e-4)
    assert r["bias_se"] ** 2 == pytest.approx(msb / (n * m), rel=1e-5)


def test_reml_estimate_is_the_optimum_of_the_deviance_used_for_satterthwaite(ejection):
    # the Satterthwaite df is evaluated at statsmodels MixedLM's REML estimate; check it
    # is the minimum of gaitval's own REML deviance (gradient ~ 0 in log-variances)
    r = loa_nested(ejection, "ic", "rv", "subject").iloc[0]
    d = (ejection["rv"] - ejection["ic"]).to_numpy()
    codes = pd.factorize(ejection["subject"], sort=True)[0]
    X = np.ones((d.size, 1))
    th = np.log([r["var_between"], r["var_within"]])
    h = 1e-5
    for i in range(2):
        e = np.eye(2)[i] * h
        g = (_reml_pieces(d, X, codes, *np.exp(th + e))[0]
             - _reml_pieces(d, X, codes, *np.exp(th - e))[0]) / (2 * h)
        assert abs(g) < 1e-3
    # and the REML bias is the GLS mean at those variances: SE^2 = 1 / sum w_i
    m = np.bincount(codes)
    w = m / (r["var_within"] + m * r["var_between"])
    assert r["bias_se"] ** 2 == pytest.approx(1 / w.sum(), rel=1e-10)


def test_reml_fit_agrees_with_statsmodels_and_survives_where_it_fails(ejection):
    # statsmodels: smf.mixedlm("d ~ 1", data, groups="subject").fit(reml=True)
    import statsmodels.formula.api as smf
    data = ejection.assign(d=ejection["rv"] - ejection["ic"])
    fit = smf.mixedlm("d ~ 1", data, groups="subject").fit(reml=True)
    r = loa_nested(ejection, "ic", "rv", "subject").iloc[0]
    assert r["bias"] == pytest.approx(fit.fe_params["Intercept"], rel=1e-5)
    assert r["var_between"] == pytest.approx(float(fit.cov_re.iloc[0, 0]), rel=1e-4)
    assert r["var_within"] == pytest.approx(fit.scale, rel=1e-4)
    # One subject's differences all 0 (an integer-frame stride duration, tiny study):
    # statsmodels' optimiser fails and falls back to a wrong answer; the profiled REML
    # puts sigma2_b on the boundary, where the bias is the plain mean of the differences
    d = np.r_[[-0.02, 0.02, 0.0, 0.0, 0.0, -0.02, 0.0, 0.0, 0.0, 0.0, 0.0], np.zeros(12)]
    df = pd.DataFrame({"s": ["a"] * 11 + ["b"] * 12, "ref": 1.0, "pro": 1.0 + d})
    out = loa_nested(df, "ref", "pro", "s").iloc[0]
    assert out["var_between"] == 0.0
    assert out["bias"] == pytest.approx(d.mean(), abs=1e-15)
    assert out["bias_df"] == 22                               # OLS: N - 1
    assert out["var_within"] == pytest.approx(np.var(d, ddof=1), rel=1e-12)
    # (statsmodels 0.15 raises "Singular matrix" on these differences, and on the tiny
    # study's returned a mean of 0.0065 for differences averaging -0.0009)


def test_loa_nested_by_groups_and_degenerate_inputs():
    df = _balanced()
    two = pd.concat([df.assign(param="a"), df.assign(param="b", pro=df["pro"] * 2)])
    out = loa_nested(two, "ref", "pro", "subject", by="param")
    assert list(out["param"]) == ["a", "b"] and list(out["n"]) == [30, 30]
    # all differences equal: exact bias, zero spread, no intervals
    flat = df.assign(pro=df["ref"] + 0.5)
    r = loa_nested(flat, "ref", "pro", "subject").iloc[0]
    assert r["bias"] == pytest.approx(0.5) and r["sd_total"] == 0.0
    assert np.isnan(r["loa_low_ci_low"])
    # one subject: no between-subject variance
    one = loa_nested(df[df["subject"] == "s0"], "ref", "pro", "subject").iloc[0]
    assert one["n_subjects"] == 1 and np.isnan(one["sd_total"])
    with pytest.raises(GaitvalError, match="unknown method"):
        loa_nested(df, "ref", "pro", "subject", method="ml")
    with pytest.raises(GaitvalError, match="not in the table"):
        loa_nested(df, "ref", "pro", "participant")


# --------------------------------------------------------------------------- prop. bias
def test_proportional_bias_ols_matches_scipy_linregress(ejection):
    # scipy.stats.linregress((rv + ic)/2, rv - ic): Bland & Altman 1999 §3.2 regression
    r = proportional_bias(ejection, "ic", "rv").iloc[0]
    a = (ejection["rv"] + ejection["ic"]) / 2
    ref = sps.linregress(a, ejection["rv"] - ejection["ic"])
    assert r["model"] == "ols" and r["slope_df"] == 58
    np.testing.assert_allclose([r["slope"], r["intercept"], r["slope_se"], r["p"]],
                               [ref.slope, ref.intercept, ref.stderr, ref.pvalue],
                               rtol=1e-10)


def test_proportional_bias_mixed_matches_statsmodels_directly(ejection):
    # statsmodels: smf.mixedlm("d ~ a", data, groups="subject").fit(reml=True)
    import statsmodels.formula.api as smf
    r = proportional_bias(ejection, "ic", "rv", subject="subject").iloc[0]
    data = ejection.assign(d=ejection["rv"] - ejection["ic"],
                           a=(ejection["rv"] + ejection["ic"]) / 2)
    fit = smf.mixedlm("d ~ a", data, groups="subject").fit(reml=True)
    assert r["model"] == "mixed" and r["n_subjects"] == 12
    assert r["slope"] == pytest.approx(fit.fe_params["a"], rel=1e-5)
    # SE from (X'V^-1 X)^-1 at the REML variances, built densely here (lme4/lmerTest's
    # choice; statsmodels' bse_fe also inverts the variance parameters' block, ~2% apart)
    vb, vw = float(fit.cov_re.iloc[0, 0]), float(fit.scale)
    same = (data["subject"].to_numpy()[:, None] == data["subject"].to_numpy()[None, :])
    V = vw * np.eye(len(data)) + vb * same
    X = np.column_stack([np.ones(len(data)), data["a"]])
    cov = np.linalg.inv(X.T @ np.linalg.solve(V, X))
    assert r["slope_se"] == pytest.approx(np.sqrt(cov[1, 1]), rel=1e-5)
    assert r["slope_ci_low"] < r["slope"] < r["slope_ci_high"]
    assert 0 < r["p"] < 1 and r["slope_df"] > 1


# --------------------------------------------------------------------------- ICC
SF_TABLE2 = np.array([[9, 2, 5, 8], [6, 1, 3, 2], [8, 4, 6, 8],
                      [7, 1, 2, 6], [10, 5, 6, 9], [6, 2, 4, 7]], dtype=float)


def test_icc_mixed_single_design_is_shrout_fleiss_icc():
    # Shrout & Fleiss (1979) Psychol. Bull. 86:420, Table 2 (6 targets x 4 judges),
    # Table 4: ICC(2,1) = .29, ICC(3,1) = .71  (McGraw & Wong ICC(A,1), ICC(C,1))
    df = pd.DataFrame(SF_TABLE2, columns=["j1", "j2", "j3", "j4"])
    r = icc_mixed(df, ["j1", "j2", "j3", "j4"]).iloc[0]
    assert r["design"] == "single" and r["k"] == 4
    assert round(r["icc_agreement"], 2) == 0.29
    assert round(r["icc_consistency"], 2) == 0.71
    # and the ANOVA route of gaitval.stats.icc to the optimiser's precision
    ref = icc(SF_TABLE2)
    assert r["icc_agreement"] == pytest.approx(ref.loc["ICC(A,1)", "icc"], rel=1e-4)
    assert r["icc_consistency"] == pytest.approx(ref.loc["ICC(C,1)", "icc"], rel=1e-4)


def test_icc_mixed_two_raters_single_design_equals_mcgraw_wong(ejection):
    # one row per target (subjects ignored): the two-rater shortcut is exactly ANOVA
    r = icc_mixed(ejection, ["ic", "rv"]).iloc[0]
    ref = icc(ejection[["ic", "rv"]].to_numpy())
    assert r["icc_agreement"] == pytest.approx(ref.loc["ICC(A,1)", "icc"], rel=1e-12)
    assert r["icc_consistency"] == pytest.approx(ref.loc["ICC(C,1)", "icc"], rel=1e-12)


def _ems(df: pd.DataFrame) -> dict:
    """Balanced subjects x occasions x 2 raters: variance components from expected mean
    squares (unrestricted model) — an independent route to the REML estimates."""
    y = np.stack([df.pivot(index="subject", columns="occasion", values=c).to_numpy()
                  for c in ("ref", "pro")], axis=2)                 # (a, b, c)
    a, b, c = y.shape
    g = y.mean()
    yi, yij, yik, yk = (y.mean(axis=(1, 2)), y.mean(axis=2), y.mean(axis=1),
                        y.mean(axis=(0, 1)))
    ms_s = b * c * np.sum((yi - g) ** 2) / (a - 1)
    ms_o = c * np.sum((yij - yi[:, None]) ** 2) / (a * (b - 1))
    ms_sr = b * np.sum((yik - yi[:, None] - yk[None, :] + g) ** 2) / ((a - 1) * (c - 1))
    ms_r = a * b * np.sum((yk - g) ** 2) / (c - 1)
    ms_e = (np.sum((y - yij[:, :, None] - yik[:, None, :] + yi[:, None, None]) ** 2)
            / (a * (b - 1) * (c - 1)))
    return {"var_residual": ms_e, "var_occasion": (ms_o - ms_e) / c,
            "var_subject_rater": (ms_sr - ms_e) / b,
            "var_subject": (ms_s - ms_o - ms_sr + ms_e) / (b * c),
            "var_rater": (ms_r - ms_sr) / (a * b)}


def test_icc_mixed_repeated_design_matches_expected_mean_squares():
    df = _balanced(seed=3, n=8, m=6)
    r = icc_mixed(df, ["ref", "pro"], subject="subject").iloc[0]
    assert r["design"] == "repeated" and r["n_subjects"] == 8 and r["n_occasions"] == 48
    ems = _ems(df)
    assert min(ems.values()) > 0                       # interior: REML = ANOVA
    for name, value in ems.items():
        assert r[name] == pytest.approx(value, rel=1e-4), name
    true = ems["var_subject"] + ems["var_occasion"]
    err = ems["var_subject_rater"] + ems["var_residual"]
    assert r["icc_consistency"] == pytest.approx(true / (true + err), rel=1e-4)
    assert r["icc_agreement"] == pytest.approx(true / (true + err + ems["var_rater"]),
                                               rel=1e-4)
    # the full variance-components model (statsmodels MixedLM, vc_formula) agrees
    g = icc_mixed(df, ["ref", "pro"], subject="subject", method="general").iloc[0]
    for name in ems:
        assert g[name] == pytest.approx(r[name], rel=2e-3, abs=1e-6), name


def test_icc_mixed_errors():
    df = _balanced()
    with pytest.raises(GaitvalError, match="at least two"):
        icc_mixed(df, ["ref"])
    with pytest.raises(GaitvalError, match="unknown method"):
        icc_mixed(df, ["ref", "pro"], method="fast")


# --------------------------------------------------------------------------- peer table
def _peer_file(tmp_path, ejection) -> Path:
    """A peer-style file (us_*/gt_*, one row per walk) with a participant column."""
    df = pd.DataFrame({"participant": ejection["subject"].map(lambda s: f"P_{s:02d}"),
                       "us_ef": ejection["rv"], "gt_ef": ejection["ic"]})
    path = tmp_path / "peer.parquet"
    df.to_parquet(path)
    return path


def test_peer_table_repeated_columns_come_from_the_stats_functions(tmp_path, ejection):
    from gaitval.tables.peer import peer_agreement_table, write_peer_table
    path = _peer_file(tmp_path, ejection)
    t = peer_agreement_table(path).iloc[0]
    df = pd.read_parquet(path)
    rm = loa_nested(df, "gt_ef", "us_ef", "participant").iloc[0]
    ic = icc_mixed(df, ["gt_ef", "us_ef"], subject="participant").iloc[0]
    pb = proportional_bias(df, "gt_ef", "us_ef", subject="participant").iloc[0]
    assert t["n_subjects"] == 12 and t["n"] == 60
    for col, src in (("bias_rm", "bias"), ("loa_low_rm", "loa_low"),
                     ("loa_high_rm_ci_high", "loa_high_ci_high"), ("sd_rm", "sd_total"),
                     ("var_between_rm", "var_between")):
        assert t[col] == rm[src], col
    assert t["icc_agreement_rm"] == ic["icc_agreement"]
    assert t["prop_bias_slope"] == pb["slope"] and t["prop_bias_p"] == pb["p"]
    # the pooled columns are unchanged: gaitval.stats.agreement on every row
    assert t["loa_low"] == pytest.approx(bland_altman(df["gt_ef"], df["us_ef"])["loa_low"])
    assert t["loa_width_ratio"] == pytest.approx(
        (t["loa_high_rm"] - t["loa_low_rm"]) / (t["loa_high"] - t["loa_low"]))
    md = write_peer_table(path, tmp_path / "peer_agreement")[1].read_text()
    assert "times as wide as the pooled ones" in md
    with pytest.raises(Exception, match="participant column"):
        peer_agreement_table(path, subject="walker")


def test_peer_table_published_file_has_no_participants(realdata):
    # Single et al. 2024's file has no participant column: the *_rm columns are empty
    # and the proportional-bias check is ordinary least squares over the 90 walks
    from gaitval.tables.peer import RM_ICC, RM_LOA, peer_agreement_table
    path = realdata / "peer-results" / "gailo_results.parquet"
    t = peer_agreement_table(path).set_index("parameter")
    assert t[[*RM_LOA, *RM_ICC, "n_subjects", "loa_width_ratio"]].isna().all().all()
    df = pd.read_parquet(path)
    a = (df["us_cadence"] + df["gt_cadence"]) / 2
    ref = sps.linregress(a, df["us_cadence"] - df["gt_cadence"])    # scipy reference call
    assert t.loc["cadence", "prop_bias_slope"] == pytest.approx(ref.slope, rel=1e-10)
    assert t.loc["cadence", "prop_bias_p"] == pytest.approx(ref.pvalue, rel=1e-10)


# --------------------------------------------------------------------------- ultrasonic
def _gait_params(seed: int = 4) -> pd.DataFrame:
    """Gait-parameter table (tables.ultrasonic_params contract): 4 subjects x 8 strides
    per speed, each subject with its own bias of the system (so strides are clustered)."""
    rng = np.random.default_rng(seed)
    rows = []
    for s in range(1, 5):
        bias = {p: rng.normal(0, 0.02) for p in ("stride_length", "stride_duration",
                                                 "stride_velocity", "h_symmetry",
                                                 "v_symmetry")}
        for speed in ("slow", "normal", "fast"):
            for k in range(8):
                for p, b in bias.items():
                    ref = 1.0 + 0.05 * rng.normal()
                    rows.append(dict(study="t", trial=f"S{s}_{speed}", subject=f"S{s}",
                                     speed=speed, stride=k, parameter=p, unit="-",
                                     reference=ref, system=ref + b + 0.01 * rng.normal()))
    return pd.DataFrame(rows)


def test_ultrasonic_table2_agreement_columns_come_from_the_stats_functions():
    from gaitval.stats import agreement
    from gaitval.tables.ultrasonic import table2
    from gaitval.tables.ultrasonic_subjects import agreement_note
    gp = _gait_params()
    t = table2(gp).set_index("subject")
    sub = gp[(gp["parameter"] == "stride_length") & (gp["speed"] == "normal")]
    rm = loa_nested(sub, "reference", "system", "subject").iloc[0]
    pooled = agreement(sub, "reference", "system").iloc[0]
    avg = t.loc["average"]
    assert avg["loa_low_rm_m"] == rm["loa_low"] and avg["loa_high_rm_m"] == rm["loa_high"]
    assert avg["loa_high_rm_ci_high_m"] == rm["loa_high_ci_high"]
    assert avg["sd_between_rm_m"] == pytest.approx(np.sqrt(rm["var_between"]))
    assert avg["loa_low_m"] == pooled["loa_low"]                  # all strides pooled
    assert avg["loa_high_ci_high_m"] == pooled["loa_high_ci_high"]
    s1 = sub[sub["subject"] == "S1"]
    ba = bland_altman(s1["reference"], s1["system"])              # S1's own strides
    assert t.loc["S1", "loa_low_m"] == pytest.approx(ba["loa_low"], rel=1e-12)
    assert np.isnan(t.loc["S1", "loa_low_rm_m"]) and np.isnan(t.loc["peak", "loa_low_m"])
    # subjects differ in bias, so the repeated-measures limits are wider, their CIs longer
    assert avg["loa_width_ratio"] > 1 and avg["loa_ci_ratio"] > 1
    note = agreement_note(table2(gp), "stride_length")
    assert f"{avg['loa_width_ratio']:.2f} times as wide" in note
    assert "4 subjects, 32 strides" in note


@pytest.mark.slow
def test_ultrasonic_agreement_table_rows_and_figure(tmp_path):
    from gaitval.report.stats_figures import bland_altman_figure
    from gaitval.tables.ultrasonic_agreement import agreement_table
    gp = _gait_params()
    t = agreement_table(gp)
    assert len(t) == 15 and set(t["speed"]) == {"slow", "normal", "fast"}
    row = t[(t["parameter"] == "stride_duration") & (t["speed"] == "fast")].iloc[0]
    sub = gp[(gp["parameter"] == "stride_duration") & (gp["speed"] == "fast")]
    ic = icc_mixed(sub, ["reference", "system"], subject="subject").iloc[0]
    assert row["icc_agreement_rm"] == ic["icc_agreement"]
    assert row["var_stride_rm"] == ic["var_occasion"] and row["n_subjects"] == 4
    # the figure colours points by subject and draws both sets of limits; same bytes
    a = bland_altman_figure(sub, "reference", "system", tmp_path / "a.png",
                            subject="subject")
    b = bland_altman_figure(sub, "reference", "system", tmp_path / "b.png",
                            subject="subject", limits=row)
    assert a.read_bytes() == b.read_bytes()


def test_satterthwaite_df_is_stable_for_a_small_design():
    """Four windows of two subjects (the tiny study's horizontal symmetry at fast speed,
    differences of order 1e-3): a change of the data by 1e-13 (relative, as another BLAS
    build makes) moved the numerical-Hessian df by 3e-4 with a fixed step of 1e-4; with
    the steps scaled to the log-variances it stays within 1e-5 (docs/numerics.md)."""
    from gaitval.stats._mixed import _fit_random_intercept

    d = np.array([-0.00148918, -0.00126077, -0.00171348, 0.00073965])
    a = np.array([1.00274923, 1.00507449, 0.99622574, 1.00460631])
    X = np.column_stack([np.ones(4), a])
    codes = np.array([0, 0, 1, 1])
    c = np.array([0.0, 1.0])
    base = _fit_random_intercept(d, X, codes, c)
    assert 0.9 < base["df"] < 1.2 and base["var_between"] > base["var_within"] > 0
    for eps in (1e-13, -1e-13, 3e-13):
        f = _fit_random_intercept(d * (1 + eps), X, codes, c)
        assert f["df"] == pytest.approx(base["df"], rel=1e-5), eps
        assert f["se"] == pytest.approx(base["se"], rel=1e-5), eps


def test_a_studys_own_paired_results_as_csv_with_its_prefixes_and_units(tmp_path,
                                                                       ejection):
    """agreement_files: the same statistics from a CSV with other column prefixes, the
    participant column named, units given; a non-number is one error naming the column
    and the row; no pair with these prefixes names the columns there are."""
    from gaitval.errors import FileFormatError
    from gaitval.tables.peer import peer_agreement_table, write_peer_table
    ref = peer_agreement_table(_peer_file(tmp_path, ejection))
    df = pd.DataFrame({"walker": ejection["subject"].map(lambda s: f"P_{s:02d}"),
                       "sys_ef": ejection["rv"], "vicon_ef": ejection["ic"]})
    csv = tmp_path / "mine.csv"
    df.to_csv(csv, index=False)
    t = peer_agreement_table(csv, "walker", system="sys_", reference="vicon_",
                             units={"ef": "%"})
    assert t["unit"].tolist() == ["%"]
    cols = [c for c in ref.columns if c != "unit"]
    pd.testing.assert_frame_equal(t[cols], ref[cols], check_exact=False, rtol=1e-12)
    paths = write_peer_table(csv, tmp_path / "peer_mine", name="mine", system="sys_",
                             reference="vicon_", subject="walker", units={"ef": "%"})
    md = paths[1].read_text()
    assert "Agreement of mine (sys_*) with its reference (vicon_*)" in md
    assert "times as wide as the pooled ones" in md
    bad = df.astype({"sys_ef": object})
    bad.loc[3, "sys_ef"] = "n/a?"
    bad.to_csv(tmp_path / "bad.csv", index=False)
    with pytest.raises(FileFormatError, match=r"column 'sys_ef', data row 4: 'n/a\?' is not"):
        peer_agreement_table(tmp_path / "bad.csv", system="sys_", reference="vicon_")
    with pytest.raises(FileFormatError, match=r"no paired us_<name> / gt_<name>.*sys_ef"):
        peer_agreement_table(csv)
    with pytest.raises(FileFormatError, match="not found"):
        peer_agreement_table(tmp_path / "none.csv")
