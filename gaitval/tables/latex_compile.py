"""``python -m gaitval.tables.latex_compile FILE.tex ...``: each table compiled on its own
with pdflatex inside :data:`gaitval.tables.latex.PREAMBLE`, after a paragraph of an
article page, and failed on a pdflatex error, "Float too large", an overfull or underfull
box, a runaway argument, or a listing of fewer than :data:`MIN_LINES_PER_PAGE` lines a
page (docs/report.md).
"""
from __future__ import annotations

import re

from gaitval.tables.latex import PREAMBLE


#: Text set before the table in the checker's document (a table is checked as it would
#: sit in a manuscript, after a paragraph).
PAGE_TEXT = r"Text before the table.\par"


#: What the page-fit check counts in pdflatex's log (:func:`compile_tables`).
LOG_PROBLEMS = {"float too large": re.compile(r"Float too large for page by ([0-9.]+)pt"),
                "overfull hbox": re.compile(r"^Overfull \\hbox", re.M),
                "overfull vbox": re.compile(r"^Overfull \\vbox", re.M),
                "underfull hbox": re.compile(r"^Underfull \\hbox", re.M),
                "underfull vbox": re.compile(r"^Underfull \\vbox", re.M),
                "runaway": re.compile(r"^Runaway (argument|definition|text|preamble)",
                                      re.M)}
#: A table of more than two pages must carry at least this many lines (rows, notes) a
#: page: fewer is a listing of paragraphs, not a table (the check fails it).
MIN_LINES_PER_PAGE = 6


class Compiled(tuple):
    """``(ok, problem, n_box_problems)`` of one table, plus ``.counts`` and ``.pages``."""

    counts: dict
    pages: int

    def __new__(cls, ok: bool, problem: str, n_boxes: int, counts: dict, pages: int):
        self = super().__new__(cls, (ok, problem, n_boxes))
        self.counts, self.pages = counts, pages
        return self


def check_log(log: str, *, lines: int | None = None) -> tuple[str, dict, int]:
    """The page-fit problems a pdflatex log shows: ``(first problem or '', counts,
    pages)``.  Every count in :data:`LOG_PROBLEMS` must be 0, and a table of ``lines``
    lines (rows of every part, and its notes at 100 characters a line) on more than two
    pages must have :data:`MIN_LINES_PER_PAGE` lines a page."""
    counts = {k: len(rx.findall(log)) for k, rx in LOG_PROBLEMS.items()}
    first = re.search(r"GAITVAL-FIRST-PAGE (\d+)", log)
    nxt = re.search(r"GAITVAL-NEXT-PAGE (\d+)", log)
    pages = int(nxt.group(1)) - int(first.group(1)) if first and nxt else 0
    err = next((ln for ln in log.splitlines() if ln.startswith("!")), "")
    if err:
        return err, counts, pages
    too_large = LOG_PROBLEMS["float too large"].search(log)
    if too_large:
        return f"Float too large for page by {too_large.group(1)}pt", counts, pages
    bad = [f"{n} {k}" for k, n in counts.items() if n]
    if bad:
        return ", ".join(bad), counts, pages
    if lines is not None and pages > 2 and lines < MIN_LINES_PER_PAGE * pages:
        return (f"{pages} pages for {lines} lines of rows and notes (fewer than "
                f"{MIN_LINES_PER_PAGE} a page)", counts, pages)
    return "", counts, pages


def compile_tables(paths, workdir, *, pdflatex: str = "pdflatex", timeout: float = 120
                   ) -> dict[str, Compiled]:
    """Compile each ``.tex`` table on its own inside
    :data:`~gaitval.tables.latex.PREAMBLE`, as a page of an article, with pdflatex, and
    check that it fits the page.

    Returns ``{path: (ok, problem, n_box_problems)}`` (a :class:`Compiled` that also has
    ``.counts`` and ``.pages``).  ``ok`` is False when pdflatex fails or its log shows a
    float too large for the page, an overfull or underfull box, a runaway argument, or
    (for a gaitval table, whose first line gives its lines) more than two pages with
    fewer than :data:`MIN_LINES_PER_PAGE` lines a page.  ``workdir`` receives the wrapper documents and logs.
    """
    import subprocess
    from pathlib import Path

    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    out = {}
    for i, p in enumerate(sorted(Path(x).resolve() for x in paths)):
        doc = workdir / f"t{i:03d}_{p.stem}.tex"
        doc.write_text(PREAMBLE + "\n\\begin{document}\n" + PAGE_TEXT
                       + "\n\\clearpage\\typeout{GAITVAL-FIRST-PAGE \\thepage}\n\\input{"
                       + p.as_posix() + "}"
                       + "\n\\clearpage\\typeout{GAITVAL-NEXT-PAGE \\thepage}\n"
                       "\\end{document}\n", encoding="utf-8")
        try:
            res = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error",
                                  "-output-directory", str(workdir), doc.name],
                                 cwd=workdir, capture_output=True, timeout=timeout)
            log_path = doc.with_suffix(".log")
            log = log_path.read_text(errors="replace") if log_path.is_file() else ""
            ok = res.returncode == 0 and doc.with_suffix(".pdf").is_file()
        except subprocess.TimeoutExpired:
            ok, log = False, "! pdflatex timed out"
        m = re.match(r"% gaitval table \S+: (\d+) lines", p.read_text(errors="replace"))
        problem, counts, pages = check_log(log, lines=int(m.group(1)) if m else None)
        if not ok and not problem:
            problem = "pdflatex failed"
        n_boxes = sum(n for k, n in counts.items() if k != "float too large")
        out[str(p)] = Compiled(ok and not problem, problem, n_boxes, counts, pages)
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m gaitval.tables.latex_compile FILE.tex ...``: compile each in a page, one line
    per file (pages and every problem)."""
    import sys
    import tempfile

    paths = list(sys.argv[1:] if argv is None else argv)
    with tempfile.TemporaryDirectory() as tmp:
        res = compile_tables(paths, tmp)
    for p, r in res.items():
        ok, problem, _ = r
        print(f"{'ok  ' if ok else 'FAIL'} {p}  {r.pages} page(s)"
              + (f"  {problem}" if problem else ""))
    print(f"{sum(r[0] for r in res.values())}/{len(res)} fit their pages")
    return 0 if all(r[0] for r in res.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
