"""``reports/index.md`` and ``reports/index.html``: every table and figure with provenance.

The index lists what exists under ``reports/tables`` and ``reports/figures`` (grouped by
protocol), each item with the command, configuration hash, gaitval version and git commit
that made it (from :mod:`gaitval.report.provenance`), and, for honesty, the paper tables
that are not produced yet.
"""
from __future__ import annotations

import html
from pathlib import Path

import pandas as pd

from gaitval import __version__
from gaitval.io.atomic import write_text
from gaitval.report.provenance import load_all

#: The paper tables gaitval renders (see ../shared/seeds/README.md), by protocol.
EXPECTED_TABLES = {
    "tug": ["tug_table2", "tug_table3", "tug_table4", "tug_table5"],
    "mtst": ["mtst_table1", "mtst_table3", "mtst_table4"],
    "rollator": ["rollator_table1", "rollator_table2"],
    "ultrasonic": [f"ultrasonic_table{i}" for i in range(1, 9)] + ["ultrasonic_tableC1"],
}
SECTION_TITLES = {
    "study": "Study, ingest and registration",
    "tug": "TUG leg tracking (Yorozu et al., Sensors 2015, seed 000)",
    "mtst": "Multi-target stepping task (Yorozu et al., Sensors 2015, seed 001)",
    "rollator": "Robotic rollator, KF vs PF (Chalvatzaki et al., 2017, seed 002)",
    "ultrasonic": "Ultrasonic foot tracking (Qi et al., Sensors 2014, seed 003)",
    "peer": "Worked example: agreement statistics on a peer's published data",
}


def _section(name: str) -> str:
    head = name.split("_")[0]
    if head in SECTION_TITLES and head != "study":
        return head
    return "study"


def _caption(md_path: Path) -> str:
    first = md_path.read_text(encoding="utf-8").splitlines()[0] if md_path.is_file() else ""
    return first.strip("* ")


def _prov_line(rec: dict | None) -> str:
    if rec is None:
        return "provenance: no record (made outside the pipeline)"
    return (f"command: `{rec['command']}` · config {rec['config_hash'] or '-'} · "
            f"gaitval {rec['gaitval_version']} · commit {rec['git_commit']}")


def build_index(reports_dir: str | Path, *, study_names: list[str] | None = None
                ) -> tuple[Path, Path]:
    """Write ``index.md`` and ``index.html`` in ``reports_dir``; return both paths."""
    rd = Path(reports_dir)
    prov = load_all(rd)
    tables = sorted((rd / "tables").glob("*.csv"))
    figures = sorted((rd / "figures").glob("*.png"))
    by_sec: dict[str, list[tuple[str, Path]]] = {}
    for p in tables:
        by_sec.setdefault(_section(p.stem), []).append(("table", p))
    for p in figures:
        by_sec.setdefault(_section(p.stem), []).append(("figure", p))
    present = {p.stem for p in tables}
    missing = {sec: [t for t in names if t not in present]
               for sec, names in EXPECTED_TABLES.items()}

    md = ["# gaitval report", "",
          f"gaitval {__version__}. Studies: {', '.join(study_names or []) or '-'}.",
          "Every item below names the command, configuration hash, package version and git "
          "commit that produced it. Published values stand beside reproduced ones in the "
          "paper tables.", ""]
    h = ["<!DOCTYPE html>", "<html><head><meta charset='utf-8'><title>gaitval report</title>",
         "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
         "table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #ccc;"
         "padding:2px 6px}.prov{color:#666;font-size:11px}</style></head><body>",
         "<h1>gaitval report</h1>",
         f"<p>gaitval {__version__}. Studies: {html.escape(', '.join(study_names or []))}."
         "</p>"]
    for sec in list(SECTION_TITLES):
        items = by_sec.get(sec, [])
        miss = missing.get(sec, [])
        if not items and not miss:
            continue
        md += [f"## {SECTION_TITLES[sec]}", ""]
        h += [f"<h2>{html.escape(SECTION_TITLES[sec])}</h2>"]
        for kind, p in items:
            rel = str(p.relative_to(rd))
            rec = prov.get(rel)
            if kind == "table":
                mdp = p.with_suffix(".md")
                cap = _caption(mdp)
                md += [f"### {p.stem}", "", mdp.read_text(encoding="utf-8").rstrip()
                       if mdp.is_file() else f"[{rel}]({rel})", "",
                       f"Files: [{p.name}]({rel}) · [{mdp.name}]({rel[:-4]}.md) · "
                       f"[{p.stem}.tex]({rel[:-4]}.tex)", "", f"_{_prov_line(rec)}_", ""]
                df = pd.read_csv(p, keep_default_na=False)
                h += [f"<h3>{html.escape(p.stem)}</h3>", f"<p>{html.escape(cap)}</p>",
                      df.to_html(index=False, border=0, na_rep=""),
                      f"<p class='prov'>{html.escape(_prov_line(rec))}</p>"]
            else:
                md += [f"### {p.stem}", "", f"![{p.stem}]({rel})", "", f"_{_prov_line(rec)}_",
                       ""]
                h += [f"<h3>{html.escape(p.stem)}</h3>",
                      f"<img src='{html.escape(rel)}' style='max-width:100%'>",
                      f"<p class='prov'>{html.escape(_prov_line(rec))}</p>"]
        if miss:
            line = "Not produced yet: " + ", ".join(miss)
            md += [f"_{line}_", ""]
            h += [f"<p><em>{html.escape(line)}</em></p>"]
    h += ["</body></html>", ""]
    return (write_text(rd / "index.md", "\n".join(md) + "\n"),
            write_text(rd / "index.html", "\n".join(h)))
