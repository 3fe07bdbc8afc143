"""Journal-ready tables over a built report (the tiny study's, built once per session by
the ``tiny_run`` fixture, as the README's report command builds it): no HTML or LaTeX
header is a machine name, every column has a declared label (gaitval.tables.labels), no
rendered cell reads zero where the CSV holds a non-zero value, and nothing a reader sees
says "seed 00N", "twin" or an issue number."""
from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

from gaitval.tables.labels import LABELS, PUBLISHED, label
from gaitval.tables.numbers import NOISE, to_display

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow          # the tiny report is built for them

sys_path_tests = Path(__file__).resolve().parent
import sys  # noqa: E402

sys.path.insert(0, str(sys_path_tests))
from test_report_numbers import html_tables, md_tables  # noqa: E402



@pytest.fixture(scope="module")
def REPORT(tiny_run) -> Path:
    return tiny_run / "reports" / "tiny"


@pytest.fixture(scope="module")
def TABLES(REPORT) -> list[Path]:
    return sorted((REPORT / "tables").glob("*.csv"))


def _tex_headers(tex: str) -> list[str]:
    """The header rows of every tabular/longtable in a .tex (between \\toprule and the
    first \\midrule of each)."""
    out = []
    for m in re.finditer(r"\\toprule\n(.*?)\\midrule", tex, re.S):
        out += [ln for ln in m.group(1).splitlines() if ln.strip()]
    return out


def test_no_html_or_latex_header_contains_an_underscore(REPORT, TABLES):
    assert TABLES
    bad = []
    for anchor, header, _ in html_tables(REPORT / "index.html"):
        bad += [f"html {anchor}: {h!r}" for h in header if "_" in h]
    for tex in sorted((REPORT / "tables").glob("*.tex")) + [REPORT / "verdicts.tex"]:
        heads = _tex_headers(tex.read_text(encoding="utf-8"))
        assert heads, tex
        bad += [f"{tex.name}: {h!r}" for h in heads if r"\_" in h or "_" in h]
    assert bad == []


def test_every_column_of_the_built_report_has_a_declared_label(TABLES):
    missing = set()
    for csv in TABLES:
        for c in to_display(pd.read_csv(csv), csv.stem).columns:
            base = c[:-len("_published")] if c.endswith("_published") else c
            if base not in LABELS:
                missing.add(f"{csv.stem}.{base}")
    assert sorted(missing) == []
    assert label("rmse_x_m_published") == LABELS["rmse_x_m"] + PUBLISHED


def _reads_zero(cell: str) -> bool:
    try:
        return float(cell.replace("−", "-")) == 0
    except ValueError:
        return False


def test_no_rendered_cell_shows_zero_for_a_non_zero_value(TABLES):
    """Each .md table (whose strings the HTML and LaTeX print too) against its CSV, cell
    by cell (the Markdown keeps the CSV's rows and columns in order)."""
    checked, bad = 0, []
    for csv in TABLES:
        df = pd.read_csv(csv)
        tables = md_tables(csv.with_suffix(".md"))
        assert tables, csv
        header, rows = tables[0]
        assert len(header) == len(df.columns) and len(rows) == len(df), csv.stem
        for i, row in enumerate(rows):
            for c, cell in zip(df.columns, row):
                v = df[c].iloc[i]
                if isinstance(v, (int, float)) and not isinstance(v, bool) \
                        and pd.notna(v) and abs(float(v)) >= NOISE:
                    checked += 1
                    if _reads_zero(cell):
                        bad.append(f"{csv.stem}.{c} row {i}: {v!r} shown as {cell!r}")
    assert checked > 500
    assert bad == []


def test_html_cells_are_the_markdown_cells(REPORT, TABLES):
    """So the zero check of the Markdown holds for the HTML too."""
    html = {a: (h, r) for a, h, r in html_tables(REPORT / "index.html")}
    for csv in TABLES:
        h, rows = html[csv.stem]
        mh, mrows = md_tables(csv.with_suffix(".md"))[0]
        assert sorted(h) == sorted(mh)
        assert sorted(map(sorted, rows)) == sorted(map(sorted, mrows))


def test_no_seed_numbers_twin_or_issue_numbers_in_what_a_reader_sees(REPORT):
    files = [REPORT / "index.md", REPORT / "index.html", REPORT / "verdicts.md",
             *(REPORT / "tables").glob("*.md"), *(REPORT / "tables").glob("*.tex")]
    bad = []
    for f in files:
        text = f.read_text(encoding="utf-8")
        for rx in (r"[Ss]eed 00\d", r"\btwin\b", r"\bissue \d+"):
            bad += [f"{f.name}: {m.group(0)!r}" for m in re.finditer(rx, text)]
    assert bad == []
