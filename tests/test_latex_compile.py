"""Every .tex gaitval writes compiles with pdflatex (issue 14, scope 4).

The escaping and number formatting are checked without TeX; the compile tests run
pdflatex (Debian: texlive-latex-base texlive-latex-recommended texlive-latex-extra) and
skip with that reason when it is not installed.  The tables of the tiny study are compiled
by tests/test_workflow.py::test_every_tex_of_the_tiny_report_compiles (its workflow run).
"""
from __future__ import annotations

import re
import shutil

import numpy as np
import pandas as pd
import pytest

from gaitval.tables import write_table
from gaitval.tables.latex import (compile_tables, format_cell, latex_text, md_to_latex,
                                  to_latex)

PDFLATEX = shutil.which("pdflatex")
needs_pdflatex = pytest.mark.skipif(
    PDFLATEX is None, reason="pdflatex not installed (Debian: apt-get install "
    "texlive-latex-base texlive-latex-recommended texlive-latex-extra)")

NASTY = "Δ ≥ 5 ± 1 ∓ −2 × 3 → x · y √n σ² – — … § é ^2 50% & # _ $ ~ \\ {x} <a> |b|"


def test_specials_and_unicode_are_latex_commands():
    out = latex_text(NASTY)
    for raw in ("Δ", "≥", "±", "∓", "−", "×", "→", "·", "√", "σ", "²", "–", "—", "…", "§"):
        assert raw not in out, raw
    for esc in (r"\%", r"\&", r"\#", r"\_", r"\$", r"\textasciitilde{}",
                r"\textbackslash{}", r"\{x\}", r"\textasciicircum{}"):
        assert esc in out, esc
    assert "$$" not in latex_text("±−") and "é" in out       # é is left to [T1]{fontenc}
    assert latex_text("ጠ") == "[U+1320]"                      # visible, never a crash
    assert md_to_latex("`a_b` **c** _d_ [e](f.md)") == \
        r"\texttt{a\_b} \textbf{c} \emph{d} e"


def test_numbers_at_fixed_precision_tiny_values_not_zero():
    assert format_cell(0.05123, 3) == "0.051"
    assert format_cell(-0.2, 2) == r"\ensuremath{-}0.20"
    assert format_cell(4.8486e-09, 3) == r"\ensuremath{4.85\times10^{-9}}"
    assert format_cell(np.nan, 3) == "" and format_cell(True, 3) == "yes"
    assert format_cell(7, 3) == "7"


def test_published_column_sits_beside_its_quantity_under_one_header():
    df = pd.DataFrame({"method": ["M1"], "n": [3], "rmse_m": [0.05],
                       "rmse_m_published": [0.04]})
    tex = to_latex(df, caption="c", label="t")
    assert r"\multicolumn{2}{c}{rmse\_\allowbreak{}m}" in tex and r"\cmidrule(lr){3-4}" in tex
    assert "M1 & 3 & 0.050 & 0.040" in tex
    assert r"\toprule" in tex and r"\bottomrule" in tex      # booktabs


def test_long_tables_are_longtables_and_wide_ones_landscape_or_split():
    long = pd.DataFrame({"trial": [f"t{i}" for i in range(127)], "x": np.arange(127.0)})
    assert r"\begin{longtable}" in to_latex(long, caption="c", label="l")
    wide = pd.DataFrame({f"quantity_{i}": [1.0] for i in range(12)})
    assert r"\begin{landscape}" in to_latex(wide, caption="c", label="w")
    wider = pd.DataFrame({"trial": ["a"]} | {f"quantity_{i}": [1.0] for i in range(40)})
    tex = to_latex(wider, caption="c", label="w")
    assert "(part 2 of" in tex and tex.count(r"\begin{table}") >= 2
    assert all("trial" in part for part in tex.split(r"\begin{table}")[1:])


def _examples(tmp_path):
    rng = np.random.default_rng(0)
    small = pd.DataFrame({"method": ["Method 1", "Method 2"], "rmse_x_m": [0.0512, np.nan],
                          "rmse_x_m_published": [0.051, 0.047], "n": [3, -4],
                          "p": [4.8e-9, 0.2], "ok": [True, False]})
    wide = pd.DataFrame({f"quantity_number_{i}": rng.normal(size=5) for i in range(30)})
    wide.insert(0, "trial", [f"tug_Y0{i}_t1" for i in range(5)])
    for i in range(0, 30, 3):
        wide[f"quantity_number_{i}_published"] = 1.0
    long = pd.DataFrame({"trial": [f"tug_Y{i:03d}_t1" for i in range(127)],
                         "reason": [f"refused: {NASTY} and a long explanation"] * 127,
                         "x_m": rng.normal(size=127)})
    mid = pd.DataFrame({f"q_{i}": rng.normal(size=3) for i in range(12)})
    paths = []
    for name, df in (("small", small), ("wide", wide), ("long", long), ("mid", mid)):
        paths += write_table(df, tmp_path / "tables" / name, caption=f"{name}: {NASTY}",
                             notes=[f"a note with `code_x` and **{NASTY}**"])
    return [p for p in paths if p.suffix == ".tex"]


@needs_pdflatex
def test_adversarial_tables_compile_without_overfull_lines(tmp_path):
    res = compile_tables(_examples(tmp_path), tmp_path / "latex")
    failed = {p: err for p, (ok, err, _) in res.items() if not ok}
    assert not failed, failed
    overfull = {p: n for p, (_, _, n) in res.items() if n}
    assert not overfull, overfull


@needs_pdflatex
def test_a_broken_table_is_reported_as_failing(tmp_path):
    """The compile check can fail: an unescaped ^ outside maths is a LaTeX error."""
    bad = tmp_path / "bad.tex"
    bad.write_text("\\begin{tabular}{l}\na^2 \\\\\n\\end{tabular}\n")
    (ok, err, _), = compile_tables([bad], tmp_path / "latex").values()
    assert not ok and re.search(r"Missing \$ inserted", err)
