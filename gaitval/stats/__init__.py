"""Statistics of validation studies: tidy DataFrames in, tidy DataFrames out.

Every function takes a long table (one row per observation) and returns a table whose
columns are listed under *Returns* in its docstring, so renderers never recompute.

- :func:`error_summary` — n, means/stds, mean/std of differences, RMSE, MAD, %RMSE, peak
  error per group (seed 003 Tables 2–6).
- :func:`normality` — Lilliefors or Jarque–Bera per group (seed 003 Table 7).
- :func:`anova_oneway` — SS/df/MS/F/p for between/within/total (seed 003 Table C1).
- :func:`paired_ttest` — paired t-test between two conditions (seed 003 Table 8).
- :func:`agreement`, :func:`icc`, :func:`bland_altman` — bias, limits of agreement,
  ICC(A,1)/ICC(C,1) with CIs, paired test of bias.
"""
from gaitval.stats.agreement import agreement, bland_altman, icc, two_way_mean_squares
from gaitval.stats.anova import anova_oneway
from gaitval.stats.normality import normality
from gaitval.stats.summary import error_summary, summarize_errors
from gaitval.stats.ttest import paired_t, paired_ttest

__all__ = ["agreement", "anova_oneway", "bland_altman", "error_summary", "icc",
           "normality", "paired_t", "paired_ttest", "summarize_errors",
           "two_way_mean_squares"]
