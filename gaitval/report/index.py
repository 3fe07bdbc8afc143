"""``reports/index.md`` and ``reports/index.html``: every table and figure with provenance.

Both files are rendered from one content model (:func:`collect`): first what the data are
(:mod:`gaitval.report.datakind`: simulated replica, replay of real mocap or real recordings,
and what a verdict on them can show), then the verdict table
(:mod:`gaitval.report.verdicts`: outcome and why), then every table under
``reports/tables`` and figure under ``reports/figures`` grouped by protocol — the papers'
results first, the study's ingest and registration tables last, as an appendix — each
table with its caption, its notes (parsed from the table's ``.md``), its file links and
the provenance record of the step that made it (:mod:`gaitval.report.provenance`), each
figure with its caption (:data:`FIGURE_CAPTIONS`), and, for honesty, the paper tables not
produced yet (in the sections of the protocols the run produced anything for; the verdict
table says which papers were not run).
The Markdown is written directly; the HTML through the jinja2 template
``templates/index.html.j2``, with each ``*_published`` column placed right after the
reproduced column it belongs to and every number printed by
:mod:`gaitval.tables.numbers`, so a cell reads the same in the HTML as in the table's
``.md``.
"""
from __future__ import annotations

import html
import json
import re
from pathlib import Path

import jinja2
import pandas as pd

from gaitval import __version__
from gaitval.io.atomic import write_text
from gaitval.report.provenance import load_all, relative_path
from gaitval.report.datakind import PAPER_PROTOCOLS, headline, paper_data, run_data
from gaitval.report.verdicts import VERDICT_COLUMNS, build_verdicts, summary_lines

#: the verdict table's columns on the HTML page (verdicts.csv/md keep VERDICT_COLUMNS);
#: ``table`` is not a column there, it is the source cell's link
VERDICT_HTML_ORDER = ("study", "data", "comparison", "source", "published", "reproduced",
                      "criterion", "outcome", "robustness", "why", "alternative")
from gaitval.tables.labels import base_of, is_published, label
from gaitval.tables.numbers import format_value, to_display

#: The paper tables gaitval renders, by protocol.
EXPECTED_TABLES = {
    "tug": ["tug_table2", "tug_table3", "tug_table4", "tug_table5"],
    "mtst": ["mtst_table1", "mtst_table3", "mtst_table4"],
    "rollator": ["rollator_table1", "rollator_table2"],
    "ultrasonic": [f"ultrasonic_table{i}" for i in range(1, 9)] + ["ultrasonic_tableC1"],
}
SECTION_TITLES = {
    "tug": "TUG leg tracking (Yorozu et al. 2015a)",
    "mtst": "Multi-target stepping task (Yorozu et al. 2015b)",
    "rollator": "Robotic rollator, KF vs PF (Chalvatzaki et al. 2017)",
    "ultrasonic": "Ultrasonic foot tracking (Qi et al. 2014)",
    "legbench": "Annotated recordings without mocap: CLEAR-MOT (Leigh et al., ICRA 2015)",
    "detections": "External leg detectors (no identity): detection rate, RMSE and false "
                  "detections against the mocap legs",
    "peer": "Worked example: agreement statistics on a peer's published data",
    "sensitivity": "Sensitivity: the verdicts under the simulated replica's alternative free choices "
                   "(python3 run.py sensitivity)",
    "study": "Appendix: study, ingest and registration",
}
#: Captions of the papers' example figures (gaitval.pipeline.paper_figures); what the
#: run cannot show is said, never drawn.
PAPER_FIGURE_CAPTIONS = {
    "tug_fig12": "TUG: scan snapshots (laser points, true legs, each method's observed "
    "leg positions with their patterns, each leg's estimate and last scans) of Methods 1 "
    "and 2 around Method 1's first false tracking, in the turn where there is one (the "
    "title says which situation the run gave); the gates are not drawn, the track files "
    "do not keep them (cf. Yorozu et al. 2015a Fig. 12).",
    "tug_fig13": "TUG: the hidden leg during Method 2's longest occlusion in the turn, "
    "tracked by Method 2 (no interpolation) and Method 3 (Catmull–Rom) against VICON, and "
    "its position error over time (cf. Yorozu et al. 2015a Fig. 13).",
    "mtst_fig6a": "MTST: foot contacts of the proposed method near an assigned target, "
    "relative to the target's centre, with the target and the judgement region of a "
    "participant of the default height (cf. Yorozu et al. 2015b Fig. 6a).",
    "mtst_fig8": "MTST: scan snapshots of Method 1 (no FS_U) and Method 2 (FS_U) around "
    "Method 1's first lost track, each method's observations with their patterns; the "
    "validation regions are not drawn (cf. Yorozu et al. 2015b Fig. 8).",
    "mtst_fig9": "MTST: scan snapshots of Method 2 (large fixed region) and the proposed "
    "method (variable region, its radii per panel) where the legs were close together "
    "(Method 2's first switch, else the legs' closest approach), each method's "
    "observations with their patterns (cf. Yorozu et al. 2015b Fig. 9).",
    "rollator_fig5": "Rollator: KF and PF estimates on the laser scan where the KF's "
    "error began with clutter and with a hidden leg; the KF's detections and the PF's "
    "particles are not drawn, the track files do not keep them (cf. Chalvatzaki et al. 2017 Fig. 5).",
    "ultrasonic_fig2": "Ultrasonic: the heel's horizontal displacement of the most "
    "symmetric normal-speed trial and its biased and unbiased autocorrelation (cf. Qi et al. "
    "2014 Fig. 2).",
    "ultrasonic_fig3": "Ultrasonic: horizontal and vertical unbiased autocorrelation of the "
    "most symmetric normal-speed trial over one symmetry window, R1 and R2 marked (cf. "
    "Qi et al. 2014 Fig. 3).",
    "ultrasonic_fig4": "Ultrasonic: as Fig. 3 for the run's least symmetric trial; the "
    "paper shows an abnormal gait, the simulated replica has none, so this is not one (cf. Qi et al. "
    "2014 Fig. 4).",
}
#: Captions of the figures, by stem (``{p}``: the parameter of a per-parameter figure).
FIGURE_CAPTIONS = {
    "tug_trajectories": "TUG: tracked (thin) and true (thick) leg trajectories of a "
    "successful and a failed trial (rows), one column per method, each panel saying "
    "success or FAILED (cf. Yorozu et al. 2015a Fig. 14). The VICON legs set the axes; a "
    "track that diverges beyond them is clipped at the edge and its panel says how far it went.",
    "tug_false_tracking": "TUG: the first false tracking of a failed trial — both legs' "
    "tracks and truth around the moment a track jumped to the other leg or was lost "
    "(cf. Yorozu et al. 2015a Fig. 11).",
    "mtst_trial": "MTST: a successful and a failed trial on the mat (rows): tracked legs "
    "(thin) against the mocap legs (thick), foot contacts, targets, target steps judged (O) "
    "and cross steps detected (+) (cf. Yorozu et al. 2015b Fig. 10). The mocap legs and the "
    "mat set the axes; a track that diverges beyond them is clipped at the edge and its panel "
    "says how far it went.",
    "rollator_turning_trial": "Rollator: lateral and forward position of each leg over "
    "time in a successful and a failed trial; truth red, KF black, PF blue; grey bands: "
    "KF error frames, dotted lines: KF re-initialisations (cf. Chalvatzaki et al. 2017 Fig. 4). "
    "The truth sets each panel's vertical axis; a track that diverges beyond it is clipped "
    "and the panel says so.",
    "ultrasonic_figA1": "Ultrasonic: histograms of the stride-parameter differences system "
    "− reference at normal speed (cf. Qi et al. 2014 Fig. A1).",
    "ultrasonic_figB1": "Ultrasonic: per-subject boxplots of the system's stride "
    "parameters at normal speed (cf. Qi et al. 2014 Fig. B1).",
    "ultrasonic_fig5": "Ultrasonic: mean ± SD of reference and system per walking speed; "
    "* p < 0.05 against normal speed (paired t-test, Table 8; cf. Qi et al. 2014 Fig. 5).",
    "ultrasonic_bland_altman_{p}": "Ultrasonic: Bland–Altman plot of {p} at normal speed, "
    "system − reference against their mean, in the quantity's display unit; points "
    "coloured by subject; pooled bias and limits of agreement (grey, dashed, 95 % CIs as "
    "bands), repeated-measures ones (black, solid, CIs as bars) and the paper's mean "
    "difference (green, dash-dot) where it gives one; the legend is below the plot.",
    "legbench_tracks": "Annotated recordings: tracked person (leg midpoint) against the "
    "hand-annotated person over time, one row per method; misses marked below.",
    **PAPER_FIGURE_CAPTIONS,
}
def figure_caption(stem: str) -> str:
    """The caption of figure ``stem`` (:data:`FIGURE_CAPTIONS`; a generic one otherwise)."""
    if stem in FIGURE_CAPTIONS:
        return FIGURE_CAPTIONS[stem]
    for key, cap in FIGURE_CAPTIONS.items():
        head = key.split("{")[0]
        if "{" in key and stem.startswith(head):
            return cap.format(p=stem[len(head):].replace("_", " "))
    return stem.replace("_", " ") + "."


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


def _read_table(csv: Path) -> pd.DataFrame:
    """A table's CSV with its types (numbers as numbers, ``True``/``False`` as booleans)."""
    return pd.read_csv(csv)


def _md_cells(md_path: Path) -> tuple[list[str], list[list[str]]] | None:
    """Header and cells of the (first) pipe table of a table's ``.md`` — the strings
    :func:`gaitval.tables.render.write_table` printed from the typed table, so the HTML
    shows exactly what the Markdown shows (a CSV read back loses a text column's type)."""
    if not md_path.is_file():
        return None
    header, rows = None, []
    for ln in md_path.read_text(encoding="utf-8").splitlines():
        if ln.startswith("| "):
            cells = [c.strip().replace("\\|", "|")
                     for c in re.split(r"(?<!\\)\|", ln.strip())[1:-1]]
            if header is None:
                header = cells
            else:
                rows.append(cells)
        elif header is not None and not ln.startswith("|---"):
            break
    return (header, rows) if header else None


def _published_beside(header: list[str], rows: list[list[str]]
                      ) -> tuple[list[tuple[str, bool]], list[list[str]]]:
    """Each published column (header ``<label>, published``, :mod:`gaitval.tables.labels`)
    moved right after its quantity's."""
    published = {base_of(c): c for c in header if is_published(c) and base_of(c) in header}
    cols = [c for c in header if c not in published.values()]
    order = []
    for c in cols:
        order.append(c)
        if c in published:
            order.append(published[c])
    idx = [header.index(c) for c in order]
    return ([(c, is_published(c)) for c in order],
            [[r[i] if i < len(r) else "" for i in idx] for r in rows])


def display_table(df: pd.DataFrame, table: str | None = None
                  ) -> tuple[list[tuple[str, bool]], list[list[str]]]:
    """Header ``(label, is_published)`` and formatted rows for the HTML report.

    The table in its display units (:func:`gaitval.tables.numbers.to_display`), each
    ``<q>_published`` column right after ``<q>``, every cell by
    :func:`gaitval.tables.numbers.format_value` — the strings of the table's ``.md``.
    """
    d = to_display(df, table)
    cols = [c for c in d.columns if not str(c).endswith("_published")
            or str(c)[:-10] not in d.columns]
    order = []
    for c in cols:
        order.append(c)
        if f"{c}_published" in d.columns:
            order.append(f"{c}_published")
    rows = [[format_value(d[c].iloc[i], c, table) for c in order] for i in range(len(d))]
    return [(label(c), c.endswith("_published")) for c in order], rows


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


#: the data line of a report that holds the crowd benchmark's table: its scenes are not the
#: study's recordings but rendered by the twin (docs/crowd.md)
RENDERED_SCENES = ("**legbench_crowd**: simulated scenes (several people rendered by the "
                   "twin's laser model, ground truth per person), not recordings: its rows "
                   "test the people trackers on scenes of other kinds than the recordings'.")


def collect(reports_dir: str | Path, study_names: list[str] | None = None,
            report_prov: dict | None = None) -> dict:
    """The report's content model, shared by the Markdown and the HTML."""
    rd = Path(reports_dir)
    prov = load_all(rd)
    tables = sorted((rd / "tables").glob("*.csv"))
    figures = sorted((rd / "figures").glob("*.png"))
    present = {p.stem for p in tables}
    studies = run_data(rd, study_names)
    verdicts = build_verdicts(rd / "tables", {p: paper_data(studies, p)
                                              for p in PAPER_PROTOCOLS},
                              [Path(s.checks["path"]) for s in studies if s.checks])
    sections = []
    for sec in SECTION_TITLES:
        items = []
        expected = EXPECTED_TABLES.get(sec, [])
        for p in sorted(tables, key=lambda q: (expected.index(q.stem) if q.stem in expected
                                               else len(expected), q.stem)):
            if _section(p.stem) != sec:             # the paper's tables first, in order
                continue
            rel = str(p.relative_to(rd))
            cap, notes = _caption_notes(p.with_suffix(".md"))
            md_cells = _md_cells(p.with_suffix(".md"))
            header, rows = (_published_beside(*md_cells) if md_cells else
                            display_table(_read_table(p), p.stem))
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
                              "caption": figure_caption(p.stem),
                              "prov": _prov_line(prov.get(rel))})
        # a protocol without any item was not in the run's studies (an MTST study
        # without mocap has no TUG trials): its section is absent, not "not produced"
        miss = [t for t in EXPECTED_TABLES.get(sec, []) if t not in present]
        if items:
            sections.append({"key": sec, "title": SECTION_TITLES[sec], "items": items,
                             "missing": miss})
    vd = verdicts.astype(str)
    return {"version": __version__, "studies": ", ".join(study_names or []) or "-",
            "data": headline(studies) + ([RENDERED_SCENES] if "legbench_crowd" in present
                                         else []),
            "verdict_summary": summary_lines(verdicts),
            "verdicts": verdicts,
            "verdict_header": list(VERDICT_COLUMNS), "verdict_rows": vd.values.tolist(),
            # the page shows the robustness share beside the outcome, before the long
            # "why" text, so that it is in view without scrolling sideways
            "verdict_html_order": [VERDICT_COLUMNS.index(h) for h in VERDICT_HTML_ORDER],
            "sections": sections, "provenance": _provenance(rd, report_prov),
            "analysed": analysed_record(studies)}


def analysed_record(studies) -> dict:
    """What ``analysed.json`` holds: per study its trials, how many were analysed and each
    refused trial's reason (read by ``run.py`` for the run's closing summary and exit code)."""
    return {s.name: {"trials": s.n_trials, "analysed": s.n_trials - len(s.refused),
                     "refused": {t: {"protocol": proto, "reason": why}
                                 for t, (proto, why) in sorted(s.refused.items())}}
            for s in studies}


def render_markdown(c: dict) -> str:
    md = ["# gaitval report", ""]
    for ln in c["data"]:
        md += [ln, ""]
    md += [f"gaitval {c['version']}. Studies: {c['studies']}. Every item below names the "
           "step, configuration hash, package version and git commit that produced it; how "
           "to rebuild the whole report, the resolved configuration, checksums of the "
           "inputs and exact package versions are under [Provenance](#provenance). "
           "Published values stand beside reproduced ones in the paper tables; the study's "
           "ingest and registration tables are the appendix.", "",
           "## Verdicts: which published comparisons were reproduced", ""]
    md += [f"- {s}" for s in c["verdict_summary"]] + [""]
    head = c["verdict_header"]
    ti = head.index("table")
    rows = [[*r[:ti], f"[{r[ti]}](#{r[ti]})" if r[ti] else "", *r[ti + 1:]]
            for r in c["verdict_rows"]]
    md += [_md_table(head, rows), ""]
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
                       f"*Figure: {it['caption']}*", "", f"_{it['prov']}_", ""]
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
    write_table(c["verdicts"], rd / "verdicts",
                caption="Published comparisons of the seed papers: reproduced, not "
                "reproduced or not comparable, and why (gaitval.report.verdicts).",
                notes=c["data"] + c["verdict_summary"])
    write_text(rd / "analysed.json", json.dumps(c["analysed"], indent=1, sort_keys=True) + "\n")
    return (write_text(rd / "index.md", render_markdown(c)),
            write_text(rd / "index.html", render_html(c)))
