"""One number format for every rendered table (gaitval.tables.numbers, issue 35): no
e-notation or float noise in any Markdown or HTML cell, no more digits than the column's
quantity allows, the CSV at full precision."""
from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitval.report.index import build_index
from gaitval.tables import write_table
from gaitval.tables.numbers import (E_NOTATION, column_format, display_name, format_value,
                                    number, to_display)

ROOT = Path(__file__).resolve().parents[1]
NUMBER = re.compile(r"^-?\d+(\.(\d+))?$")


# -- scanning rendered tables -------------------------------------------------------------
def md_tables(path: Path) -> list[tuple[list[str], list[list[str]]]]:
    """Every pipe table of a Markdown file: (header, rows)."""
    out, cur = [], None
    for ln in path.read_text(encoding="utf-8").splitlines():
        if ln.startswith("| "):
            cells = [c.strip().replace("\\|", "|")
                     for c in re.split(r"(?<!\\)\|", ln.strip())[1:-1]]
            if cur is None:
                cur = (cells, [])
                out.append(cur)
            else:
                cur[1].append(cells)
        elif ln.startswith("|---"):
            continue
        else:
            cur = None
    return out


class _Tables(HTMLParser):
    """The tables of index.html, each with the id of the ``<h3>`` above it."""

    def __init__(self):
        super().__init__()
        self.tables, self.anchor, self.cell, self.row = [], "verdicts", None, None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "h3" and a.get("id"):
            self.anchor = a["id"]
        elif tag == "table":
            self.tables.append((self.anchor, []))
        elif tag == "tr" and self.tables:
            self.row = []
            self.tables[-1][1].append(self.row)
        elif tag in ("td", "th") and self.row is not None:
            self.cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self.cell is not None:
            self.row.append("".join(self.cell).strip())
            self.cell = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell.append(data)


def html_tables(path: Path) -> list[tuple[str, list[str], list[list[str]]]]:
    p = _Tables()
    p.feed(path.read_text(encoding="utf-8"))
    return [(anchor, rows[0], rows[1:]) for anchor, rows in p.tables if rows]


def problems(table: str, header: list[str], rows: list[list[str]],
             names: dict[str, str] | None = None) -> list[str]:
    """Cells with e-notation, ``nan``/``<NA>`` or more decimals than the column's format
    (a value below its decimals is shown with two significant figures instead, never as
    zero).  ``names``: rendered header (a label) -> the column's display name."""
    out = []
    for row in rows:
        for h, cell in zip(header, row):
            if E_NOTATION.search(cell) or cell in ("nan", "NaN", "<NA>", "None", "inf"):
                out.append(f"{table}.{h}: {cell!r}")
                continue
            m = NUMBER.match(cell)
            if m and table != "verdicts":
                f = column_format((names or {}).get(h, h), table)
                if f.kind == "sig":                        # significant figures
                    continue
                allowed = {"p": 3, "int": 1, "fixed": f.decimals}.get(f.kind, 3)
                small = 0 < abs(float(cell.replace("−", "-"))) < 10 ** -allowed \
                    and len(m.group(2) or "") <= allowed + 12
                if len(m.group(2) or "") > allowed and not small:
                    out.append(f"{table}.{h}: {cell!r} has more than {allowed} decimals")
    return out


def header_names(csv: Path) -> dict[str, str]:
    """Rendered header (label) -> display name, of the table whose CSV is ``csv``."""
    if not csv.is_file():
        return {}
    from gaitval.tables.labels import label

    cols = to_display(pd.read_csv(csv), csv.stem).columns
    return {label(c): c for c in cols}


def scan_report(rd: Path) -> tuple[int, list[str]]:
    """(cells scanned, problems) over every table .md, verdicts.md and index.html."""
    n, bad = 0, []
    for md in sorted((rd / "tables").glob("*.md")) + [rd / "verdicts.md"]:
        for header, rows in md_tables(md):
            n += sum(len(r) for r in rows)
            bad += problems(md.stem, header, rows, header_names(md.with_suffix(".csv")))
    for anchor, header, rows in html_tables(rd / "index.html"):
        n += sum(len(r) for r in rows)
        names = header_names(rd / "tables" / f"{anchor}.csv")
        bad += [f"html {p}" for p in problems(anchor, header, rows, names)]
    return n, bad


# -- the format ---------------------------------------------------------------------------
def test_float_noise_is_an_honest_zero_never_e_notation():
    assert format_value(-1.68e-18, "diff_mean_s", "ultrasonic_table3") == "0.000"
    assert format_value(0.0, "diff_mean_s", "ultrasonic_table3") == "0.000"


def test_a_non_zero_value_is_never_printed_as_zero():
    """Below its column's decimals a value gets two significant figures (Table 8's
    0.000246, Table C1's small SS), never 0.000 nor -0.000 nor e-notation."""
    assert format_value(-7.91e-05, "diff_mean_m", "ultrasonic_table2") == "-0.000079"
    assert format_value(-0.0004, "bias", None) == "-0.00040"
    assert format_value(0.000246, "mean", "ultrasonic_table8") == "0.00025"
    assert format_value(0.0031, "SS", "ultrasonic_tableC1") == "0.0031"
    assert format_value(0.0134, "SS", "ultrasonic_tableC1") == "0.013"   # significant figures
    assert format_value(1.3, "SS_published", "ultrasonic_tableC1") == "1.3"
    assert format_value(0.04, "n", None) == "0.040"                 # a count's mean
    assert format_value(0.0123, "mean", "ultrasonic_table8") == "0.012"   # unchanged
    assert format_value(float("inf"), "x") == "∞"
    assert format_value(np.nan, "x") == "" and format_value(pd.NA, "x") == ""


def test_p_values_counts_rates_and_per_cent():
    assert format_value(4.85e-9, "p") == "< 0.001" and format_value(0.0413, "fast_p") == "0.041"
    assert format_value(0.0, "p_published") == "< 0.001"            # the paper's 0.000
    assert format_value(14.0, "n_success_published") == "14"        # a count stored as float
    assert display_name("occlusion_rate") == "occlusion_pct"
    assert column_format("success_rate").scale == 100.0
    assert format_value(89.2857, "success_pct") == "89.3"
    assert format_value(46.0841, "improvement_pct", "rollator_improvement") == "46.1"


def test_one_unit_and_precision_per_column():
    """pole_residual_m mixed 2.71e-05, 0.000669, 0.001: now one column in mm."""
    df = pd.DataFrame({"trial": ["a", "b", "c"], "pole_residual_m": [2.71e-05, 0.000669, 0.001]})
    from gaitval.tables.numbers import format_frame
    shown = format_frame(df, "study_registration_default")
    assert list(shown.columns) == ["trial", "pole_residual_mm"]
    assert list(shown["pole_residual_mm"]) == ["0.03", "0.67", "1.00"]
    # the rollator's Table I in the paper's cm; the unit column follows
    t1 = pd.DataFrame({"unit": ["m", "m/s"], "rmse_kf": [0.0973, 0.1044],
                       "rmse_kf_published": [0.0973, 0.1044]})
    s1 = format_frame(t1, "rollator_table1")
    assert list(s1["unit"]) == ["cm", "cm/s"] and list(s1["rmse_kf"]) == ["9.73", "10.44"]
    # a paper table keeps the paper's unit: TUG RMSE in m with three decimals
    assert format_value(0.05124, "rmse_x_m", "tug_table4") == "0.051"


def test_number_in_a_sentence_has_no_e_notation():
    assert number(0.000123) == "0.000123" and number(46.084) == "46.1"
    assert number(1234.4) == "1234" and number(np.nan) == "n/a" and number(0) == "0"


# -- every rendered table -----------------------------------------------------------------
def test_every_rendered_table_of_an_adversarial_report_is_clean(tmp_path):
    """Tables with float noise, tiny p-values, counts with gaps and mixed magnitudes,
    under the stems the pipeline uses; every Markdown and HTML cell is scanned."""
    rd = tmp_path / "reports" / "x"
    rng = np.random.default_rng(3)
    write_table(pd.DataFrame({
        "subject": ["US01", "US02", "US03"], "n_strides": [246.0, np.nan, 231.0],
        "diff_mean_s": [-1.68e-18, -7.91e-05, 0.0], "rmse_s": rng.random(3) * 1e-2,
        "rmse_s_published": [0.042, 0.03, 0.027], "p": [4.85e-9, 0.04134, np.nan]}),
        rd / "tables" / "ultrasonic_table3", caption="T3")
    write_table(pd.DataFrame({
        "trial": ["t1", "t2", "t3"], "pole_residual_m": [2.71e-05, 0.000669, 0.001],
        "clock_drift_ppm": [1e-7, 30.25, -12.5], "yaw_deg": [179.2, 1e-12, -0.00001]}),
        rd / "tables" / "study_registration_x", caption="Registration")
    write_table(pd.DataFrame({
        "statistic": ["RMSE"], "improvement_pct": [46.0841],
        "improvement_pct_published_cells": [30.123456], "cells": [16]}),
        rd / "tables" / "rollator_improvement", caption="Improvement")
    write_table(pd.DataFrame({
        "method": ["tug_m1"], "occlusion_rate": [0.0503856], "occlusion_rate_published":
        [0.054], "rmse_x_m": [0.0133732], "rmse_x_m_published": [0.042]}),
        rd / "tables" / "tug_table4", caption="T4")
    build_index(rd, study_names=["x"])
    n, bad = scan_report(rd)
    assert n > 60 and bad == []
    md = (rd / "tables" / "ultrasonic_table3.md").read_text()
    assert "| US01 | 246 | 0.000 |" in md and "< 0.001" in md
    html = (rd / "index.html").read_text()
    assert ">0.03<" in html and ">46.1<" in html                    # same strings as .md
    csv = pd.read_csv(rd / "tables" / "study_registration_x.csv")
    assert csv["pole_residual_m"].iloc[0] == pytest.approx(2.71e-05)   # full precision


def test_every_rendered_table_of_a_built_report_is_clean():
    """The report built in this checkout (`python3 run.py report`, reports/<run>/)."""
    built = sorted(p.parent for p in (ROOT / "reports").glob("*/index.html"))
    if not built:
        pytest.skip("no report built in this checkout (python3 run.py report)")
    for rd in built:
        n, bad = scan_report(rd)
        assert n > 0 and bad == [], (rd, bad[:20])
