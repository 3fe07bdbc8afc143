"""Statistics of validation studies: tidy DataFrames in, tidy DataFrames out.

Every function takes a long table (one row per observation) and returns a table whose
columns are listed under *Returns* in its docstring, so renderers never recompute.

- :func:`error_summary` — n, means/stds, mean/std of differences, RMSE, MAD, %RMSE, peak
  error per group (seed 003 Tables 2–6).
- :func:`normality` — Lilliefors or Jarque–Bera per group (seed 003 Table 7).
- :func:`anova_oneway` — SS/df/MS/F/p for between/within/total (seed 003 Table C1).
- :func:`paired_ttest` — paired t-test between two conditions (seed 003 Table 8).
- :func:`agreement`, :func:`icc`, :func:`bland_altman` — bias, limits of agreement,
  ICC(A,1)/ICC(C,1) with CIs, paired test of bias; every row treated as independent
  ("pooled").
- :func:`loa_nested`, :func:`loa_replicates`, :func:`proportional_bias`,
  :func:`icc_mixed`, :func:`mover_limits` — the same questions when each subject gives
  several rows (strides, walks, replicates): limits of agreement from between- and
  within-subject variance with MOVER CIs, mixed-model bias and ICC with variance
  components (Bland & Altman 2007; Zou 2013).
"""
from gaitval.stats.agreement import agreement, bland_altman, icc, two_way_mean_squares
from gaitval.stats.anova import anova_oneway
from gaitval.stats.normality import normality
from gaitval.stats.icc_mixed import icc_mixed
from gaitval.stats.repeated import loa_nested, loa_replicates, mover_limits, proportional_bias
from gaitval.stats.summary import error_summary, summarize_errors
from gaitval.stats.ttest import paired_t, paired_ttest

__all__ = ["agreement", "anova_oneway", "bland_altman", "error_summary", "icc",
           "icc_mixed", "loa_nested", "loa_replicates", "mover_limits", "normality",
           "paired_t", "paired_ttest", "proportional_bias", "summarize_errors",
           "two_way_mean_squares"]
