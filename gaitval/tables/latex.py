"""LaTeX of one table through pandas' ``Styler.to_latex``: booktabs, escaping, page fit.

Every ``.tex`` gaitval writes compiles with pdflatex inside :data:`PREAMBLE` (the packages
``booktabs``, ``longtable``, ``pdflscape``, ``array`` and ``[T1]{fontenc}``; Debian:
texlive-latex-base, texlive-latex-recommended, texlive-latex-extra).  What the renderer
does so that it does:

* **Headers.** Each column's label with its unit (:mod:`gaitval.tables.labels`), never
  its machine name (the CSV keeps those).
* **Escaping.** Every header, cell, caption and note goes through
  :func:`~gaitval.tables.latex_text.latex_text`: the ten LaTeX specials (``\\ & % $ # _ { }
  ~ ^``) become their text commands and Unicode the tables use (Δ ≥ ≤ ± ∓ − × → · √ σ ² – —
  … §, any Greek letter) becomes a LaTeX command wrapped in ``\\ensuremath`` where it is
  maths, so adjacent symbols never meet as ``$$``. Latin-1 letters (é, ü) are left to
  ``[T1]{fontenc}``; anything else is printed as ``[U+XXXX]`` rather than breaking the
  compile.  The inline Markdown of captions and notes (code, bold, italics, links) becomes
  ``\\texttt``, ``\\textbf``, ``\\emph`` and plain text.
* **Numbers.** The report's one number format (:func:`gaitval.tables.numbers.format_value`,
  by column and table: the same text as the Markdown and HTML, never e-notation; p-values
  as ``< 0.001``); minus signs as maths minus; numeric columns right-aligned.
* **Published beside reproduced.** ``<q>_published`` moves right after ``<q>`` under one
  header ``<q>`` with sub-columns *ours* and *paper* (``\\multicolumn`` + ``\\cmidrule``).
* **Page fit.**  Column widths are estimated from their longest entry and header (0.6 em a
  character).  A table that fits a portrait article text width is set in
  ``\\footnotesize``; a wider one in landscape (``pdflscape``) in ``\\scriptsize``.  Long
  text columns share the width left by the others as ragged-right ``p{..}`` paragraphs
  (a justified narrow column is all underfull lines); a long header over short entries
  breaks between its words.  A table that still does not fit is split into parts
  that each repeat its *key columns* (:func:`key_columns`: the leading columns that tell
  the rows apart, e.g. ``method`` and ``tug_phase``), results first and descriptive text
  last.  A text column of sentences (entries over :data:`PROSE_CHARS` characters) is a
  full-width line under its row.  The parts are one ``table`` float when their estimated
  height fits the page, else longtables (page breaks, repeated header) with the
  notes after them as a paragraph that may break; tables of more than :data:`LONG_ROWS`
  rows are always longtables.
* **Checked as pages.**  :func:`~gaitval.tables.latex_compile.compile_tables` (``python -m
  gaitval.tables.latex_compile``) compiles each file inside :data:`PREAMBLE`, after a
  paragraph of an article page, and fails it on a pdflatex error, "Float too large", an
  overfull or underfull box, a runaway argument, or a listing of too few lines a page.

Same input, same bytes: nothing here depends on time or the machine.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd

from gaitval.tables.labels import label
from gaitval.tables.latex_text import cell_text, format_cell, is_missing, latex_text, md_to_latex


#: What a document needs to \input any gaitval table (tests/test_latex_compile.py uses it).
PREAMBLE = "\n".join([
    r"\documentclass{article}",
    r"\usepackage[T1]{fontenc}",
    r"\usepackage[utf8]{inputenc}",
    r"\usepackage{booktabs}",
    r"\usepackage{longtable}",
    r"\usepackage{pdflscape}",
    r"\usepackage{array}",
])


#: Rows above which a table is a longtable.
LONG_ROWS = 40
#: Page fit (article class): text width in pt and font size in pt of a portrait table
#: (\footnotesize) and a landscape one (\scriptsize, \tabcolsep 4pt); a character is taken
#: as 0.6 em wide (measured: 0.56 em for letters, 0.6 em with \\_).
PORTRAIT = {"width_pt": 345.0, "height_pt": 550.0, "size_pt": 8.0, "baseline_pt": 9.5,
            "tabcolsep_pt": 6.0}
LANDSCAPE = {"width_pt": 540.0, "height_pt": 345.0, "size_pt": 7.0, "baseline_pt": 8.0,
             "tabcolsep_pt": 4.0}
#: A text column whose entries average more characters than this is prose (a sentence
#: per row): it is set as a full-width line under its row, not as a column.
PROSE_CHARS = 120
#: Width (pt) the ragged-right paragraph columns leave free for the error of the other
#: columns' estimated widths.
FLEX_MARGIN_PT = 2.0
#: A part taller than this fraction of the page's height is a longtable, not a float.
FLOAT_FRACTION = 0.8


def _plain_len(v, column: str, table: str | None) -> int:
    """Printed width of a cell in characters (for the page-fit estimate)."""
    return 0 if is_missing(v) else len(cell_text(v, column, table))


def _numeric(col: pd.Series) -> bool:
    vals = [v for v in col if not is_missing(v)]
    return bool(vals) and all(isinstance(v, (int, float, np.integer, np.floating))
                              and not isinstance(v, (bool, np.bool_)) for v in vals)


def _groups(df: pd.DataFrame) -> list[list[str]]:
    """Columns in display order, ``<q>`` and ``<q>_published`` as one group."""
    cols = [str(c) for c in df.columns]
    out, used = [], set()
    for c in cols:
        if c in used:
            continue
        if c.endswith("_published") and c[:-10] in cols:
            continue                                  # placed with its quantity
        pub = f"{c}_published"
        group = [c, pub] if pub in cols else [c]
        used.update(group)
        out.append(group)
    return out


def _col_info(df: pd.DataFrame, col: str, table: str | None) -> dict:
    """Natural width (characters, entries and header), the narrowest a paragraph column
    may get (its longest word up to 17 characters -- longer ones may break -- or header
    piece between underscores, at least 8) and the kind."""
    cells = max([_plain_len(v, col, table) for v in df[col]] + [0])
    num = _numeric(df[col])
    words = [len(w) for v in df[col] if isinstance(v, str) for w in v.split()]
    head = label(col)
    return {"num": num, "chars": max(cells, len(head)), "cells": cells,
            "min": max([8, min(max(words + [0]), 17)]
                       + [len(w) for w in re.split(r"[_ ]", head)]),
            "head": max(len(w) for w in re.split(r"(?<=[_ ])", head)),
            "shrink": not num and cells > 12}


def _p(width_pt: float) -> str:
    """A paragraph column, set ragged right (a justified narrow column is all underfull
    lines)."""
    return rf">{{\raggedright\arraybackslash}}p{{{width_pt:.1f}pt}}"


def _layout(groups, info, page) -> tuple[dict[str, str], bool]:
    """Column formats for one page kind and whether the table fits its width.

    Numbers and short text keep their natural width (``r``/``l``); long text columns
    share what is left as ragged-right ``p{..pt}`` paragraphs (water-filling: a column
    narrower than its share keeps its natural width); a pair (``ours``/``paper``) is at
    least as wide as its header."""
    cw, pad = 0.6 * page["size_pt"], 2 * page["tabcolsep_pt"]
    specs, fixed, flex = {}, 0.0, []
    for g in groups:
        if len(g) == 1 and info[g[0]]["shrink"]:
            flex.append(g[0])
            continue
        inner = sum(max(info[c]["cells"], 5) * cw + pad for c in g)
        for c in g:
            specs[c] = "r" if info[c]["num"] else "l"
        if len(g) == 2:                           # a header over ours/paper: no break
            head = (len(label(g[0])) + 3) * cw + pad
        elif info[g[0]]["chars"] > max(info[g[0]]["cells"], info[g[0]]["head"]):
            # a long header over short entries breaks between its words
            w = max(info[g[0]]["cells"], info[g[0]]["head"] + 2, 5) * cw
            align = r"\raggedleft" if info[g[0]]["num"] else r"\raggedright"
            specs[g[0]] = rf">{{{align}\arraybackslash}}p{{{w:.1f}pt}}"
            head = w + pad
        else:
            head = info[g[0]]["chars"] * cw + pad
        fixed += max(inner, head)
    avail = page["width_pt"] - fixed - pad * len(flex)
    left = sorted(flex, key=lambda c: (info[c]["chars"], c))
    while left:
        share = avail / len(left)
        c = left[0]
        if info[c]["chars"] * cw <= share:
            specs[c], avail = "l", avail - info[c]["chars"] * cw
            left.pop(0)
            continue
        # the paragraph columns leave FLEX_MARGIN_PT of the width unused: the widths of
        # the other columns are estimates (0.6 em a character), and a row of them 0.36 pt
        # wider than estimated overfilled the line (tiny's tug_failures)
        share = (avail - FLEX_MARGIN_PT) / len(left)
        for c in left:
            w = max(share, info[c]["min"] * cw)
            specs[c] = _p(w)
            avail -= w
        avail += FLEX_MARGIN_PT
        break
    return specs, avail >= -0.5


def _is_float_col(col: pd.Series) -> bool:
    vals = [v for v in col if not is_missing(v)]
    return any(isinstance(v, (float, np.floating)) and not float(v).is_integer()
               for v in vals)


def _determined(df: pd.DataFrame, by: list[str], col: str) -> bool:
    """Whether ``by`` determines ``col`` (one value of ``col`` per combination)."""
    keyed = df[by + [col]].astype(str)
    return bool((keyed.groupby(by, dropna=False)[col].nunique() <= 1).all())


def key_columns(df: pd.DataFrame) -> list[str]:
    """The columns that say what a row is, repeated in every part of a split table.

    Candidates are the leading columns before the first column with fractional numbers
    (or the first ``*_published``): names, labels, numbers of scenario or subject.  Of
    them a column is kept unless the kept ones already determine it (``label`` beside
    ``method``, ``subject`` beside ``subject_no``), until the kept ones tell the rows
    apart.  Of two columns that determine each other the text one is kept (``scenario``
    rather than ``scenario_no``).  At least the first column.
    """
    cols = [str(c) for c in df.columns]
    if df.empty or not cols:
        return cols[:1]
    cand = []
    for c in cols:
        if c.endswith("_published") or _is_float_col(df[c]):
            break
        cand.append(c)
    kept: list[str] = []
    for c in cand:
        if kept and _determined(df, kept, c):
            last = kept[-1]
            if (_numeric(df[last]) and not _numeric(df[c])
                    and _determined(df, [c], last)):
                kept[-1] = c                      # the same key, in words
            continue
        kept.append(c)
        if not df.duplicated(subset=kept).any():
            break
    return kept or cols[:1]


def _split(keys, rest, info, page) -> list[list[list[str]]]:
    """Parts that fit ``page``, each repeating the key columns ``keys`` (groups)."""
    parts, cur = [], []
    for g in rest:
        if cur and not _layout(keys + cur + [g], info, page)[1]:
            parts.append(keys + cur)
            cur = []
        cur.append(g)
    parts.append(keys + cur)
    return parts


def _head(name: str) -> str:
    """A column header: the column's label with its unit (:mod:`gaitval.tables.labels`)."""
    return latex_text(label(name))


def _col_width_pt(spec: str, info: dict, page: dict) -> float:
    m = re.search(r"p\{([0-9.]+)pt\}", spec)
    return float(m.group(1)) if m else info["chars"] * 0.6 * page["size_pt"]


def _height_pt(df: pd.DataFrame, groups, specs, info, page, *, table: str | None,
               caption: str, notes: list[str]) -> float:
    """A generous estimate of a part's height as a float: caption, header, rows (a row
    is as tall as its tallest paragraph cell) and notes."""
    cw, line = 0.6 * page["size_pt"], page["baseline_pt"]
    cols = [c for g in groups for c in g]
    widths = {c: max(_col_width_pt(specs[c], info[c], page), 1.0) for c in cols}
    para = [c for c in cols if "p{" in specs[c]]

    def lines(text_len: float, width: float) -> int:
        return max(1, math.ceil(1.15 * text_len * cw / width))

    rows = 0.0
    for _, row in df[cols].iterrows():
        n = max([lines(_plain_len(row[c], c, table), widths[c]) for c in para] + [1])
        rows += n * line
    head = max([lines(len(label(c)), widths[c]) for c in para] + [1]) * line
    head += line if any(len(g) == 2 for g in groups) else 0
    text_w = page["width_pt"]
    cap = math.ceil(1.15 * (len(caption) + 12) * 5.0 / text_w) * 12.0 + 10
    note = sum(math.ceil(1.15 * len(n) * cw / text_w) for n in notes) * line + 6
    return cap + head + rows + note + 3 * 4


def _render_part(df: pd.DataFrame, groups: list[list[str]], specs: dict[str, str], *,
                 caption: str, label: str, table: str | None, long: bool) -> str:
    cols = [c for g in groups for c in g]
    paired = any(len(g) == 2 for g in groups)
    if paired:
        tuples = [(_head(g[0]), "") if len(g) == 1 else
                  (_head(g[0]), sub) for g in groups
                  for sub in (["ours", "paper"] if len(g) == 2 else [None])]
        tuples = [(a, b or "") for a, b in tuples]
        columns = pd.MultiIndex.from_tuples(tuples)
    else:
        columns = pd.Index([_head(c) for c in cols])
    body = pd.DataFrame([[format_cell(v, c, table) for c, v in zip(cols, row)]
                         for row in df[cols].itertuples(index=False)], columns=columns)
    styler = body.style.hide(axis="index").format(lambda v: v)
    tex = styler.to_latex(
        column_format="".join(specs[c] for c in cols), hrules=True,
        environment="longtable" if long else None,
        position=None if long else "htbp", position_float=None if long else "centering",
        caption=caption, label=f"tab:{label}", multicol_align="c", sparse_columns=True)
    if paired:                                   # a rule under each ours/paper header
        rules, j = [], 1
        for g in groups:
            if len(g) == 2:
                rules.append(rf"\cmidrule(lr){{{j}-{j + 1}}}")
            j += len(g)
        first = tex.split("\\toprule\n", 1)[1].split("\n", 1)[0]
        tex = tex.replace(first + "\n", first + "\n" + " ".join(rules) + "\n")
    return tex


def _with_prose(tex: str, df: pd.DataFrame, prose: list[str], ncols: int, page: dict, *,
                table: str | None, long: bool) -> str:
    """Each row of ``tex`` followed by its prose columns as one full-width line."""
    head, body = tex.rsplit("\\endlastfoot\n" if long else "\\midrule\n", 1)
    rows, tail = body.split("\\bottomrule", 1) if not long else (body, "")
    lines = rows.split(" \\\\\n")
    width = page["width_pt"] - 2 * page["tabcolsep_pt"]
    out = []
    for k, ln in enumerate(lines[:len(df)]):
        text = "; ".join(rf"\textit{{{latex_text(c)}}}: {format_cell(df[c].iloc[k], c, table)}"
                         for c in prose if not is_missing(df[c].iloc[k]))
        out.append(ln + " \\\\\n" + rf"\multicolumn{{{ncols}}}"
                   rf"{{>{{\raggedright\arraybackslash}}p{{{width:.1f}pt}}}}"
                   rf"{{\quad {text}}} \\[2pt]" + "\n")
    rest = " \\\\\n".join(lines[len(df):])
    sep = "\\endlastfoot\n" if long else "\\midrule\n"
    return head + sep + "".join(out) + rest + ("\\bottomrule" + tail if not long else "")


def to_latex(df: pd.DataFrame, *, caption: str, label: str, notes: list[str] | None = None,
             keys: list[str] | None = None) -> str:
    """The table as LaTeX that fits a page, compiling inside :data:`PREAMBLE`.

    Portrait if it fits the text width, else landscape, else split into landscape parts
    that each repeat the key columns (``keys``, default :func:`key_columns`).  A part is a
    ``table`` float when its estimated height fits the page with room to spare, else a
    ``longtable`` (page breaks, repeated header) with the notes after it as a paragraph.
    ``label`` is also the table's name for the number format
    (:func:`gaitval.tables.numbers.format_value`).
    """
    table = label
    df = df.reset_index(drop=True)
    df.columns = [str(c) for c in df.columns]
    notes = list(notes or [])
    info = {c: _col_info(df, c, table) for c in df.columns}
    prose = [c for c in df.columns if not info[c]["num"] and len(df.columns) > 1
             and np.mean([_plain_len(v, c, table) for v in df[c]] or [0]) > PROSE_CHARS]
    groups = [g for g in _groups(df) if g[0] not in prose]
    keys = [k for k in (keys if keys is not None else key_columns(df.drop(columns=prose)))
            if k in df.columns]
    page, parts, part_specs = _fit(groups, info, keys)
    cap = md_to_latex(caption)
    caps = [cap if len(parts) == 1 else f"{cap} (part {i + 1} of {len(parts)})"
            for i in range(len(parts))]
    long = _is_long(df, parts, part_specs, info, page, table=table, caps=caps, notes=notes,
                    prose=prose)
    return _document(df, parts, part_specs, page, prose, caps=caps, notes=notes, label=label,
                     table=table, long=long)


def _fit(groups, info, keys) -> tuple[dict, list, list]:
    """The page (portrait, else landscape) and the parts the column groups are split
    into to fit it, each part with its column specs (:func:`to_latex`)."""
    page = PORTRAIT
    specs, fits = _layout(groups, info, page)
    parts = [groups]
    if not fits:
        page = LANDSCAPE
        specs, fits = _layout(groups, info, page)
        key_groups = [g for g in groups if g[0] in keys] or groups[:1]
        rest = [g for g in groups if g not in key_groups]
        if not fits and len(rest) > 1:
            # results first, descriptions (text, yes/no) in the last part(s)
            text = [g for g in rest if not any(info[c]["num"] for c in g)]
            parts = _split(key_groups, [g for g in rest if g not in text] + text, info,
                           page)
    part_specs = [specs] if len(parts) == 1 else [_layout(p, info, page)[0] for p in parts]
    return page, parts, part_specs


def _is_long(df: pd.DataFrame, parts, part_specs, info, page, *, table, caps, notes,
             prose) -> bool:
    """A longtable rather than one float: more than :data:`LONG_ROWS` rows, or taller
    than :data:`FLOAT_FRACTION` of the page (:func:`to_latex`)."""
    # a float must fit the page (the text height, or the text width in landscape) with
    # room for the text around it; anything taller, or long, is a longtable
    prose_lines = sum(math.ceil(1.15 * _plain_len(v, c, table) * 0.6 * page["size_pt"]
                                / page["width_pt"]) for c in prose for v in df[c])
    return len(df) > LONG_ROWS or sum(
        _height_pt(df, p, part_specs[i], info, page, table=table, caption=caps[i],
                   notes=notes if i == len(parts) - 1 else []) + 12
        for i, p in enumerate(parts)) + prose_lines * page["baseline_pt"] \
        > FLOAT_FRACTION * page["height_pt"]


def _document(df: pd.DataFrame, parts, part_specs, page, prose, *, caps, notes, label,
              table, long: bool) -> str:
    """The table's LaTeX: its parts in one float (or as longtables), landscape when the
    page is, the notes after them (:func:`to_latex`)."""
    landscape = page is LANDSCAPE
    lines = len(df) * len(parts) + sum(math.ceil(len(n) / 100) for n in notes)
    out = [f"% gaitval table {label}: {lines} lines; pdflatex with booktabs, "
           "longtable, pdflscape, array, [T1]{fontenc} (gaitval.tables.latex.PREAMBLE)."]
    if landscape:
        out.append(r"\begin{landscape}")
    # A float resets the font to \normalsize, so the size goes inside it (after
    # \centering); a longtable is no float and takes it from the enclosing group.
    size = r"\scriptsize\setlength{\tabcolsep}{4pt}" if landscape else r"\footnotesize"
    out.append("{" + size if long else "{")
    if not long:                 # one float holds every part, so they stay together
        out += [r"\begin{table}[htbp]", r"\centering", size]
    note_lines = [md_to_latex(n) + r"\par" for n in notes]
    for i, part in enumerate(parts):
        plabel = label if i == 0 else f"{label}-{i + 1}"
        tex = _render_part(df, part, part_specs[i], caption=caps[i], label=plabel,
                           table=table, long=long).rstrip("\n")
        if prose and i == len(parts) - 1:
            tex = _with_prose(tex, df, prose, len([c for g in part for c in g]), page,
                              table=table, long=long)
        if not long:
            tex = tex.replace("\\begin{table}[htbp]\n\\centering\n", "", 1)
            tex = tex.replace("\n\\end{table}", "")
            if i:
                out.append(r"\par\bigskip")
        out.append(tex)
    if notes and long:                            # a paragraph that may break pages
        out.append("\n".join([r"{\raggedright"] + note_lines + ["}"]))
    elif notes:                                   # the notes stay with their table
        out.append("\n".join([r"\par\smallskip\noindent\begin{minipage}{\linewidth}"
                              r"\raggedright"] + note_lines + [r"\end{minipage}"]))
    if not long:
        out.append(r"\end{table}")
    out.append("}")
    if landscape:
        out.append(r"\end{landscape}")
    return "\n".join(out) + "\n"
