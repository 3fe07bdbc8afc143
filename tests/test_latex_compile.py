"""Every .tex gaitval writes compiles with pdflatex and fits its page (issues 14 and 35).

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
from gaitval.tables.latex import LANDSCAPE, key_columns, to_latex
from gaitval.tables.latex_compile import check_log, compile_tables
from gaitval.tables.latex_text import format_cell, latex_text, md_to_latex

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


def test_numbers_take_the_reports_one_format_never_e_notation():
    """Issue 35: a LaTeX cell prints what the Markdown prints (gaitval.tables.numbers),
    minus signs as maths minus; a tiny p-value is "< 0.001", not 4.85e-9 nor 0.000."""
    from gaitval.tables.numbers import format_value
    for v, col in ((0.05123, "rmse_m"), (-0.2, "bias_m"), (7, "n_trials")):
        assert format_cell(v, col) == format_value(v, col).replace(
            "-", r"\ensuremath{-}", 1)
    assert format_cell(-0.2, "bias_m").startswith(r"\ensuremath{-}")
    assert format_cell(4.8486e-09, "p") == r"\textless{} 0.001"
    assert format_cell(np.nan, "p") == "" and format_cell(True, "ok") == "yes"
    assert format_cell(float("-inf"), "x") == r"\ensuremath{-\infty}"


def test_published_column_sits_beside_its_quantity_under_one_header():
    df = pd.DataFrame({"method": ["M1"], "n": [3], "rmse_m": [0.05],
                       "rmse_m_published": [0.04]})
    tex = to_latex(df, caption="c", label="t")
    assert r"\multicolumn{2}{c}{RMSE (m)}" in tex and r"\cmidrule(lr){3-4}" in tex
    from gaitval.tables.numbers import format_value
    x, xp = format_value(0.05, "rmse_m", "t"), format_value(0.04, "rmse_m_published", "t")
    assert f"M1 & 3 & {x} & {xp}" in tex            # the Markdown's number format
    assert r"\toprule" in tex and r"\bottomrule" in tex      # booktabs


def test_long_tables_are_longtables_and_wide_ones_landscape_or_split():
    long = pd.DataFrame({"trial": [f"t{i}" for i in range(127)], "x": np.arange(127.0)})
    assert r"\begin{longtable}" in to_latex(long, caption="c", label="l")
    wide = pd.DataFrame({f"quantity_{i}": [1.0] for i in range(12)})
    assert r"\begin{landscape}" in to_latex(wide, caption="c", label="w")
    wider = pd.DataFrame({"trial": ["a"]} | {f"quantity_{i}": [1.0] for i in range(40)})
    tex = to_latex(wider, caption="c", label="w")
    assert "(part 2 of" in tex and tex.count(r"\caption{") >= 2
    assert all("Trial" in part for part in tex.split(r"\caption{")[1:])


def _headers(tex: str) -> list[str]:
    """The first header line of each part of a rendered table."""
    return [part.split("\n", 1)[1].split(" \\\\", 1)[0]
            for part in tex.split("\\toprule")[1:]]


def test_key_columns_are_the_columns_that_name_a_row():
    rollator = pd.DataFrame({"scenario_no": [1, 1, 2, 2], "scenario": ["straight"] * 2
                             + ["turn"] * 2, "subject_no": [1, 1, 1, 1],
                             "subject": ["P01"] * 4, "parameter": ["x", "y", "x", "y"],
                             "unit": ["m"] * 4, "n_kf": [5, 5, 6, 6],
                             "rmse_kf": [0.1, 0.2, 0.3, 0.4]})
    # scenario_no and scenario say the same (the words kept); subject is one value, and
    # with the parameter the rows are told apart
    assert key_columns(rollator) == ["scenario", "parameter"]
    tug4 = pd.DataFrame({"method": ["tug_m1"] * 2 + ["tug_m2"] * 2,
                         "base_method": ["tug_m1"] * 2 + ["tug_m2"] * 2,
                         "label": ["Method 1"] * 2 + ["Method 2"] * 2,
                         "tug_phase": ["forward", "turning"] * 2, "rmse_x_m": [0.1] * 4})
    assert key_columns(tug4) == ["method", "tug_phase"]     # label follows from method
    assert key_columns(pd.DataFrame({"x": [0.5], "y": [1.5]})) == ["x"]


def test_every_part_of_a_split_table_carries_all_its_key_columns():
    n = 4
    df = pd.DataFrame({"method": ["tug_m1", "tug_m1", "tug_m2", "tug_m2"],
                       "label": ["Method 1 (GNN)"] * 2 + ["Method 2 (gait phase)"] * 2,
                       "tug_phase": ["forward", "turning"] * 2}
                      | {f"quantity_number_{i}": np.linspace(0.1, 0.9, n) for i in range(12)})
    tex = to_latex(df, caption="c", label="w", notes=["a note"])
    heads = _headers(tex)
    assert len(heads) >= 2 and "(part 2 of" in tex
    for h in heads:                                   # not only the first column
        assert h.startswith("Method & TUG phase &"), h          # the columns' labels
    # the text that method determines (label) is no key: it sits in one part only
    assert len({h for h in heads if "Label" in h}) == 1    # (a longtable repeats it)
    assert tex.count(r"\begin{table}") == 1          # all parts in one float


def test_prose_is_a_full_width_line_under_its_row_and_long_tables_are_longtables():
    df = pd.DataFrame({"trial": [f"t{i}" for i in range(50)], "x_m": np.arange(50.0),
                       "evidence": ["a sentence that explains what happened, " * 5] * 50})
    tex = to_latex(df, caption="c", label="p", notes=["n " * 300])
    assert r"\begin{longtable}" in tex and r"\begin{table}" not in tex
    assert tex.count(r"\multicolumn{2}{>{\raggedright\arraybackslash}p{") == 50
    assert "evidence" not in _headers(tex)[0]
    assert tex.index(r"\end{longtable}") < tex.index("n n n")   # notes after, breakable


def test_the_log_check_names_each_page_fit_problem():
    page = "GAITVAL-FIRST-PAGE 2\nGAITVAL-NEXT-PAGE 3\n"
    assert check_log(page) == ("", {k: 0 for k in check_log(page)[1]}, 1)
    assert check_log(page + "LaTeX Warning: Float too large for page by 235.0pt on input "
                     "line 9.")[0] == "Float too large for page by 235.0pt"
    for line, what in (("Underfull \\hbox (badness 10000) in paragraph", "underfull hbox"),
                       ("Overfull \\hbox (3.1pt too wide) in alignment", "overfull hbox"),
                       ("Overfull \\vbox (2.0pt too high) has occurred", "overfull vbox"),
                       ("Runaway argument?", "runaway")):
        problem, counts, _ = check_log(page + line + "\n")
        assert counts[what] == 1 and what in problem, (line, problem)
    long = "GAITVAL-FIRST-PAGE 2\nGAITVAL-NEXT-PAGE 46\n"
    assert "44 pages for 82 lines" in check_log(long, lines=82)[0]
    assert check_log(long, lines=1000)[0] == ""


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
def test_adversarial_tables_fit_their_pages(tmp_path):
    """No float too large, no overfull or underfull box, no runaway argument."""
    paths = _examples(tmp_path)
    res = compile_tables(paths, tmp_path / "latex")
    failed = {p: err for p, (ok, err, _) in res.items() if not ok}
    assert not failed, failed
    assert all(sum(r.counts.values()) == 0 and r.pages >= 1 for r in res.values())


@needs_pdflatex
def test_the_page_check_fails_what_does_not_fit(tmp_path):
    """A float taller than the page, and a justified narrow column, fail the check."""
    tall = tmp_path / "tall.tex"
    tall.write_text("\\begin{table}[htbp]\\centering\n\\begin{tabular}{l}\n"
                    + "row \\\\\n" * 80 + "\\end{tabular}\n\\end{table}\n")
    narrow = tmp_path / "narrow.tex"
    narrow.write_text("\\begin{tabular}{p{30pt}}\nsome words in a justified narrow "
                      "column that cannot be set well \\\\\n\\end{tabular}\n")
    res = compile_tables([tall, narrow], tmp_path / "latex")
    (ok_n, err_n, _), (ok_t, err_t, _) = res[str(narrow)], res[str(tall)]
    assert not ok_t and err_t.startswith("Float too large for page by")
    assert not ok_n and "hbox" in err_n, err_n


@needs_pdflatex
def test_a_broken_table_is_reported_as_failing(tmp_path):
    """The compile check can fail: an unescaped ^ outside maths is a LaTeX error."""
    bad = tmp_path / "bad.tex"
    bad.write_text("\\begin{tabular}{l}\na^2 \\\\\n\\end{tabular}\n")
    (ok, err, _), = compile_tables([bad], tmp_path / "latex").values()
    assert not ok and re.search(r"Missing \$ inserted", err)
