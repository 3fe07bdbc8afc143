"""What the data of a report are: simulated replica, replay of real mocap, or real recordings.

Read from the report's resolved configuration (``provenance/config.yaml``, written by the
workflow's ``report_config`` rule) and each study's trial sheet:

* a study with a ``simulate:`` block whose preset (``config/studies/<preset>.yaml``) has a
  ``replay:`` section is a **replay of real mocap** (real leg motion, simulated laser);
* any other ``simulate:`` study is a **simulated replica** of the papers' protocols;
* a study given by its own trial sheet is **real recordings**.

Each study's trial sheet says which protocols it has and how many subjects and trials; a
study smaller than the paper it is compared with is called so (the ``tiny`` preset has one
subject per protocol: it tests the pipeline, not the papers).  Nothing here imports the
simulator (import contract ``analysis-not-simulate``): presets are read as YAML.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
import yaml

#: The protocols (trial sheet ``protocol``) behind each paper's tables.
PAPER_PROTOCOLS = {"tug": ("tug",), "mtst": ("mtst",), "rollator": ("rollator",),
                   "ultrasonic": ("treadmill", "pendulum")}
#: Subjects and trials of each paper (seed README): what "smaller than the paper" means.
PAPER_SIZE = {"tug": (7, 28), "mtst": (16, 48), "rollator": (4, 16), "ultrasonic": (10, 30)}
#: The sentences a report's reader needs before any verdict, per data kind.
MEANING = {
    "simulated": ("A verdict on simulated data shows whether gaitval's implementation of a "
                  "paper's method, run on a replica of its protocol, orders and sizes its "
                  "results as the paper did; it cannot confirm or refute the paper's "
                  "findings about real people and sensors, and how hard the data are is set "
                  "by the simulator's assumptions (docs/simulator.md)."),
    "replay": ("A replay drives a simulated laser with real mocap walks: it tests the "
               "trackers on real gait kinematics, not on real sensor noise or occluders."),
    "real": ("Real recordings test the methods on real sensors and people; their subjects "
             "and setups still differ from the papers'."),
}
REPO = Path(__file__).resolve().parents[2]


@dataclass
class StudyData:
    """One study of the run: its name, kind, a label and its size per protocol."""
    name: str
    kind: str                          # simulated | replay | real | unknown
    label: str                         # "simulated replica (default, seed 20150904)"
    sizes: dict[str, tuple[int, int]] = field(default_factory=dict)   # protocol -> (subj, trials)
    #: the twin's physical checks (``physics.csv`` beside a simulated study's trial
    #: sheet): ``path``, ``n``, ``passed``, ``unchecked`` and the ``failed`` rows' names
    checks: dict | None = None
    #: trials refused at registration (``tables/study_registration_<study>.csv``):
    #: trial -> (protocol, reason); they are in no table of the run
    refused: dict[str, tuple[str, str]] = field(default_factory=dict)

    @property
    def n_trials(self) -> int:
        return sum(v[1] for v in self.sizes.values())

    @property
    def analysed(self) -> dict[str, tuple[int, int]]:
        """protocol -> (subjects, trials) analysed: the sheet's less the refused trials
        (a subject all of whose trials were refused is not counted)."""
        if not self.refused or self.rows is None:
            return dict(self.sizes)
        left = self.rows[~self.rows["trial"].isin(list(self.refused))]
        out = {p: (0, 0) for p in self.sizes}
        out.update({p: (int(g["subject"].nunique()), int(g["trial"].nunique()))
                    for p, g in left.groupby("protocol", sort=True)})
        return out

    #: the sheet's ``protocol, subject, trial`` columns (None when unreadable)
    rows: pd.DataFrame | None = None


def physics_checks(path: Path) -> dict | None:
    """Summary of a simulated study's ``physics.csv`` (gaitval.simulate.physics: the twin's
    physical checks against real gait and the papers' observation statistics), or None
    when the study has none.  A row without a pass/fail (no reference) is *unchecked*."""
    try:
        df = pd.read_csv(path, usecols=["check", "protocol", "phase", "passed"])
    except (OSError, ValueError):
        return None
    ok = df["passed"].astype(str).str.lower()
    failed = df[ok == "false"]
    names = [f"{r.check} ({r.protocol}" + (f", {r.phase})" if isinstance(r.phase, str)
                                             else ")") for r in failed.itertuples()]
    return {"path": str(path), "n": len(df), "passed": int((ok == "true").sum()),
            "unchecked": int((~ok.isin(["true", "false"])).sum()), "failed": names}


def _load_yaml(path: Path) -> dict:
    try:
        with open(path, encoding="utf-8") as fh:
            return yaml.safe_load(fh) or {}
    except (OSError, yaml.YAMLError):
        return {}


def refusals(reports_dir: Path, name: str) -> dict:
    """Trials of study ``name`` refused at registration, from the study's registration
    table in the report: trial -> (protocol, reason)."""
    try:
        df = pd.read_csv(Path(reports_dir) / "tables" / f"study_registration_{name}.csv",
                         dtype=str, keep_default_na=False)
    except (OSError, ValueError):
        return {}
    if not {"trial", "status"} <= set(df.columns):
        return {}
    bad = df[df["status"] != "ok"]
    return {str(r["trial"]): (str(r.get("protocol", "")), str(r.get("reason", "")))
            for r in bad.to_dict("records")}


def _rows(sheet: Path) -> pd.DataFrame | None:
    try:
        return pd.read_csv(sheet, usecols=["protocol", "subject", "trial"], dtype=str)
    except (OSError, ValueError):
        return None


def _sizes(sheet: Path) -> dict[str, tuple[int, int]]:
    df = _rows(sheet)
    if df is None:
        return {}
    return {p: (int(g["subject"].nunique()), int(g["trial"].nunique()))
            for p, g in df.groupby("protocol", sort=True)}


def study_data(name: str, config: dict, base: Path = Path(".")) -> StudyData:
    """The :class:`StudyData` of study ``name`` under the resolved ``config``; paths
    relative to ``base`` (the workflow's working directory)."""
    entry = (config.get("studies") or {}).get(name) or {}
    sim = entry.get("simulate")
    if sim:
        preset = str(sim.get("preset", name))
        seed = sim.get("seed", _load_yaml(REPO / "config" / "studies" / f"{preset}.yaml")
                       .get("seed", "?"))
        pcfg = _load_yaml(REPO / "config" / "studies" / f"{preset}.yaml")
        sheet = base / config.get("data_dir", "data") / name / "trials.csv"
        checks = physics_checks(sheet.parent / "physics.csv")
        if pcfg.get("replay"):
            return StudyData(name, "replay", f"replay of real mocap ({preset}, seed {seed})",
                             _sizes(sheet), checks)
        return StudyData(name, "simulated", f"simulated replica ({preset}, seed {seed})",
                         _sizes(sheet), checks)
    if entry.get("trial_sheet"):
        sheet = Path(entry["trial_sheet"])
        return StudyData(name, "real", f"real recordings ({name})",
                         _sizes(sheet if sheet.is_absolute() else base / sheet))
    return StudyData(name, "unknown", f"{name} (data kind unknown)")


def run_data(reports_dir: str | Path, study_names: list[str] | None,
             base: Path = Path(".")) -> list[StudyData]:
    """Every study of the run, from ``<reports_dir>/provenance/config.yaml``; studies
    without it are ``unknown`` (an index built outside the workflow)."""
    config = _load_yaml(Path(reports_dir) / "provenance" / "config.yaml")
    names = list(study_names or config.get("run") or [])
    if not config:
        return [StudyData(n, "unknown", f"{n} (data kind unknown: no provenance/config.yaml)")
                for n in names]
    out = [study_data(n, config, base) for n in names]
    for s in out:
        s.refused = refusals(Path(reports_dir), s.name)
        if s.refused:
            s.rows = _rows(_sheet_of(s.name, config, base))
    return out


def _sheet_of(name: str, config: dict, base: Path) -> Path:
    entry = (config.get("studies") or {}).get(name) or {}
    if entry.get("simulate"):
        return base / config.get("data_dir", "data") / name / "trials.csv"
    sheet = Path(entry.get("trial_sheet") or "")
    return sheet if sheet.is_absolute() else base / sheet


def paper_data(studies: list[StudyData], paper: str) -> str:
    """The data a paper's verdicts rest on: the studies with its protocols, each with its
    size where it is smaller than the paper's (``toy size: 1 subject, 2 trials; paper 7,
    28``)."""
    protos = PAPER_PROTOCOLS.get(paper, (paper,))
    parts = []
    for s in studies:
        have = {p: s.analysed[p] for p in protos if p in s.sizes}
        if s.sizes and not have:
            continue
        text = s.label
        if have:
            subj = max(v[0] for v in have.values())
            trials = sum(v[1] for v in have.values())
            ps, pt = PAPER_SIZE.get(paper, (0, 0))
            n_ref = sum(1 for proto, _ in s.refused.values() if proto in protos)
            if subj < ps:
                text += (f"; smaller than the paper: {subj} subject{'s' * (subj != 1)}, "
                         f"{trials} trial{'s' * (trials != 1)} analysed (paper {ps}, {pt})")
            elif n_ref:
                text += f"; {trials} trial{'s' * (trials != 1)} analysed"
            if n_ref:
                text += f", {n_ref} refused at registration"
        parts.append(text)
    return " + ".join(parts) if parts else "no study of the run has this protocol"


def _without_where(reason: str) -> str:
    """A refusal's message without its leading ``[file ..., trial ...]`` (the line names
    the trial already)."""
    return re.sub(r"^\[[^\]]*\]\s*", "", reason)


def headline(studies: list[StudyData]) -> list[str]:
    """The lines at the top of the report: what the data are and what a verdict means."""
    if not studies:
        return ["Data: no study named (an index built outside the workflow)."]
    out = ["Data: " + "; ".join(f"**{s.name}**: {s.label}" for s in studies) + "."]
    for s in studies:
        if s.refused:
            n_an = s.n_trials - len(s.refused)
            out.append(f"**{s.name}: {n_an} of {s.n_trials} trials analysed; "
                       f"{len(s.refused)} refused at registration** and left out of every "
                       "table and verdict (the registration table in the appendix has "
                       "each one's files):")
            out += [f"✗ `{t}` ({proto}): {_without_where(why)}"
                    for t, (proto, why) in sorted(s.refused.items())]
    for s in studies:
        small = [paper for paper, protos in PAPER_PROTOCOLS.items()
                 if any(p in s.sizes for p in protos) and max(
                     s.analysed[p][0] for p in protos if p in s.sizes) < PAPER_SIZE[paper][0]]
        if small:
            out.append(f"**{s.name}** has fewer subjects than the paper for "
                       f"{', '.join(small)}: a comparison it is too small for is reported "
                       "as _not comparable (too small)_, and the others rest on few walks.")
    for s in studies:
        c = s.checks
        if not c:
            continue
        line = (f"**{s.name}**'s simulated replica passes {c['passed']} of its {c['n']} "
                f"physical checks "
                f"(`{c['path']}`: gait and contact physics against real walks, the papers' "
                f"occlusion rates, phase durations and step counts; docs/simulator.md, "
                f"\"Physical checks\")")
        if c["unchecked"]:
            n = c["unchecked"]
            line += (f"; {n} {'has' if n == 1 else 'have'} no reference and "
                     f"{'is' if n == 1 else 'are'} shown only")
        if c["failed"]:
            line += (f"; **{len(c['failed'])} fail**: {', '.join(c['failed'])}, which the "
                     "verdicts on those protocols inherit (what is known of each failure's "
                     "cause: docs/simulator.md, \"Known limits\")")
        out.append(line + ".")
    kinds = dict.fromkeys(s.kind for s in studies)
    out += [MEANING[k] for k in kinds if k in MEANING]
    if any(k == "unknown" for k in kinds):
        out.append("The kind of some data is unknown (no resolved configuration beside the "
                   "report): read the verdicts as about data of unknown origin.")
    return out
