"""Text of a LaTeX table (:mod:`gaitval.tables.latex`): every header, cell, caption and note
escaped (:func:`latex_text`: the LaTeX specials as text commands, the Unicode the tables
use as LaTeX commands, maths wrapped in ``\\ensuremath``), inline Markdown as LaTeX
(:func:`md_to_latex`), and a cell in the report's one number format (:func:`format_cell`).
"""
from __future__ import annotations

import math
import re
import unicodedata

import numpy as np
import pandas as pd


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


def is_missing(v) -> bool:
    if v is None or v is pd.NA or v is pd.NaT:
        return True
    return isinstance(v, (float, np.floating)) and math.isnan(v)


def cell_text(v, column: str, table: str | None) -> str:
    """A cell's plain text: numbers in the report's number format, the rest as given."""
    from gaitval.tables.numbers import format_value
    if isinstance(v, (float, np.floating)) and math.isinf(float(v)):
        return "-inf" if v < 0 else "inf"
    return format_value(v, column, table)


def format_cell(v, column: str, table: str | None = None) -> str:
    """One cell of ``column`` (display name) of ``table`` as LaTeX (module docstring)."""
    if is_missing(v):
        return ""
    if isinstance(v, (float, np.floating)) and math.isinf(float(v)):
        return r"\ensuremath{-\infty}" if v < 0 else r"\ensuremath{\infty}"
    text = latex_text(cell_text(v, column, table))
    if isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(
            v, (bool, np.bool_)):
        return text.replace("-", r"\ensuremath{-}", 1) if text.startswith("-") else text
    if any(len(w) > 16 for w in str(v).split()):    # a path or identifier may break
        text = text.replace(r"\_", r"\_\allowbreak{}").replace("/", r"/\allowbreak{}")
    return text
