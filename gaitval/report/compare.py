"""Two report folders' tables compared within a stated tolerance (docs/numerics.md).

``gaitval compare-tables A B --rtol 1e-9`` reads
every ``*.csv`` under ``A`` and ``B`` (a report folder: ``tables/*.csv`` and
``verdicts.csv``; or a ``tables`` folder) and compares them cell by cell:

* **numbers** (a column whose cells all read as numbers) agree when
  ``|a - b| <= atol + rtol * max(|a|, |b|)``, or when they differ by one unit in the last
  digit the table prints (tables print 6 significant digits, so two values closer than
  ``rtol`` print that way when they straddle a rounding boundary; ``--strict-digits``
  turns this off);
* **counts** (a column whose cells are all integers) and **text** (verdict outcomes,
  labels, numbers quoted in sentences) must be equal;
* an empty cell (NaN) must be empty in both.

Rows and columns are compared in order; a missing file, column or row is a mismatch.  For
each table it prints the worst relative difference of a number (where, and both values),
how many numbers differ at all, and the exact mismatches; the exit status is 0 when every
table agrees, 1 otherwise.
"""
from __future__ import annotations

import fnmatch
import math
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from gaitval.errors import GaitvalError

_INT = re.compile(r"^[+-]?\d+$")


@dataclass
class TableDiff:
    """How one table of ``A`` compares to the same table of ``B``.

    ``worst``: the largest relative difference of a numeric cell (0 when none differ),
    ``where``: that cell (``row i, column c: a vs b``); ``n_numbers``: numeric cells
    compared, ``n_differ``: those not printed identically, ``n_last_digit``: those that
    differ by one unit in the last printed digit only; ``exact``: mismatches of counts,
    text, empty cells or shape (each a sentence); ``ok``: within the tolerance."""

    name: str
    worst: float = 0.0
    where: str = ""
    n_numbers: int = 0
    n_differ: int = 0
    n_last_digit: int = 0
    exact: list[str] = field(default_factory=list)
    ok: bool = True


def _number(s: str) -> float | None:
    try:
        return float(s)
    except ValueError:
        return None


def _last_digit_apart(x: float, y: float, digits: int) -> bool:
    """Whether ``x`` and ``y`` differ by at most one unit in the ``digits``-th significant
    digit (``1.23457`` vs ``1.23456`` at 6 digits)."""
    scale = max(abs(x), abs(y))
    unit = 10.0 ** (math.floor(math.log10(scale)) - digits + 1)
    return abs(x - y) <= unit * (1 + 1e-9)


def _kind(a, b) -> str:
    """``count``, ``number`` or ``text``: what every non-empty cell of both columns is."""
    cells = [s for s in list(a) + list(b) if s != ""]
    if cells and all(_INT.match(s) for s in cells):
        return "count"
    if cells and all(_number(s) is not None for s in cells):
        return "number"
    return "text"


def compare_frames(name: str, A, B, *, rtol: float,
                   atol: float = 0.0, last_digit: bool = True, digits: int = 6) -> TableDiff:
    """Compare two DataFrames read as strings (``dtype=str, keep_default_na=False``);
    ``digits``: the significant digits the tables print (:func:`gaitval.tables.render.
    write_table`'s ``%.6g``)."""
    d = TableDiff(name)
    if list(A.columns) != list(B.columns):
        d.exact.append(f"columns differ: {list(A.columns)} vs {list(B.columns)}")
    if len(A) != len(B):
        d.exact.append(f"{len(A)} rows vs {len(B)}")
    n = min(len(A), len(B))
    for col in [c for c in A.columns if c in B.columns]:
        a, b = A[col].iloc[:n], B[col].iloc[:n]
        kind = _kind(a, b)
        for i, (x, y) in enumerate(zip(a, b)):
            if kind != "number" or x == "" or y == "":
                if x != y:
                    d.exact.append(f"row {i + 1}, {col} ({kind}): {x!r} vs {y!r}")
                continue
            d.n_numbers += 1
            if x == y:
                continue
            d.n_differ += 1
            fx, fy = float(x), float(y)
            diff = abs(fx - fy)
            if not math.isfinite(diff):            # inf vs a number, or nan printed
                d.exact.append(f"row {i + 1}, {col}: {x} vs {y}")
                continue
            scale = max(abs(fx), abs(fy))
            rel = diff / scale if scale > 0 else 0.0
            within = diff <= atol + rtol * scale
            if not within and last_digit and _last_digit_apart(fx, fy, digits):
                d.n_last_digit += 1
                within = True
            if rel > d.worst:
                d.worst, d.where = rel, f"row {i + 1}, {col}: {x} vs {y}"
            if not within:
                d.ok = False
    d.ok = d.ok and not d.exact
    return d


def _csvs(folder: Path, ignore: list[str]) -> dict[str, Path]:
    out = {}
    for p in sorted(folder.rglob("*.csv")):
        rel = p.relative_to(folder).as_posix()
        if not any(fnmatch.fnmatch(rel, g) for g in ignore):
            out[rel] = p
    return out


def compare_folders(a: Path, b: Path, *, rtol: float, atol: float = 0.0,
                    last_digit: bool = True, ignore: list[str] | None = None
                    ) -> list[TableDiff]:
    """:func:`compare_frames` for every ``*.csv`` under ``a`` and ``b`` (relative paths
    matched; ``ignore``: glob patterns of relative paths to leave out)."""
    import pandas as pd                         # here: building the CLI parser need not

    for f in (a, b):
        if not Path(f).is_dir():
            raise GaitvalError("not a folder of report tables", path=f)
    fa, fb = _csvs(Path(a), ignore or []), _csvs(Path(b), ignore or [])
    if not fa and not fb:
        raise GaitvalError(f"no *.csv under {a} or {b}", path=a)
    out = []
    for rel in sorted(set(fa) | set(fb)):
        if rel not in fa or rel not in fb:
            out.append(TableDiff(rel, exact=[f"only in {a if rel in fa else b}"], ok=False))
            continue
        read = lambda p: pd.read_csv(p, dtype=str, keep_default_na=False)  # noqa: E731
        out.append(compare_frames(rel, read(fa[rel]), read(fb[rel]), rtol=rtol, atol=atol,
                                  last_digit=last_digit))
    return out


def format_report(diffs: list[TableDiff], rtol: float, max_lines: int = 3) -> str:
    """One line per table (worst relative difference, cells that differ, exact
    mismatches), the first ``max_lines`` exact mismatches under it, and a verdict."""
    w = max([len(d.name) for d in diffs] + [5])
    lines = [f"{'table':<{w}}  {'numbers':>7}  {'differ':>6}  {'last digit':>10}  "
             f"{'worst rel':>9}  exact  where"]
    for d in diffs:
        lines.append(f"{d.name:<{w}}  {d.n_numbers:>7}  {d.n_differ:>6}  "
                     f"{d.n_last_digit:>10}  {d.worst:>9.2e}  {len(d.exact):>5}  {d.where}")
        lines += [f"    {e}" for e in d.exact[:max_lines]]
        if len(d.exact) > max_lines:
            lines.append(f"    ... {len(d.exact) - max_lines} more")
    bad = [d.name for d in diffs if not d.ok]
    lines.append(f"{len(diffs) - len(bad)} of {len(diffs)} tables agree within rtol "
                 f"{rtol:g} (counts and text exactly)" + (f"; differ: {', '.join(bad)}"
                                                          if bad else ""))
    return "\n".join(lines)


def run(args) -> int:
    """The verb: prints :func:`format_report`; 0 when every table agrees, else 1."""
    diffs = compare_folders(args.a, args.b, rtol=args.rtol, atol=args.atol,
                            last_digit=not args.strict_digits, ignore=args.ignore)
    print(format_report(diffs, args.rtol))
    return 0 if all(d.ok for d in diffs) else 1
