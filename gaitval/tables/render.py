"""Render one tidy table as ``<stem>.csv``, ``<stem>.md`` and ``<stem>.tex``.

Every paper table goes through :func:`write_table`, so all three files always say the same
thing: the CSV is the tidy source (units in column names), the Markdown carries the caption
and notes for the report, the LaTeX (:mod:`gaitval.tables.latex`, pandas' Styler with
booktabs) is ready for a manuscript.  Floats are formatted with a fixed number of decimals
so the outputs are byte-identical for the same input.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.atomic import write_text


def _fmt(v, digits: int) -> str:
    if v is None or (isinstance(v, float) and np.isnan(v)):
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.{digits}f}"
    return str(v)


def to_markdown(df: pd.DataFrame, digits: int = 3) -> str:
    cols = [str(c) for c in df.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for row in df.itertuples(index=False):
        lines.append("| " + " | ".join(_fmt(v, digits).replace("|", "\\|") for v in row)
                     + " |")
    return "\n".join(lines)


def write_table(df: pd.DataFrame, stem: str | Path, *, caption: str,
                notes: list[str] | None = None, digits: int = 3,
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
    digits : int
        Decimals for floats in Markdown and LaTeX (the CSV keeps ``csv_float_format``).

    Returns
    -------
    list of Path
        The three files written.
    """
    stem = Path(stem)
    csv_text = df.to_csv(index=False, float_format=csv_float_format, lineterminator="\n")
    md = [f"**{caption}**", "", to_markdown(df, digits)]
    if notes:
        md += [""] + [f"- {n}" for n in notes]
    from gaitval.tables.latex import to_latex   # lazily: `python -m gaitval.tables.latex`

    tex = to_latex(df, caption=caption, notes=notes, label=stem.name, digits=digits)
    paths = [stem.with_suffix(".csv"), stem.with_suffix(".md"), stem.with_suffix(".tex")]
    write_text(paths[0], csv_text)
    write_text(paths[1], "\n".join(md) + "\n")
    write_text(paths[2], tex)
    return paths
