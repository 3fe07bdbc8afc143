"""One number format for every rendered table (Markdown, HTML, LaTeX); the CSV keeps full
precision.

A cell's format depends only on its column (the *quantity*) and, for a few paper tables,
on the table — never on the value — so a column reads the same from its first row to its
last and the same in ``.md``, ``index.html`` and ``.tex``:

* **p-values** (``p``, ``*_p``, ``p_*``): ``< 0.001`` below 0.001, else three decimals.
* **counts** (``n``, ``n_*``, ``*_frames``, ``*_steps``, ``trials`` …): whole numbers,
  also when the CSV stores them as floats because a cell is empty.
* **proportions** (``*_rate``, 0–1): shown in per cent with one decimal, as the papers print
  them (``89.3``); the header becomes ``*_pct``.
* **lengths**: the paper's unit where the table reproduces a paper (TUG Tables 4–5: m, three
  decimals; rollator Table I: cm and cm/s, two decimals; ultrasonic Table 1: mm, two
  decimals); elsewhere a length with an error's name (``*residual*``, ``*rmse*``, ``*err*``,
  ``*bias*``, ``*loa*``, ``*sd*``, ``*std*``, ``*mad*``) in mm with two decimals (header
  ``*_mm``), any other length in m with three.
* **times** ``*_s`` three decimals (ms), **per cent** ``*_pct`` one, **Hz** two, **degrees**
  one, **ppm** one; any other float three decimals (the table may say otherwise, e.g.
  ``mtst_table3``: one).

Fixed decimals per quantity mean no scientific notation and no float noise.  A non-zero
value is never printed as zero: one that would round to zero at its quantity's precision
is printed with two significant figures instead (``0.00025`` for 0.000246 in a column of
three decimals, an ANOVA's small SS ``0.0031``); float noise below :data:`NOISE`
(``-1.68e-18`` for an exact zero) is zero, never ``-0.000``.  The CSV keeps the exact
value.  A quantity's decimals are its significant figures at the magnitude the papers
report it (mm resolution for leg positions, 0.1 % for rates); a proportion is in per cent
everywhere in a table (``*_rate`` and ``*_rate_*`` columns alike).

API
---
:func:`column_format` (the format of a column), :func:`format_value` (one cell),
:func:`to_display` (a table converted to its display units, headers renamed, still
numeric — what a renderer such as :mod:`gaitval.tables.latex` receives) and
:func:`format_frame` (every cell as its display string).  A renderer calls
``format_value(value, column, table=stem)`` on the frame :func:`to_display` returned.
:func:`number` formats a number inside a sentence (notes, verdicts) without e-notation.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import pandas as pd


@dataclass(frozen=True)
class Format:
    """How a column is printed.

    ``kind``: ``"p"`` (p-value), ``"int"`` (count), ``"fixed"`` (``decimals`` decimals),
    ``"sig"`` (``decimals`` significant figures) or ``"text"`` (as written); ``scale``: factor from the CSV's unit to the display unit;
    ``rename``: ``(old suffix, new suffix)`` of the header, or None.
    """
    kind: str
    decimals: int = 3
    scale: float = 1.0
    rename: tuple[str, str] | None = None


P_VALUE = Format("p", 3)
COUNT = Format("int", 0)
_ERRORISH = re.compile(r"(residual|rmse|err|bias|loa|(^|_)sd(_|$)|std|mad|offset_error)")
_COUNT = re.compile(r"^(n|h|n_.*|.*_n|.*_count|.*frames(_.*)?|.*_steps|time_steps|trials|"
                    r".*_trials(_.*)?|cells|.*_cells|reinitialisations|.*_no|strides|"
                    r".*_strides|markers|events|sensor_samples|beams|anchors|"
                    r"timestamp_issues|annotations|lost_.*|false_.*|ft_.*|sf_.*|df.*)$")
_P = re.compile(r"^(p|.*_p|p_.*)$")

#: Tables that reproduce a paper table print lengths in the paper's unit (see module notes).
PAPER_TABLES = ("tug_table", "tug_failures", "mtst_table", "rollator_table", "rollator_improvement",
                "ultrasonic_table", "ultrasonic_agreement")
#: Per-table formats of columns (the paper's precision where it differs from the rules).
TABLE_COLUMNS: dict[str, dict[str, Format]] = {
    "rollator_table1": {c: Format("fixed", 2, 100.0) for c in (
        "rmse_kf", "rmse_pf", "mad_kf", "mad_pf")},            # Chalvatzaki et al. 2017: cm, cm/s
    "rollator_table2": {"tracking_time_s": Format("fixed", 2)},
    # Qi et al. 2014 Table C1: sums and mean squares span four orders of magnitude
    # (0.0017 to 1.3), so significant figures, not decimals
    "ultrasonic_tableC1": {"SS": Format("sig", 2), "MS": Format("sig", 2)},
}
#: Per-table formats of columns by prefix: an external method's columns are
#: named after it (``rmse_<method>``), so they are matched by their statistic.
TABLE_PREFIXES: dict[str, dict[tuple[str, ...], Format]] = {
    "rollator_table1": {("rmse_", "mad_"): Format("fixed", 2, 100.0)},
}
#: Text columns whose values change with a table's display unit.
TABLE_TEXT = {"rollator_table1": {"unit": {"m": "cm", "m/s": "cm/s"}}}
#: Decimals of floats no rule covers, per table (the papers' precision); default 3.
TABLE_DECIMALS = {"mtst_table3": 1, "mtst_table4": 1, "rollator_improvement": 1,
                  "ultrasonic_tableC1": 2}


def _table_key(table: str | None, mapping: dict) -> str | None:
    if not table:
        return None
    return next((k for k in mapping if table == k or table.startswith(k + "_")), None)


def column_format(column: str, table: str | None = None) -> Format:
    """The :class:`Format` of ``column`` (a ``*_published`` column as its quantity's)."""
    name = str(column)
    base = name[:-len("_published")] if name.endswith("_published") else name
    for suffix in ("_published_cells", "_paper_text"):
        if base.endswith(suffix):
            base = base[:-len(suffix)]
    key = _table_key(table, TABLE_COLUMNS)
    if key and base in TABLE_COLUMNS[key]:
        return TABLE_COLUMNS[key][base]
    pkey = _table_key(table, TABLE_PREFIXES)
    for prefixes, fmt in (TABLE_PREFIXES[pkey].items() if pkey else ()):
        if base.startswith(prefixes):
            return fmt
    low = base.lower()
    paper = bool(table) and table.startswith(PAPER_TABLES)
    if _P.match(low):
        return P_VALUE
    if _COUNT.match(low) and "per_" not in low:
        return COUNT
    if low.endswith("_rate"):
        return Format("fixed", 1, 100.0, ("_rate", "_pct"))
    if "_rate_" in low and not low.endswith(("_hz", "_pct")):
        # a rate of a variant (success_rate_persistent_swap): per cent too, so that one
        # table never shows a proportion both as a fraction and in per cent
        return Format("fixed", 1, 100.0, ("_rate_", "_pct_"))
    if low.endswith("_pct") or low.endswith("_percent"):
        return Format("fixed", 1)
    if low.endswith("_mm"):
        return Format("fixed", 2)
    if low.endswith("_m") or low.endswith("_mps"):
        if not paper and _ERRORISH.search(low):
            unit = "_m" if low.endswith("_m") else "_mps"
            return Format("fixed", 2, 1000.0, (unit, "_mm" if unit == "_m" else "_mmps"))
        return Format("fixed", 3)
    if low.endswith("_s"):
        return Format("fixed", 3)
    if low.endswith("_hz"):
        return Format("fixed", 2)
    if low.endswith(("_deg", "_ppm")):
        return Format("fixed", 1)
    dec = TABLE_DECIMALS.get(_table_key(table, TABLE_DECIMALS) or "", 3)
    return Format("fixed", dec)


def display_name(column: str, table: str | None = None) -> str:
    """The header of ``column`` in its display unit (``occlusion_rate`` →
    ``occlusion_pct``, ``pole_residual_m`` → ``pole_residual_mm``)."""
    f = column_format(column, table)
    name = str(column)
    if f.rename is None:
        return name
    old, new = f.rename
    pub = name.endswith("_published")
    base = name[:-len("_published")] if pub else name
    if base.endswith(old):
        base = base[:-len(old)] + new
    elif old.endswith("_") and old in base:             # an infix (``_rate_``)
        base = base.replace(old, new, 1)
    return base + ("_published" if pub else "")


def _missing(v) -> bool:
    if v is None or v is pd.NA or v is pd.NaT:
        return True
    try:
        return isinstance(v, (float, np.floating)) and math.isnan(v)
    except TypeError:
        return False


def fixed(x: float, decimals: int) -> str:
    """``x`` with ``decimals`` decimals; a value that rounds to zero is ``0.000`` (no
    ``-0.000``); infinities as ``∞``/``-∞``."""
    if math.isinf(x):
        return "∞" if x > 0 else "-∞"
    text = f"{x:.{decimals}f}"
    if text.startswith("-") and float(text) == 0:
        text = text[1:]
    return text


def p_value(p) -> str:
    """``< 0.001`` or three decimals; empty when missing."""
    if _missing(p):
        return ""
    p = float(p)
    return "< 0.001" if p < 0.001 else fixed(p, 3)


def format_value(value, column: str, table: str | None = None) -> str:
    """One cell of ``column`` (already in its display unit, see :func:`to_display`) as text.

    Missing → ``""``; booleans → ``yes``/``no``; strings unchanged; numbers by
    :func:`column_format`.
    """
    if _missing(value):
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, str):
        return value
    if not isinstance(value, (int, float, np.integer, np.floating)):
        return str(value)
    f = column_format(column, table)
    x = float(value)
    if f.kind == "p":
        return p_value(x)
    if f.kind == "sig":
        return number(x, f.decimals)
    integral = math.isfinite(x) and abs(x - round(x)) < 1e-9
    if f.kind == "int":
        return str(int(round(x))) if integral else not_zero(x, fixed(x, 1))
    if isinstance(value, (int, np.integer)) and f.scale == 1.0:
        return str(int(value))                    # an integer column (rates in Hz, sizes)
    return not_zero(x, fixed(x, f.decimals))


#: Below this magnitude a value is float noise (``-1.68e-18`` for an exact zero) and
#: printed as zero; any larger value is never printed as zero.
NOISE = 1e-12


def not_zero(x: float, text: str, sig: int = 2) -> str:
    """``text`` (``x`` at its column's decimals), unless it reads zero for a non-zero
    ``x``: then ``x`` to ``sig`` significant figures (``0.000246``, an ANOVA's small SS
    ``0.0031``), never e-notation.  Float noise (:data:`NOISE`) stays zero."""
    if math.isfinite(x) and abs(x) >= NOISE and _reads_zero(text):
        return number(x, sig)
    return text


def _reads_zero(text: str) -> bool:
    try:
        return float(text) == 0
    except ValueError:
        return False


def to_display(df: pd.DataFrame, table: str | None = None) -> pd.DataFrame:
    """``df`` in its display units: scaled numeric columns, renamed headers, text columns
    that name a unit changed with it.  Numbers stay numbers (for a renderer's alignment);
    format them with :func:`format_value` under their new names."""
    out = df.copy()
    out.columns = [str(c) for c in out.columns]
    for c in list(out.columns):
        f = column_format(c, table)
        if f.scale != 1.0 and pd.api.types.is_numeric_dtype(out[c]) \
                and not pd.api.types.is_bool_dtype(out[c]):
            out[c] = out[c].astype(float) * f.scale
    key = _table_key(table, TABLE_TEXT)
    for c, mapping in (TABLE_TEXT.get(key, {}) if key else {}).items():
        if c in out:
            out[c] = out[c].map(lambda v: mapping.get(v, v) if isinstance(v, str) else v)
    out.columns = [display_name(c, table) for c in out.columns]
    return out


def format_frame(df: pd.DataFrame, table: str | None = None) -> pd.DataFrame:
    """Every cell of ``df`` as its display string, headers in display units."""
    d = to_display(df, table)
    rows = [[format_value(v, c, table) for c, v in zip(d.columns, row)]
            for row in d.itertuples(index=False, name=None)]
    return pd.DataFrame(rows, columns=d.columns, dtype=object)


def number(x, sig: int = 3) -> str:
    """A number inside a sentence: ``sig`` significant figures, never e-notation (``0.000123``,
    ``46.1``, ``1234``); missing → ``n/a``."""
    if _missing(x):
        return "n/a"
    x = float(x)
    if math.isinf(x):
        return "∞" if x > 0 else "-∞"
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    dec = max(0, sig - 1 - mag)
    return fixed(x, min(dec, 12))


#: Scientific notation or float noise in rendered text (what tests scan for).
E_NOTATION = re.compile(r"(?<![A-Za-z_])[-+]?\d+(\.\d+)?[eE][-+]?\d+(?![A-Za-z_])")
