"""``reports/index.md`` and ``reports/index.html``: every table and figure with provenance.

Both files are rendered from one content model (:func:`collect`): the verdict table on top
(:mod:`gaitval.report.verdicts`), then every table under ``reports/tables`` and figure under
``reports/figures`` grouped by protocol, each table with its caption, its notes (parsed from
the table's ``.md``), its file links and the provenance record of the step that made it
(:mod:`gaitval.report.provenance`), and, for honesty, the paper tables not produced yet
(in the sections of the protocols the run produced anything for; the verdict table says
which papers were not run).
The Markdown is written directly; the HTML through the jinja2 template
``templates/index.html.j2``, with each ``*_published`` column placed right after the
reproduced column it belongs to and numbers printed at the precision the paper prints.
"""
from __future__ import annotations

import html
import re
from pathlib import Path

import jinja2
import numpy as np
import pandas as pd

from gaitval import __version__
from gaitval.io.atomic import write_text
from gaitval.report.provenance import load_all, relative_path
from gaitval.report.verdicts import VERDICT_COLUMNS, build_verdicts, summary_lines

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
    "legbench": "Annotated recordings without mocap: CLEAR-MOT (Leigh et al., ICRA 2015)",
    "peer": "Worked example: agreement statistics on a peer's published data",
}


def _section(name: str) -> str:
    head = name.split("_")[0]
    if head in SECTION_TITLES and head != "study":
        return head
    return "study"


def _caption_notes(md_path: Path) -> tuple[str, list[str]]:
    """Caption (first line) and notes (``- `` lines) of a table's Markdown file."""
    if not md_path.is_file():
        return "", []
    lines = md_path.read_text(encoding="utf-8").splitlines()
    notes = [ln[2:] for ln in lines[1:] if ln.startswith("- ")]
    return (lines[0].strip("* ") if lines else ""), notes


def _prov_line(rec: dict | None) -> str:
    """One short line per item: the step that made it and its record (the step's full
    command is in the record; the report's provenance is once, at the end)."""
    if rec is None:
        return "provenance: no record (made outside the pipeline)"
    return (f"made by step `{rec['step']}` · config {rec['config_hash'] or '-'} · "
            f"gaitval {rec['gaitval_version']} · commit {rec['git_commit'][:12]} · "
            f"[record]({rec['record']})")


def _dependency_versions(env_file: Path) -> list[str]:
    """Exact versions of gaitval's declared dependencies, from ``environment.txt``."""
    try:
        from importlib.metadata import requires
        names = {re.split(r"[ ;<>=!~\[(]", r, maxsplit=1)[0].lower().replace("_", "-")
                 for r in requires("gaitval") or [] if "extra ==" not in r}
    except Exception:                                 # gaitval not installed as a dist
        names = set()
    if not env_file.is_file():
        return []
    return [ln for ln in env_file.read_text().splitlines()
            if ln.split("==")[0].lower().replace("_", "-") in names]


def _provenance(rd: Path, rec: dict | None) -> list[str]:
    """The report's provenance as Markdown lines (once per report)."""
    if rec is None:
        return ["No report provenance: this index was not built by the workflow "
                "(no `provenance/rebuild.json` or `provenance/inputs.txt`)."]
    out = []
    if rec.get("command"):
        out.append(f"Rebuild this report (from the gaitval checkout): `{rec['command']}`")
    out.append(f"git commit `{rec['git_commit']}` · gaitval {rec['gaitval_version']} · "
               f"Python {rec['python']} · {rec['platform']}")
    if rec.get("config"):
        out.append(f"Resolved configuration: [{rec['config']}]({rec['config']})"
                   + (f" (hash {rec['config_hash']})" if rec.get("config_hash") else ""))
    if rec.get("inputs"):
        out.append(f"Input files: [{rec['inputs']}]({rec['inputs']}), SHA-256 of "
                   f"{rec['n_input_files']} files ({rec['input_bytes'] / 1e6:.1f} MB); "
                   f"check with `sha256sum -c {relative_path(rd)}/{rec['inputs']}` in the "
                   "working folder (paths relative to it)")
    if rec.get("reproduce"):
        out.append(f"Rebuild it elsewhere: `bash {rec['reproduce']}` clones commit "
                   f"`{str(rec['git_commit'])[:12]}`, builds the environment from "
                   f"[{rec.get('lock', 'the lock')}]({rec.get('lock', '')}) and checks "
                   f"the inputs and [tables]({rec['tables']}) against the report's")
    deps = _dependency_versions(rd / rec["environment"])
    out.append(f"Environment: [{rec['environment']}]({rec['environment']}), "
               f"{rec['n_distributions']} distributions at exact versions"
               + (f"; gaitval's dependencies: {', '.join(f'`{d}`' for d in deps)}"
                  if deps else ""))
    out.append("Each step's full command is in its record under `provenance/`.")
    return out


def _decimals(col: pd.Series) -> int | None:
    """Decimals the paper prints in a ``*_published`` column (as stored in the CSV)."""
    vals = [str(v) for v in col if str(v) not in ("", "nan")]
    ds = [len(v.split(".")[1]) if "." in v and "e" not in v.lower() else 0 for v in vals]
    return min(max(ds), 4) if ds else None          # ratios stored in full: 4 at most


def _fmt_cell(v, decimals: int | None, pcol: bool) -> str:
    if isinstance(v, str):
        try:
            x = float(v) if v not in ("", "True", "False") else v
        except ValueError:
            return v
        if isinstance(x, str):
            return {"True": "yes", "False": "no"}.get(x, x)
        if "." not in v and "e" not in v.lower():
            return v                                  # integers as written
        v = x
    if isinstance(v, (int, np.integer)):
        return str(v)
    if v is None or not np.isfinite(v):
        return ""
    if pcol:
        return "< 0.001" if v < 0.001 else f"{v:.3f}"
    if decimals is not None:
        return f"{v:.{decimals}f}"
    if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e6):
        return f"{v:.3g}"
    return f"{v:.3f}"


def display_table(df: pd.DataFrame) -> tuple[list[tuple[str, bool]], list[list[str]]]:
    """Header ``(name, is_published)`` and formatted rows for the HTML report.

    Each ``<q>_published`` column moves right after ``<q>``; ``<q>`` and its published
    column are printed with the decimals the paper prints (those of the published column);
    p-values as ``< 0.001`` or three decimals; other floats with three decimals.
    """
    cols = [c for c in df.columns if not str(c).endswith("_published")
            or str(c)[:-10] not in df.columns]
    order = []
    for c in cols:
        order.append(c)
        if f"{c}_published" in df.columns:
            order.append(f"{c}_published")
    out = []
    for c in order:
        base = c[:-10] if c.endswith("_published") else c
        dec = _decimals(df[f"{base}_published"]) if f"{base}_published" in df else None
        pcol = base == "p" or base.endswith("_p")
        out.append((c, dec, pcol))
    rows = [[_fmt_cell(df[c].iloc[i], dec, pcol) for c, dec, pcol in out]
            for i in range(len(df))]
    return [(c, c.endswith("_published")) for c, _, _ in out], rows


_MD_INLINE = [(re.compile(r"`([^`]+)`"), r"<code>\1</code>"),
              (re.compile(r"\*\*([^*]+)\*\*"), r"<strong>\1</strong>"),
              (re.compile(r"\[([^\]]+)\]\(([^)]+)\)"), r"<a href='\2'>\1</a>"),
              (re.compile(r"(?<![\w*])_([^_]+)_(?![\w])"), r"<em>\1</em>")]


def md_inline(text: str) -> str:
    """The inline Markdown the report uses (code, bold, links, italics) as safe HTML."""
    out = html.escape(text, quote=False)
    for rx, rep in _MD_INLINE:
        out = rx.sub(rep, out)
    return out


def _md_table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(v).replace("|", "\\|") for v in r) + " |" for r in rows]
    return "\n".join(lines)


def collect(reports_dir: str | Path, study_names: list[str] | None = None,
            report_prov: dict | None = None) -> dict:
    """The report's content model, shared by the Markdown and the HTML."""
    rd = Path(reports_dir)
    prov = load_all(rd)
    tables = sorted((rd / "tables").glob("*.csv"))
    figures = sorted((rd / "figures").glob("*.png"))
    present = {p.stem for p in tables}
    verdicts = build_verdicts(rd / "tables")
    sections = []
    for sec in SECTION_TITLES:
        items = []
        for p in tables:
            if _section(p.stem) != sec:
                continue
            rel = str(p.relative_to(rd))
            cap, notes = _caption_notes(p.with_suffix(".md"))
            df = pd.read_csv(p, keep_default_na=False, dtype=str)
            header, rows = display_table(df)
            items.append({"kind": "table", "stem": p.stem, "caption": cap, "notes": notes,
                          "md": (p.with_suffix(".md").read_text(encoding="utf-8").rstrip()
                                 if p.with_suffix(".md").is_file() else ""),
                          "header": header, "rows": rows,
                          "files": [(p.name, rel), (f"{p.stem}.md", rel[:-4] + ".md"),
                                    (f"{p.stem}.tex", rel[:-4] + ".tex")],
                          "prov": _prov_line(prov.get(rel))})
        for p in figures:
            if _section(p.stem) == sec:
                rel = str(p.relative_to(rd))
                items.append({"kind": "figure", "stem": p.stem, "src": rel,
                              "prov": _prov_line(prov.get(rel))})
        # a protocol without any item was not in the run's studies (an MTST study
        # without mocap has no TUG trials): its section is absent, not "not produced"
        miss = [t for t in EXPECTED_TABLES.get(sec, []) if t not in present]
        if items:
            sections.append({"key": sec, "title": SECTION_TITLES[sec], "items": items,
                             "missing": miss})
    vd = verdicts.astype(str)
    return {"version": __version__, "studies": ", ".join(study_names or []) or "-",
            "verdict_summary": summary_lines(verdicts),
            "verdict_header": list(VERDICT_COLUMNS), "verdict_rows": vd.values.tolist(),
            "sections": sections, "provenance": _provenance(rd, report_prov)}


def render_markdown(c: dict) -> str:
    md = ["# gaitval report", "",
          f"gaitval {c['version']}. Studies: {c['studies']}.",
          "Every item below names the step, configuration hash, package version and git "
          "commit that produced it; how to rebuild the whole report, the resolved "
          "configuration, checksums of the inputs and exact package versions are under "
          "[Provenance](#provenance). Published values stand beside reproduced ones in the "
          "paper tables.", "", "## Verdicts: which published comparisons were reproduced", ""]
    md += [f"- {s}" for s in c["verdict_summary"]] + [""]
    rows = [[*r[:-1], f"[{r[-1]}](#{r[-1]})" if r[-1] else ""] for r in c["verdict_rows"]]
    md += [_md_table(c["verdict_header"], rows), ""]
    for sec in c["sections"]:
        md += [f"## {sec['title']}", ""]
        for it in sec["items"]:
            if it["kind"] == "table":
                md += [f"### {it['stem']}", "", it["md"] or f"[{it['stem']}]"
                       f"({it['files'][0][1]})", "",
                       "Files: " + " · ".join(f"[{n}]({r})" for n, r in it["files"]), "",
                       f"_{it['prov']}_", ""]
            else:
                md += [f"### {it['stem']}", "", f"![{it['stem']}]({it['src']})", "",
                       f"_{it['prov']}_", ""]
        if sec["missing"]:
            md += ["_Not produced yet: " + ", ".join(sec["missing"]) + "_", ""]
    md += ["## Provenance", ""] + [f"- {ln}" for ln in c["provenance"]] + [""]
    return "\n".join(md) + "\n"


_ENV = jinja2.Environment(loader=jinja2.PackageLoader("gaitval.report", "templates"),
                          autoescape=jinja2.select_autoescape(["html", "j2"]),
                          trim_blocks=True, lstrip_blocks=True)
_ENV.filters["md"] = lambda s: jinja2.utils.markupsafe.Markup(md_inline(s))


def render_html(c: dict) -> str:
    return _ENV.get_template("index.html.j2").render(**c)


def build_index(reports_dir: str | Path, *, study_names: list[str] | None = None
                ) -> tuple[Path, Path]:
    """Write ``index.md``, ``index.html`` and ``verdicts.{csv,md,tex}`` in ``reports_dir``;
    return the first two paths."""
    from gaitval.tables.render import write_table

    from gaitval.report.provenance import write_report_provenance

    rd = Path(reports_dir)
    c = collect(rd, study_names, write_report_provenance(rd))
    write_table(build_verdicts(rd / "tables"), rd / "verdicts",
                caption="Published comparisons of the seed papers and whether the "
                "reproduction goes the same way (gaitval.report.verdicts).",
                notes=c["verdict_summary"])
    return (write_text(rd / "index.md", render_markdown(c)),
            write_text(rd / "index.html", render_html(c)))
