"""LaTeX of one table through pandas' ``Styler.to_latex``: booktabs, escaping, page fit.

Every ``.tex`` gaitval writes compiles with pdflatex inside :data:`PREAMBLE` (the packages
``booktabs``, ``longtable``, ``pdflscape`` and ``[T1]{fontenc}``; Debian:
texlive-latex-base, texlive-latex-recommended, texlive-latex-extra).  What the renderer
does so that it does:

* **Escaping.** Every header, cell, caption and note goes through :func:`latex_text`: the
  ten LaTeX specials (``\\ & % $ # _ { } ~ ^``) become their text commands and Unicode the
  tables use (Δ ≥ ≤ ± ∓ − × → · √ σ ² – — … §, any Greek letter) becomes a LaTeX command
  wrapped in ``\\ensuremath`` where it is maths, so adjacent symbols never meet as ``$$``.
  Latin-1 letters (é, ü) are left to ``[T1]{fontenc}``; anything else is printed as
  ``[U+XXXX]`` rather than breaking the compile.  The inline Markdown of captions and notes
  (code, bold, italics, links) becomes ``\\texttt``, ``\\textbf``, ``\\emph`` and plain text.
* **Numbers.** Floats with the table's fixed number of decimals (``digits``); a non-zero
  value that would print as zero at that precision in scientific notation
  (``4.85\\times10^{-9}``), so a p-value of 5e-9 is not shown as ``0.000``; minus signs
  as maths minus; numeric columns right-aligned.
* **Published beside reproduced.** ``<q>_published`` moves right after ``<q>`` under one
  header ``<q>`` with sub-columns *ours* and *paper* (``\\multicolumn`` + ``\\cmidrule``).
* **Page fit.** Column widths are estimated from their longest entry and header (0.6 em a
  character).  A table that fits a portrait article text width is a ``table`` float in
  ``\\footnotesize``; a wider one is set in landscape (``pdflscape``) in ``\\scriptsize``.
  Long text columns share the width left by the others as ``p{..}`` paragraphs; a table
  with numbers that still does not fit is split into parts that repeat its first column.
  Tables of more than :data:`LONG_ROWS` rows are ``longtable`` (page breaks, repeated
  header).  Notes follow the table as a small paragraph inside its float.

Same input, same bytes: nothing here depends on time or the machine.
"""
from __future__ import annotations

import math
import re
import unicodedata

import numpy as np
import pandas as pd

#: What a document needs to \input any gaitval table (tests/test_latex_compile.py uses it).
PREAMBLE = "\n".join([
    r"\documentclass{article}",
    r"\usepackage[T1]{fontenc}",
    r"\usepackage[utf8]{inputenc}",
    r"\usepackage{booktabs}",
    r"\usepackage{longtable}",
    r"\usepackage{pdflscape}",
])
#: Rows above which a table is a longtable.
LONG_ROWS = 40
#: Page fit (article class): text width in pt and font size in pt of a portrait table
#: (\footnotesize) and a landscape one (\scriptsize, \tabcolsep 4pt); a character is taken
#: as 0.6 em wide (measured: 0.56 em for letters, 0.6 em with \\_).
PORTRAIT = {"width_pt": 345.0, "size_pt": 8.0, "tabcolsep_pt": 6.0}
LANDSCAPE = {"width_pt": 540.0, "size_pt": 7.0, "tabcolsep_pt": 4.0}

_SPECIALS = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
             "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
             "^": r"\textasciicircum{}", "<": r"\textless{}", ">": r"\textgreater{}",
             "|": r"\textbar{}"}
_MATH = {"≥": r"\geq", "≤": r"\leq", "±": r"\pm", "∓": r"\mp", "−": "-", "×": r"\times",
         "→": r"\rightarrow", "←": r"\leftarrow", "↔": r"\leftrightarrow",
         "⇒": r"\Rightarrow", "·": r"\cdot", "√": r"\surd", "≈": r"\approx", "≠": r"\neq",
         "∞": r"\infty", "∈": r"\in", "∑": r"\sum", "≡": r"\equiv", "∼": r"\sim",
         "²": "^{2}", "³": "^{3}", "¹": "^{1}", "⁻": "^{-}", "°": r"^{\circ}",
         "µ": r"\mu", "∆": r"\Delta", "′": r"\prime", "⋅": r"\cdot", "∝": r"\propto"}
_TEXT = {"–": "--", "—": "---", "…": r"\dots{}", "§": r"\S{}", "‘": "`", "’": "'",
         "“": "``", "”": "''", "\u00a0": "~", "\u2009": r"\,", "\u202f": r"\,",
         "¶": r"\P{}", "•": r"\textbullet{}", "✓": "yes", "✗": "no"}
_GREEK_VARIANTS = {"FINAL SIGMA": "varsigma", "EPSILON": "epsilon", "OMICRON": "o"}


def _char(ch: str) -> str:
    if ch in _SPECIALS:
        return _SPECIALS[ch]
    if ord(ch) < 128:
        return ch
    if ch in _MATH:
        return rf"\ensuremath{{{_MATH[ch]}}}"
    if ch in _TEXT:
        return _TEXT[ch]
    name = unicodedata.name(ch, "")
    if name.startswith("GREEK ") and " LETTER " in name and "WITH" not in name:
        letter = name.split(" LETTER ", 1)[1]
        word = _GREEK_VARIANTS.get(letter, letter.lower())
        if name.startswith("GREEK CAPITAL"):
            word = word.capitalize()
            if word in ("Alpha", "Beta", "Epsilon", "Zeta", "Eta", "Iota", "Kappa", "Mu",
                        "Nu", "O", "Omicron", "Rho", "Tau", "Chi"):
                return {"Alpha": "A", "Beta": "B", "Epsilon": "E", "Zeta": "Z", "Eta": "H",
                        "Iota": "I", "Kappa": "K", "Mu": "M", "Nu": "N", "O": "O",
                        "Omicron": "O", "Rho": "P", "Tau": "T", "Chi": "X"}[word]
        return rf"\ensuremath{{\{word}}}"
    if ord(ch) < 256 and unicodedata.category(ch).startswith("L"):
        return ch                                   # é, ü, ß: [T1]{fontenc} + utf8
    plain = unicodedata.normalize("NFKD", ch).encode("ascii", "ignore").decode()
    return "".join(_char(c) for c in plain) if plain else f"[U+{ord(ch):04X}]"


def latex_text(s: str) -> str:
    """Plain text as LaTeX text: specials escaped, Unicode as LaTeX commands."""
    return "".join(_char(ch) for ch in str(s))


_MD = re.compile(r"`([^`]+)`|\*\*([^*]+)\*\*|\[([^\]]+)\]\(([^)]+)\)"
                 r"|(?<![\w*])_([^_]+)_(?![\w])")


def md_to_latex(s: str) -> str:
    """The report's inline Markdown (code, bold, links, italics) as LaTeX."""
    out, pos = [], 0
    for m in _MD.finditer(s):
        out.append(latex_text(s[pos:m.start()]))
        code, bold, link, _url, em = m.groups()
        if code is not None:
            out.append(rf"\texttt{{{latex_text(code)}}}")
        elif bold is not None:
            out.append(rf"\textbf{{{latex_text(bold)}}}")
        elif link is not None:
            out.append(latex_text(link))
        else:
            out.append(rf"\emph{{{latex_text(em)}}}")
        pos = m.end()
    out.append(latex_text(s[pos:]))
    return "".join(out)


def _is_missing(v) -> bool:
    if v is None or v is pd.NA or v is pd.NaT:
        return True
    return isinstance(v, (float, np.floating)) and math.isnan(v)


def format_cell(v, digits: int) -> str:
    """One cell as LaTeX at ``digits`` decimals (see the module docstring)."""
    if _is_missing(v):
        return ""
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v)).replace("-", r"\ensuremath{-}")
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if math.isinf(x):
            return r"\ensuremath{-\infty}" if x < 0 else r"\ensuremath{\infty}"
        if x != 0 and abs(x) < 0.5 * 10.0 ** -digits:
            mant, exp = f"{x:.2e}".split("e")
            return rf"\ensuremath{{{mant}\times10^{{{int(exp)}}}}}"
        text = f"{x:.{digits}f}"
        return text.replace("-", r"\ensuremath{-}", 1) if text.startswith("-") else text
    text = latex_text(v)
    if any(len(w) > 16 for w in str(v).split()):    # a path or identifier may break
        text = text.replace(r"\_", r"\_\allowbreak{}").replace("/", r"/\allowbreak{}")
    return text


def _plain_len(v, digits: int) -> int:
    """Printed width of a cell in characters (for the page-fit estimate)."""
    if _is_missing(v):
        return 0
    if isinstance(v, (float, np.floating)) and not math.isinf(float(v)):
        x = float(v)
        if x != 0 and abs(x) < 0.5 * 10.0 ** -digits:
            return 10
        return len(f"{x:.{digits}f}")
    return len(str(v))


def _numeric(col: pd.Series) -> bool:
    vals = [v for v in col if not _is_missing(v)]
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


def _col_info(df: pd.DataFrame, col: str, digits: int) -> dict:
    """Natural width (characters, entries and header), the narrowest a paragraph column
    may get (its longest word up to 17 characters -- longer ones may break -- or header
    piece between underscores, at least 8) and the kind."""
    cells = max([_plain_len(v, digits) for v in df[col]] + [0])
    num = _numeric(df[col])
    words = [len(w) for v in df[col] if isinstance(v, str) for w in v.split()]
    return {"num": num, "chars": max(cells, len(col)), "cells": cells,
            "min": max([8, min(max(words + [0]), 17)]
                       + [len(w) for w in re.split(r"[_ ]", col)]),
            "shrink": not num and cells > 12}


def _layout(groups, info, page) -> tuple[dict[str, str], bool]:
    """Column formats for one page kind and whether the table fits its width.

    Numbers and short text keep their natural width (``r``/``l``); long text columns
    share what is left as ``p{..pt}`` paragraphs (water-filling: a column narrower than
    its share keeps its natural width); a pair (``ours``/``paper``) is at least as wide
    as its header."""
    cw, pad = 0.6 * page["size_pt"], 2 * page["tabcolsep_pt"]
    specs, fixed, flex = {}, 0.0, []
    for g in groups:
        if len(g) == 1 and info[g[0]]["shrink"]:
            flex.append(g[0])
            continue
        inner = sum(max(info[c]["cells"], 5) * cw + pad for c in g)
        head = (len(g[0]) * cw + pad) if len(g) == 2 else info[g[0]]["chars"] * cw + pad
        fixed += max(inner, head)
        for c in g:
            specs[c] = "r" if info[c]["num"] else "l"
    avail = page["width_pt"] - fixed - pad * len(flex)
    left = sorted(flex, key=lambda c: (info[c]["chars"], c))
    while left:
        share = avail / len(left)
        c = left[0]
        if info[c]["chars"] * cw <= share:
            specs[c], avail = "l", avail - info[c]["chars"] * cw
            left.pop(0)
            continue
        for c in left:
            w = max(share, info[c]["min"] * cw)
            specs[c] = f"p{{{w:.1f}pt}}"
            avail -= w
        break
    return specs, avail >= -0.5


def _split(groups, info) -> list[list[list[str]]]:
    """Parts that fit a landscape page, each repeating the first column (the label)."""
    key, rest = groups[:1], groups[1:]
    parts, cur = [], []
    for g in rest:
        if cur and not _layout(key + cur + [g], info, LANDSCAPE)[1]:
            parts.append(key + cur)
            cur = []
        cur.append(g)
    parts.append(key + cur)
    return parts


def _head(name: str) -> str:
    """A column header; it may break after an underscore in a paragraph column."""
    return latex_text(name).replace(r"\_", r"\_\allowbreak{}")


def _render_part(df: pd.DataFrame, groups: list[list[str]], specs: dict[str, str], *,
                 caption: str, label: str, digits: int, long: bool) -> str:
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
    body = pd.DataFrame([[format_cell(v, digits) for v in row]
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


def to_latex(df: pd.DataFrame, *, caption: str, label: str, notes: list[str] | None = None,
             digits: int = 3) -> str:
    """The table as LaTeX (``table`` or ``longtable``, portrait, landscape or split),
    compiling inside :data:`PREAMBLE`."""
    df = df.reset_index(drop=True)
    df.columns = [str(c) for c in df.columns]
    groups = _groups(df)
    info = {c: _col_info(df, c, digits) for c in df.columns}
    specs, fits = _layout(groups, info, PORTRAIT)
    landscape = not fits
    parts = [groups]
    if landscape:
        specs, fits = _layout(groups, info, LANDSCAPE)
        if not fits and len(groups) > 2 and any(info[g[0]]["num"] for g in groups):
            parts = _split(groups, info)
    part_specs = [specs] if len(parts) == 1 else [_layout(p, info, LANDSCAPE)[0]
                                                  for p in parts]
    long = len(df) > LONG_ROWS
    cap = md_to_latex(caption)
    out = [f"% gaitval table {label}: pdflatex with booktabs, longtable, pdflscape, "
           "[T1]{fontenc} (gaitval.tables.latex.PREAMBLE)."]
    if landscape:
        out.append(r"\begin{landscape}")
    # A float resets the font to \normalsize, so the size goes inside it (after
    # \centering); a longtable is no float and takes it from the enclosing group.
    size = r"\scriptsize\setlength{\tabcolsep}{4pt}" if landscape else r"\footnotesize"
    out.append("{" + size if long else "{")
    note_block = "\n".join(
        [r"\par\smallskip\noindent\begin{minipage}{\linewidth}\raggedright"]
        + [md_to_latex(n) + r"\par" for n in notes or []] + [r"\end{minipage}"])
    for i, part in enumerate(parts):
        pcap = cap if len(parts) == 1 else f"{cap} (part {i + 1} of {len(parts)})"
        plabel = label if i == 0 else f"{label}-{i + 1}"
        tex = _render_part(df, part, part_specs[i], caption=pcap, label=plabel, digits=digits,
                           long=long).rstrip("\n")
        if not long:
            tex = tex.replace("\\centering\n", "\\centering\n" + size + "\n", 1)
        if notes and i == len(parts) - 1:         # the notes stay with their table
            tex = (tex + "\n" + note_block if long else
                   tex.replace("\\end{table}", note_block + "\n\\end{table}"))
        out.append(tex)
    out.append("}")
    if landscape:
        out.append(r"\end{landscape}")
    return "\n".join(out) + "\n"


def compile_tables(paths, workdir, *, pdflatex: str = "pdflatex",
                   timeout: float = 120) -> dict[str, tuple[bool, str, int]]:
    """Compile each ``.tex`` table on its own inside :data:`PREAMBLE` with pdflatex.

    Returns ``{path: (ok, first error line or '', overfull hbox count)}``.  ``workdir``
    receives the wrapper documents and logs.
    """
    import subprocess
    from pathlib import Path

    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    out = {}
    for i, p in enumerate(sorted(Path(x).resolve() for x in paths)):
        doc = workdir / f"t{i:03d}_{p.stem}.tex"
        doc.write_text(PREAMBLE + "\n\\begin{document}\n\\input{" + p.as_posix()
                       + "}\n\\end{document}\n", encoding="utf-8")
        try:
            res = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error",
                                  "-output-directory", str(workdir), doc.name],
                                 cwd=workdir, capture_output=True, timeout=timeout)
            log_path = doc.with_suffix(".log")
            log = log_path.read_text(errors="replace") if log_path.is_file() else ""
            ok = res.returncode == 0 and doc.with_suffix(".pdf").is_file()
        except subprocess.TimeoutExpired:
            ok, log = False, "! pdflatex timed out"
        err = next((ln for ln in log.splitlines() if ln.startswith("!")), "")
        out[str(p)] = (ok, err, log.count("Overfull \\hbox"))
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m gaitval.tables.latex FILE.tex ...``: compile each, one line per file."""
    import sys
    import tempfile

    paths = list(sys.argv[1:] if argv is None else argv)
    with tempfile.TemporaryDirectory() as tmp:
        res = compile_tables(paths, tmp)
    for p, (ok, err, overfull) in res.items():
        print(f"{'ok  ' if ok else 'FAIL'} {p}  overfull hboxes: {overfull}"
              + (f"  {err}" if err else ""))
    print(f"{sum(ok for ok, _, _ in res.values())}/{len(res)} compiled")
    return 0 if all(ok for ok, _, _ in res.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
