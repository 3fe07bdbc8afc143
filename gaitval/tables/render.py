"""Render one tidy table as ``<stem>.csv``, ``<stem>.md`` and ``<stem>.tex``.

Every paper table goes through :func:`write_table`, so all three files always say the same
thing: the CSV is the tidy source (units in column names), the Markdown and the LaTeX
print each column's label with its unit (:mod:`gaitval.tables.labels`); the Markdown
carries the caption and notes for the report, the LaTeX (:mod:`gaitval.tables.latex`, pandas' Styler with
booktabs) is ready for a manuscript.  The Markdown and the LaTeX get the table in its
display units (:func:`gaitval.tables.numbers.to_display`: per cent for rates, mm for
registration residuals, cm for the rollator's Table I) and every Markdown cell is printed by
:func:`gaitval.tables.numbers.format_value`, the format the HTML report uses too: fixed
decimals per quantity, ``< 0.001`` for p-values, never e-notation.  The CSV keeps full
precision in SI units.  Same input, same bytes.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from gaitval.io.atomic import write_text
from gaitval.tables.labels import label
from gaitval.tables.numbers import format_value, to_display


def to_markdown(df: pd.DataFrame, table: str | None = None) -> str:
    """``df`` (in display units, :func:`gaitval.tables.numbers.to_display`) as a Markdown
    table, each header the column's label (:func:`gaitval.tables.labels.label`), each
    cell by :func:`gaitval.tables.numbers.format_value`."""
    cols = [str(c) for c in df.columns]
    heads = [label(c) for c in cols]
    lines = ["| " + " | ".join(heads) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for row in df.itertuples(index=False, name=None):
        lines.append("| " + " | ".join(format_value(v, c, table).replace("|", "\\|")
                                       for c, v in zip(cols, row)) + " |")
    return "\n".join(lines)


def cite_columns(text: str, df: pd.DataFrame, shown: pd.DataFrame) -> str:
    """``text`` (a caption or note) with each machine name of a column of the table
    (``ft_forward``, `` `diff_mean` ``; the CSV's or the display one) replaced by the
    header the reader sees, in italics (``_False tracking, forward_``)."""
    import re

    names = {}
    for orig, disp in zip(df.columns, shown.columns):
        for name in {str(orig), str(disp)}:
            if "_" in name:
                names[name] = label(disp)
    for name in sorted(names, key=len, reverse=True):
        n = re.escape(name)
        text = re.sub(rf"`{n}`|(?<![\w`]){n}(?![\w`])",
                      lambda m, n=name: f"_{names[n]}_", text)
    return text


def write_table(df: pd.DataFrame, stem: str | Path, *, caption: str,
                notes: list[str] | None = None,
                csv_float_format: str = "%.6g") -> list[Path]:
    """Write ``df`` to ``<stem>.csv``, ``<stem>.md`` and ``<stem>.tex`` (atomically).

    Parameters
    ----------
    df : DataFrame
        The tidy table.  Put published values in their own columns (e.g.
        ``rmse_x_m_published`` beside ``rmse_x_m``) so they sit side by side.
    stem : path without suffix, e.g. ``reports/tables/tug_table4``.
    caption : str
        One paragraph: what the table is, which paper table it reproduces.
    notes : list of str
        Deviations from the paper, disagreements and their likely causes.
    csv_float_format : str
        The CSV's floats (full precision); the Markdown and LaTeX print each column in
        its quantity's format (:mod:`gaitval.tables.numbers`).

    Returns
    -------
    list of Path
        The three files written.
    """
    stem = Path(stem)
    csv_text = df.to_csv(index=False, float_format=csv_float_format, lineterminator="\n")
    shown = to_display(df, stem.name)
    caption, notes = cite_columns(caption, df, shown), [cite_columns(n, df, shown)
                                                       for n in notes or []]
    md = [f"**{caption}**", "", to_markdown(shown, stem.name)]
    if notes:
        md += [""] + [f"- {n}" for n in notes]
    from gaitval.tables.latex import to_latex

    tex = to_latex(shown, caption=caption, notes=notes, label=stem.name)
    paths = [stem.with_suffix(".csv"), stem.with_suffix(".md"), stem.with_suffix(".tex")]
    write_text(paths[0], csv_text)
    write_text(paths[1], "\n".join(md) + "\n")
    write_text(paths[2], tex)
    return paths
