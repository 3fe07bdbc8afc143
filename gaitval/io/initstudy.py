"""``gaitval init-study FOLDER``: a trial sheet, a subject table, a ``study.yaml`` and a
workflow config snippet from a folder of recordings (issue 37).

The folder holds what a lab exported: C3D files, laser logs (``*.scan.parquet``, ROS bags),
ultrasonic logs (``*.us.parquet``), rater annotations (``*.annotations.csv``,
``*.positions.csv``), MTST target layouts (``*.targets.csv``) and external trackers' tracks
(``*.tracks.csv``/``*.tracks.parquet``).  :func:`scan_folder` finds them; :func:`init_study`
pairs each sensor file with its C3D — by name (the same stem) first, then by time (the
files' modification times, closest first, within ``max_time_gap_s``) — and reads what the
files say about each trial:

* protocol, subject, speed, scenario, repetition and stick from the words of the file
  name (``tug_Y01_t1``, ``rollator_P01_straight_r1``, ``us_US01_slow``; words separated by
  ``_``, ``-``, ``.`` or spaces); the subject from the C3D's ``SUBJECTS:NAMES`` only when
  the name has no subject word (Vicon's names are often a session's, e.g. ``Treadmill``;
  the summary says where each id came from); the protocol from the markers when the name has no protocol word (rollator
  markers ``RLT_*``; ultrasonic logs are ``treadmill`` trials unless named ``pendulum``);
* the sensor height from the scan log's ``mounting_height_m``, the LaserScan topic of a
  bag when it has exactly one;
* the subject's height, mass, knee and ankle widths and leg length from the C3D's
  Plug-in-Gait ``PROCESSING`` parameters (``Height``, ``Bodymass``, ``L/RKneeWidth``, ...);
* whether the laser can be registered with poles: a C3D without ``POLE<n>`` markers gets
  the manual-pose columns ``sensor_x_m``, ``sensor_y_m``, ``sensor_yaw_deg`` to fill in.
* external trackers' track files named by trial id (``<folder>/<trial>.tracks.csv``):
  an entry of the ``study.yaml``'s ``external_methods:``, checked like a hand-written one;
  a tracker topic recorded in the sensor bags: a commented entry (its legs are the
  user's to name); leg_tracker's leg detections (``LegArray``) recorded in them: an
  ``external_detections:`` entry.  The config snippet holds only what a study.yaml cannot: where the
  sheet and subject table are, and ``run``.

What the files cannot say and a table needs is written as :data:`FILL_IN` — the shank
width at the sensor's height (``leg_width_m``), a subject's height for the MTST foot model,
whether an MTST participant walked with a stick, a study calibration such as the
rollator's sensor mount — so that ``gaitval validate`` refuses the sheet, naming the row
and the column, until the user has filled it in.  Nothing is guessed silently: every
filled value's source and every cell left to the user are listed in the report
(:class:`InitResult`).
"""
from __future__ import annotations

import csv
import io
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from gaitval.errors import GaitvalError
from gaitval.io.atomic import write_text

#: what a cell the user must fill in holds (refused by ``gaitval validate``)
FILL_IN = "FILL_IN"
TRIAL_COLUMNS = ("study", "protocol", "subject", "trial", "sensor_kind", "mocap_file",
                 "sensor_file", "sensor_topic", "annotation_file", "sensor_height_m",
                 "sensor_x_m", "sensor_y_m", "sensor_yaw_deg", "clock_offset_s", "speed",
                 "speed_mps", "stick", "scenario", "repetition")
SUBJECT_COLUMNS = ("subject", "group", "age_y", "sex", "height_m", "mass_kg", "leg_width_m",
                   "knee_width_m", "ankle_width_m", "leg_length_m", "shank_length_m",
                   "stick")
PROTOCOL_WORDS = {"tug": "tug", "mtst": "mtst", "rollator": "rollator",
                  "treadmill": "treadmill", "pendulum": "pendulum", "legbench": "legbench"}
#: words of a file name that name the sensor or the kind of file, not the trial
NOISE_WORDS = {"us", "ultrasonic", "lrs", "laser", "scan", "mocap", "vicon", "trial"}
SPEEDS = ("slow", "normal", "fast")
STICK_WORDS = {"stick": True, "cane": True, "nostick": False, "no-stick": False}
_REPETITION = re.compile(r"^(?:t|r|rep|trial)?(\d{1,6})$")
_ID_BAD = re.compile(r"[^A-Za-z0-9_.-]")


def _as_id(text: str, fallback: str) -> str:
    """``text`` as an id (gaitval.configcheck.id_problem): other characters as ``_``, no
    leading ``-`` or ``.`` (a command line would read ``-rf`` as options)."""
    return _ID_BAD.sub("_", text).lstrip("-.")[:100] or fallback


def _unique_id(candidates: list[str], taken: set[str]) -> str:
    """The first of ``candidates`` (ids) no id in ``taken`` (lower case) equals up to
    case, else the last one with ``_2``, ``_3``, ...: ids that differ only in case name
    one folder on macOS and Windows.  Adds the id to ``taken``."""
    for c in candidates:
        if c.lower() not in taken:
            taken.add(c.lower())
            return c
    n = 2
    while f"{candidates[-1]}_{n}".lower() in taken:
        n += 1
    taken.add(f"{candidates[-1]}_{n}".lower())
    return f"{candidates[-1]}_{n}"
#: folders never scanned: what gaitval or a simulator writes, and hidden folders
SKIP_DIRS = {"truth", "results", "reports", "logs", ".snakemake"}
SUFFIXES = (("c3d", (".c3d",)), ("scanlog", (".scan.parquet",)),
            ("ultrasonic", (".us.parquet",)), ("annotations", (".annotations.csv",)),
            ("positions", (".positions.csv",)), ("targets", (".targets.csv",)),
            ("tracks", (".tracks.csv", ".tracks.parquet")),
            ("foot", (".foot.csv", ".foot.parquet")), ("bag", (".bag",)))
#: the protocols an external file of each kind can cover (leg tracks: a fixed or moving
#: laser; heel trajectories: the treadmill, docs/formats.md "Foot trajectories")
EXTERNAL_KINDS = {"tracks": {"tug", "mtst", "rollator"}, "foot": {"treadmill"}}


@dataclass
class Found:
    """One recording file: its kind, path relative to the folder, and name stem."""

    kind: str
    rel: str
    stem: str
    mtime: float


@dataclass
class InitResult:
    """What :func:`init_study` wrote and what the user must still do."""

    folder: Path
    written: list[Path] = field(default_factory=list)
    kept: list[Path] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)       # what was filled from where
    todo: list[str] = field(default_factory=list)        # cells and settings to fill in
    unpaired: list[str] = field(default_factory=list)    # files that became no trial
    problems: list[str] = field(default_factory=list)    # gaitval validate's list

    def text(self) -> str:
        out = [f"init-study {self.folder}:"]
        out += [f"  wrote {p}" for p in self.written]
        out += [f"  kept  {p} (exists; --force replaces it)" for p in self.kept]
        if self.notes:
            out.append("from the files:")
            out += [f"  {n}" for n in self.notes]
        if self.unpaired:
            out.append("files that are no trial:")
            out += [f"  {n}" for n in self.unpaired]
        if self.todo:
            out.append(f"to fill in (cells marked {FILL_IN}):")
            out += [f"  {n}" for n in self.todo]
        if self.problems:
            out.append(f"gaitval validate: {len(self.problems)} problem"
                       f"{'s' * (len(self.problems) > 1)}:")
            out += [f"  {p}" for p in self.problems]
        else:
            out.append("gaitval validate: OK")
        return "\n".join(out)


def _kind(name: str) -> tuple[str, str] | None:
    low = name.lower()
    for kind, sufs in SUFFIXES:
        for s in sufs:
            if low.endswith(s) and len(name) > len(s):
                return kind, name[:-len(s)]
    return None


def scan_folder(folder: Path) -> list[Found]:
    """Every recording file under ``folder`` (sorted by path), ROS 2 bag folders included;
    symbolic links that lead outside the folder are skipped (the sheet could not use them)."""
    folder = Path(folder)
    root = folder.resolve()
    found: list[Found] = []
    for dirpath, dirnames, filenames in os.walk(folder):
        d = Path(dirpath)
        if (d / "metadata.yaml").is_file() and d != folder:        # a ROS 2 bag folder
            found.append(Found("bag", d.relative_to(folder).as_posix(), d.name,
                               (d / "metadata.yaml").stat().st_mtime))
            dirnames[:] = []
            continue
        dirnames[:] = sorted(n for n in dirnames if n not in SKIP_DIRS and not n.startswith("."))
        for name in sorted(filenames):
            k = _kind(name)
            p = d / name
            if k is None or not p.resolve().is_relative_to(root):
                continue
            found.append(Found(k[0], p.relative_to(folder).as_posix(), k[1],
                               p.stat().st_mtime))
    return sorted(found, key=lambda f: f.rel)


def _words(stem: str) -> list[str]:
    return [w for w in re.split(r"[_\-. ]+", stem) if w]


def _c3d_facts(path: Path) -> dict:
    """Labels, Vicon subject name and Plug-in-Gait anthropometrics (m, kg) of a C3D."""
    from gaitval.io.c3d import read_c3d
    from gaitval.io.c3d_params import Parameters, decode_text, parse_parameters

    tr = read_c3d(path)
    out: dict = {"labels": list(tr.labels)}
    with open(path, "rb") as fh:
        head = fh.read(512)
        ps = (max(head[0], 1) - 1) * 512
        ds = (int.from_bytes(head[16:18], "little") - 1) * 512
        fh.seek(0)
        section = fh.read(ds)
    try:
        proc = section[ps + 3]
        params = Parameters(parse_parameters(section, ps, ds), dec=proc == 85)
    except Exception:                                  # noqa: BLE001 - read_c3d read it
        return out
    names = params.params.get(("SUBJECTS", "NAMES"))
    if names is not None and names.type == -1:
        text = decode_text(names.data).strip()
        width = names.dims[0] if names.dims else len(text)
        first = text[:width].strip() if width else ""
        if first and not _ID_BAD.search(first):
            out["subject"] = first
    pig = {}
    for key, col, scale in (("Height", "height_m", 1e-3), ("Bodymass", "mass_kg", 1.0),
                            ("KneeWidth", "knee_width_m", 1e-3),
                            ("AnkleWidth", "ankle_width_m", 1e-3),
                            ("LegLength", "leg_length_m", 1e-3),
                            ("TibiaLength", "shank_length_m", 1e-3)):
        vals = [params.first("PROCESSING", n.upper()) for n in (key, f"L{key}", f"R{key}")]
        vals = [v for v in vals if v is not None and v > 0]
        if vals:
            pig[col] = round(sum(vals) / len(vals) * scale, 4)
    out["pig"] = pig
    return out


def _bag_topics(path: Path) -> tuple[str | None, list[str], list[str]]:
    """The bag's LaserScan topic (None unless exactly one), its tracker topics
    (:data:`gaitval.io.tracks.bag.BAG_PEOPLE_TYPES`: a tracker recorded with the scans) and its
    leg-detection topics (:data:`gaitval.io.tracks.bag.BAG_LEG_DETECTIONS`)."""
    from gaitval.io.rosbag import LASERSCAN, _open
    from gaitval.io.tracks.bag import BAG_LEG_DETECTIONS, BAG_PEOPLE_TYPES

    reader = _open(path, None)
    try:
        scans = sorted({c.topic for c in reader.connections if c.msgtype == LASERSCAN})
        trackers = sorted({c.topic for c in reader.connections
                           if c.msgtype in BAG_PEOPLE_TYPES})
        detectors = sorted({c.topic for c in reader.connections
                            if c.msgtype == BAG_LEG_DETECTIONS})
    finally:
        reader.close()
    return (scans[0] if len(scans) == 1 else None), trackers, detectors


def _scanlog_height(path: Path) -> float | None:
    import json

    import pyarrow.parquet as pq
    meta = (pq.read_schema(path).metadata or {}).get(b"gaitval:scanlog")
    if not meta:
        return None
    h = json.loads(meta).get("mounting_height_m")
    return float(h) if isinstance(h, (int, float)) and h > 0 else None


def _pair(sensors: list[Found], c3ds: list[Found], max_gap: float
          ) -> tuple[dict[str, Found], list[str]]:
    """sensor rel -> C3D: by stem first, then by modification time (one to one)."""
    by_stem: dict[str, list[Found]] = {}
    for c in c3ds:
        by_stem.setdefault(c.stem, []).append(c)
    pairs: dict[str, Found] = {}
    used: set[str] = set()
    notes: list[str] = []
    for s in sensors:
        hits = [c for c in by_stem.get(s.stem, []) if c.rel not in used]
        if len(hits) == 1:
            pairs[s.rel] = hits[0]
            used.add(hits[0].rel)
    left_s = [s for s in sensors if s.rel not in pairs]
    left_c = [c for c in c3ds if c.rel not in used]
    cand = sorted((abs(s.mtime - c.mtime), s.rel, c.rel) for s in left_s for c in left_c
                  if abs(s.mtime - c.mtime) <= max_gap)
    taken_s: set[str] = set()
    for gap, srel, crel in cand:
        if srel in taken_s or crel in used:
            continue
        pairs[srel] = next(c for c in left_c if c.rel == crel)
        used.add(crel)
        taken_s.add(srel)
        notes.append(f"{srel} paired with {crel} by time (files written {gap:.0f} s apart; "
                     "check)")
    return pairs, notes


def _fmt(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "True" if v else "False"
    if isinstance(v, float):
        return repr(round(v, 6))
    return str(v)


def _csv(rows: list[dict], columns) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([_fmt(r.get(c)) for c in columns])
    return buf.getvalue()


def _trial_from_name(stem: str, kind: str, labels: list[str]) -> dict:
    words = _words(stem)
    low = [w.lower() for w in words]
    out: dict = {}
    protos = [PROTOCOL_WORDS[w] for w in low if w in PROTOCOL_WORDS]
    if protos:
        out["protocol"] = protos[0]
    elif kind == "ultrasonic":
        out["protocol"] = "treadmill"
    elif any(lab.startswith("RLT_") for lab in labels):
        out["protocol"] = "rollator"
    rest = []
    for w, lw in zip(words, low):
        if lw in PROTOCOL_WORDS or lw in NOISE_WORDS:
            continue
        if lw in SPEEDS:
            out["speed"] = lw
        elif lw in STICK_WORDS:
            out["stick"] = STICK_WORDS[lw]
        elif _REPETITION.match(lw):
            out.setdefault("repetition", int(_REPETITION.match(lw).group(1)))
        else:
            rest.append(w)
    rest = [w for w in (_as_id(w, "") for w in rest) if w]  # ids: letters, digits, _ . -
    if out.get("protocol") == "pendulum":
        out["subject"] = "pendulum"
        rest = [w for w in rest if w.lower() != "pendulum"]
    elif rest:
        out["subject"] = rest.pop(0)
    if rest:
        out["scenario"] = "_".join(rest)
    return out


def init_study(folder, *, study: str | None = None, force: bool = False,
               max_time_gap_s: float = 300.0, validate: bool = True) -> InitResult:
    """Write ``trials.csv``, ``subjects.csv``, ``study.yaml`` (when absent) and
    ``gaitval.config.yaml`` into ``folder`` from the recordings in it (module docstring);
    run ``gaitval validate`` on the result.  Existing ``trials.csv``/``subjects.csv`` are
    replaced only with ``force``; an existing ``study.yaml`` is always kept."""
    folder = Path(folder)
    if not folder.is_dir():
        raise GaitvalError(f"init-study: {folder} is not a folder")
    study = study or _as_id(folder.resolve().name, "study")
    res = InitResult(folder)
    sheet, subjects_csv = folder / "trials.csv", folder / "subjects.csv"
    for p in (sheet, subjects_csv):
        if p.exists() and not force:
            raise GaitvalError(f"init-study: {p} exists; move it away or pass --force to "
                               "replace it")
    files = scan_folder(folder)
    if not files:
        raise GaitvalError(f"init-study: {folder} holds no recording gaitval reads "
                           "(*.c3d, *.scan.parquet, *.bag, *.us.parquet; docs/formats.md)")
    c3ds = [f for f in files if f.kind == "c3d"]
    sensors = [f for f in files if f.kind in ("scanlog", "bag", "ultrasonic")]
    by_kind_stem = {(f.kind, f.stem): f for f in files}
    pairs, notes = _pair(sensors, c3ds, max_time_gap_s)
    res.notes += notes
    paired_c3d = {c.rel for c in pairs.values()}
    res.unpaired += [f"{c.rel}: a C3D without a sensor file of the same name or time"
                     for c in c3ds if c.rel not in paired_c3d]

    facts: dict[str, dict] = {}
    bag_trackers: dict[str, list[str]] = {}       # tracker topic -> sensor bags with it
    bag_detectors: dict[str, list[str]] = {}      # LegArray topic -> sensor bags with it
    trials: list[dict] = []
    ids: set[str] = set()
    id_source: dict[str, list[str]] = {}          # where each trial's subject id came from
    for s in sensors:
        c3d = pairs.get(s.rel)
        f = {"labels": []}
        if c3d:
            try:
                f = _c3d_facts(folder / c3d.rel)
            except GaitvalError as exc:               # a file gaitval cannot read: said
                res.unpaired.append(f"{c3d.rel}: {exc}")
        if c3d:
            facts[c3d.rel] = f
        info = _trial_from_name(s.stem, s.kind, f["labels"])
        if info.get("subject"):
            id_source.setdefault("the file name", []).append(s.stem)
        elif f.get("subject") and info.get("protocol") != "pendulum":
            info["subject"] = f["subject"]           # the name has no subject word
            id_source.setdefault("the C3D's SUBJECTS:NAMES", []).append(s.stem)
        trial = _unique_id([_as_id(s.stem, "trial"),
                            _as_id(s.rel.rsplit(".", 2)[0].replace("/", "_"), "trial")], ids)
        row = {"study": study, "trial": trial, "sensor_file": s.rel,
               "sensor_kind": "ultrasonic" if s.kind == "ultrasonic" else "lrs",
               "mocap_file": c3d.rel if c3d else "", **info}
        ann = by_kind_stem.get(("annotations", s.stem)) or by_kind_stem.get(("positions",
                                                                              s.stem))
        if ann:
            row["annotation_file"] = ann.rel
        if s.kind == "bag":
            try:
                topic, trackers, detectors = _bag_topics(folder / s.rel)
            except GaitvalError as exc:
                res.unpaired.append(f"{s.rel}: {exc}")
                topic, trackers, detectors = None, [], []
            for tt in trackers:
                bag_trackers.setdefault(tt, []).append(s.rel)
            for tt in detectors:
                bag_detectors.setdefault(tt, []).append(s.rel)
            row["sensor_topic"] = topic or FILL_IN
            if topic is None:
                res.todo.append(f"trials.csv {trial}: sensor_topic (the bag has none or "
                                "several LaserScan topics; `gaitval inspect` lists them)")
        if row["sensor_kind"] == "lrs":
            h = _scanlog_height(folder / s.rel) if s.kind == "scanlog" else None
            if h is not None:
                row["sensor_height_m"] = h
            else:
                row["sensor_height_m"] = FILL_IN
                res.todo.append(f"trials.csv {trial}: sensor_height_m (the log does not "
                                "give the scan plane's height)")
            poles = [lab for lab in f["labels"] if re.fullmatch(r"POLE\d+", lab)]
            if c3d and len(poles) < 2 and row.get("protocol") != "rollator":
                for col in ("sensor_x_m", "sensor_y_m", "sensor_yaw_deg"):
                    row[col] = FILL_IN
                res.todo.append(f"trials.csv {trial}: sensor_x_m, sensor_y_m, sensor_yaw_deg"
                                " (the C3D has no POLE1/POLE2 markers: measure the sensor's "
                                "pose in the mocap frame)")
        if not c3d and not ann:
            res.unpaired.append(f"{s.rel}: no C3D and no annotations (a trial needs one of "
                                "them)")
        for col in ("protocol", "subject"):
            if not row.get(col):
                row[col] = FILL_IN
                res.todo.append(f"trials.csv {trial}: {col} (not in the file name"
                                f"{' or the C3D' if col == 'subject' else ''})")
        if row.get("protocol") == "mtst" and "stick" not in row:
            row["stick"] = FILL_IN
            res.todo.append(f"trials.csv {trial}: stick (true/false; MTST Tables 1, 3 and 4 "
                            "group by it)")
        trials.append(row)
    for src, stems in id_source.items():
        res.notes.append(f"subject ids from {src}: {len(stems)} trial"
                         f"{'s' * (len(stems) != 1)} ({', '.join(stems[:3])}"
                         f"{', ...' if len(stems) > 3 else ''})")
    _number_repetitions(trials)
    trials.sort(key=lambda r: (r["trial"]))

    subjects = _subject_rows(trials, facts, res)
    yaml_path = folder / "study.yaml"
    external = _external_methods(trials, files, res, yaml_path)
    bag_lines = _bag_tracker_lines(trials, bag_trackers, res)
    detections = _bag_detections(trials, bag_detectors, res, yaml_path)
    if yaml_path.exists():
        res.kept.append(yaml_path)
        # not written there: the entries to add are in the todo list instead
        res.notes = [n for n in res.notes if not n.startswith(
            ("study.yaml external_methods.", "study.yaml external_detections."))]
        _external_todo(yaml_path, external, bag_lines, res, detections)
    else:
        write_text(yaml_path, _study_yaml(trials, files, res, external, bag_lines,
                                          detections))
        res.written.append(yaml_path)
    write_text(sheet, _csv(trials, TRIAL_COLUMNS))
    write_text(subjects_csv, _csv(subjects, SUBJECT_COLUMNS))
    res.written += [sheet, subjects_csv]
    snippet = folder / "gaitval.config.yaml"
    write_text(snippet, _config_snippet(study, folder))
    res.written.append(snippet)
    res.notes.append(f"{len(trials)} trials, {len(subjects)} subjects; run with "
                     f"`python3 run.py report --configfile {snippet}`")
    if validate:
        from gaitval.io.trialsheet import sheet_problems
        _, problems = sheet_problems(sheet, subjects_csv)
        res.problems = [str(p) for p in problems]
    return res


def _number_repetitions(trials: list[dict]) -> None:
    """A trial without a repetition word: its number among the trials of the same
    protocol, subject, speed and scenario (by trial id)."""
    groups: dict[tuple, list[dict]] = {}
    for r in trials:
        if "repetition" not in r:
            key = (r.get("protocol"), r.get("subject"), r.get("speed"), r.get("scenario"))
            groups.setdefault(key, []).append(r)
    for rows in groups.values():
        for i, r in enumerate(sorted(rows, key=lambda r: r["trial"]), 1):
            r["repetition"] = i


def _subject_rows(trials: list[dict], facts: dict, res: InitResult) -> list[dict]:
    out: dict[str, dict] = {}
    for r in trials:
        subj = r["subject"]
        if subj == FILL_IN:
            continue
        row = out.setdefault(subj, {"subject": subj, "_protocols": set()})
        row["_protocols"].add(r.get("protocol"))
        pig = facts.get(r.get("mocap_file"), {}).get("pig") or {}
        for k, v in pig.items():
            row.setdefault(k, v)
    rows = []
    for subj in sorted(out):
        row = out[subj]
        protos = row.pop("_protocols")
        src = [k for k in ("height_m", "mass_kg", "knee_width_m", "ankle_width_m",
                           "leg_length_m", "shank_length_m") if k in row]
        if src:
            res.notes.append(f"subjects.csv {subj}: {', '.join(src)} from the C3D's "
                             "Plug-in-Gait PROCESSING parameters")
        if not protos - {"treadmill", "pendulum"}:
            row["leg_width_m"] = 0.10
            res.notes.append(f"subjects.csv {subj}: leg_width_m 0.10, a placeholder (the "
                             "ultrasonic protocol does not use it; the table requires one)")
        else:
            row["leg_width_m"] = FILL_IN
        if row["leg_width_m"] == FILL_IN:
            hint = (f"; the mocap's knee width is {row['knee_width_m']} m"
                    if "knee_width_m" in row else "")
            res.todo.append(f"subjects.csv {subj}: leg_width_m (shank width at the "
                            f"sensor's height, measured{hint})")
        if "mtst" in protos:
            if "height_m" not in row:
                row["height_m"] = FILL_IN
                res.todo.append(f"subjects.csv {subj}: height_m (the MTST foot model scales "
                                "with it)")
            row["stick"] = FILL_IN
            res.todo.append(f"subjects.csv {subj}: stick (true/false)")
        rows.append(row)
    return rows


def _study_yaml(trials: list[dict], files: list[Found], res: InitResult,
                external: dict | None = None, bag_lines: list[str] = (),
                detections: dict | None = None) -> str:
    """study.yaml: the MTST target layouts when every MTST trial has one in one folder;
    the rollator's sensor mount as a key to fill in; the external trackers' track files as
    ``external_methods:`` (:func:`_external_methods`), a tracker recorded in the sensor
    bags as commented entries (:func:`_bag_tracker_lines`)."""
    doc: dict = {}
    lines = ["# Study calibration (docs/formats.md, 'Study calibration'), written by "
             "gaitval init-study."]
    mtst = [r["trial"] for r in trials if r.get("protocol") == "mtst"]
    targets = {f.stem: f.rel for f in files if f.kind == "targets"}
    if mtst and all(t in targets for t in mtst):
        dirs = {str(Path(targets[t]).parent) for t in mtst}
        if len(dirs) == 1:
            d = dirs.pop()
            doc.setdefault("mtst", {})["targets"] = (
                f"{d}/{{trial}}.targets.csv" if d != "." else "{trial}.targets.csv")
            res.notes.append(f"study.yaml mtst.targets: {doc['mtst']['targets']}")
    elif mtst:
        res.todo.append("study.yaml mtst.targets: no target layout (*.targets.csv) for "
                        "every MTST trial (or set mtst.require_targets: false)")
    if any(r.get("protocol") == "rollator" for r in trials):
        doc.setdefault("rollator", {})["sensor_mount"] = {
            "x_m": FILL_IN, "y_m": FILL_IN, "yaw_rad": FILL_IN}
        res.todo.append("study.yaml rollator.sensor_mount: the laser's pose in the "
                        "rollator frame (x_m, y_m, yaw_rad)")
    if any(r.get("sensor_kind") == "lrs" and r.get("mocap_file")
           and r.get("sensor_x_m") != FILL_IN for r in trials):
        lines.append("# registration.pole_diameter_m: the calibration poles' diameter "
                     "(default 0.05 m)")
    if external:
        doc["external_methods"] = external
    if detections:
        doc["external_detections"] = detections
    body = yaml.safe_dump(doc, sort_keys=True) if doc else ""
    tail = []
    if bag_lines:
        tail += ["# A tracker recorded in the sensor bags (docs/formats.md, 'External "
                 "methods'):", "# to validate it, fill in each leg's person id and "
                 "uncomment its entry"]
        tail += ["# external_methods:"] * (not external) + list(bag_lines)
    tracks = sorted({f.rel for f in files if f.kind == "tracks"})
    if tracks and not external:
        tail += ["# External trackers' tracks were found, not named by trial ids "
                 "(docs/formats.md, 'External methods'); declare each as a method, e.g.",
                 "# external_methods:",
                 f"#   my_tracker: {{path: \"{tracks[0]}\"}}   # {{trial}} for the trial id"]
    return "\n".join(lines) + "\n" + body + "".join(f"{t}\n" for t in tail)


def _external_todo(yaml_path: Path, external: dict, bag_lines: list[str],
                   res: InitResult, detections: dict | None = None) -> None:
    """A study.yaml init-study keeps (the user's): the external methods it found and the
    file does not declare, as entries for the user to add (the file is not rewritten)."""
    try:
        doc = yaml.safe_load(yaml_path.read_text(encoding="utf-8")) or {}
    except (OSError, yaml.YAMLError):
        doc = {}
    have = (doc.get("external_methods") or {}) if isinstance(doc, dict) else {}
    for name, entry in external.items():
        if name not in have:
            res.todo.append(f"study.yaml (kept): add under external_methods: {name}: "
                            f"{yaml.safe_dump(entry, default_flow_style=True).strip()}")
    for line in bag_lines:
        res.todo.append(f"study.yaml (kept): a tracker in the sensor bags, to add under "
                        f"external_methods: with its legs filled in: {line.lstrip('# ')}")
    have = (doc.get("external_detections") or {}) if isinstance(doc, dict) else {}
    for name, entry in (detections or {}).items():
        if name not in have:
            res.todo.append(f"study.yaml (kept): add under external_detections: {name}: "
                            f"{yaml.safe_dump(entry, default_flow_style=True).strip()}")


def _bag_detections(trials: list[dict], bag_detectors: dict[str, list[str]],
                    res: InitResult, yaml_path: Path) -> dict:
    """leg_tracker's leg detections (``LegArray``) recorded in the sensor bags: one
    ``external_detections:`` entry per topic whose bags are the trials' sensor bags, named
    by trial id in one folder (the TUG and MTST trials'; nothing for the user to fill in:
    detections have no legs to map), each checked against the schema."""
    from gaitval.configcheck import check_study_file

    out = {}
    by_file = {r["sensor_file"]: r["trial"] for r in trials}
    for topic, bags in sorted(bag_detectors.items()):
        dirs = {str(Path(b).parent) for b in bags}
        if len(dirs) != 1 or not all(Path(b).stem == by_file.get(b) for b in bags):
            continue
        d = dirs.pop()
        protos = sorted({r.get("protocol") for r in trials if r["sensor_file"] in bags}
                        & {"tug", "mtst"})
        if not protos:
            continue
        name = "det_" + (_ID_BAD.sub("_", topic.strip("/")) or "bag")
        entry = {"path": f"{d}/{{trial}}.bag" if d != "." else "{trial}.bag",
                 "topic": topic, "protocols": protos}
        try:
            check_study_file({"external_detections": {name: entry}}, yaml_path)
        except GaitvalError as exc:
            res.todo.append(f"study.yaml external_detections.{name}: {exc}")
            continue
        out[name] = entry
        res.notes.append(f"study.yaml external_detections.{name}: leg detections "
                         f"{topic} of the sensor bags, scored in the detection table")
    return out


def _external_methods(trials: list[dict], files: list[Found], res: InitResult,
                      yaml_path: Path) -> dict:
    """External trackers' files (``<folder>/<trial>.tracks.csv`` or ``.parquet``, and
    foot-tracking systems' ``<folder>/<trial>.foot.csv`` or ``.parquet``): one method per
    folder and suffix whose files are named by trial ids, named after the folder; its
    protocols those of its trials (:data:`EXTERNAL_KINDS`) (docs/formats.md, *External methods*): the
    study.yaml's ``external_methods:``, each entry checked against the schema a
    hand-written one is (:func:`gaitval.configcheck.check_study_file`)."""
    from gaitval.configcheck import check_study_file

    proto = {r["trial"]: r.get("protocol") for r in trials}
    groups: dict[tuple[str, str, str], list[str]] = {}
    for f in files:
        if f.kind not in EXTERNAL_KINDS:
            continue
        parent = str(Path(f.rel).parent)
        suffix = Path(f.rel).name[len(f.stem):]
        groups.setdefault((parent, suffix, f.kind), []).append(f.stem)
    out: dict = {}
    for (parent, suffix, kind), stems in sorted(groups.items()):
        known = [t for t in stems if t in proto]
        if not known:
            what = "external tracks" if kind == "tracks" else "heel trajectories"
            res.unpaired += [f"{parent}/{t}{suffix}: {what} of no trial id" for t in stems]
            continue
        protos = sorted({proto[t] for t in known} & EXTERNAL_KINDS[kind])
        name = _ID_BAD.sub("_", Path(parent).name if parent != "." else "external")
        name = f"ext_{name}" if not name.startswith("ext") else name
        path = (f"{parent}/{{trial}}{suffix}" if parent != "." else f"{{trial}}{suffix}")
        want = sorted(t for t, p in proto.items() if p in protos)
        missing = sorted(set(want) - set(known))
        if not protos:
            continue
        entry = {"path": path, "protocols": protos}
        try:
            check_study_file({"external_methods": {name: entry}}, yaml_path)
        except GaitvalError as exc:
            res.unpaired.append(f"{parent}/*{suffix}: not declared ({exc})")
            continue
        out[name] = entry
        res.notes.append(f"study.yaml external_methods.{name}: {path} "
                         f"({', '.join(protos)} trials)")
        if missing:
            res.todo.append(f"study.yaml external_methods.{name}: no file for trial(s) "
                            f"{', '.join(missing[:5])}{' ...' if len(missing) > 5 else ''} "
                            "(every trial of its protocols needs one; narrow protocols or "
                            "add the files)")
    return out


def _bag_tracker_lines(trials: list[dict], bag_trackers: dict[str, list[str]],
                       res: InitResult) -> list[str]:
    """Commented study.yaml lines (entries of ``external_methods:``) for a tracker topic recorded in the sensor bags: which
    person id is which leg only the user knows, so the entry is left for them to enable."""
    lines = []
    by_file = {r["sensor_file"]: r["trial"] for r in trials}
    for topic, bags in sorted(bag_trackers.items()):
        dirs = {str(Path(b).parent) for b in bags}
        named = all(Path(b).stem == by_file.get(b) for b in bags)
        if len(dirs) != 1 or not named:
            continue
        d = dirs.pop()
        path = f"{d}/{{trial}}.bag" if d != "." else "{trial}.bag"
        protos = sorted({r.get("protocol") for r in trials if r["sensor_file"] in bags}
                        & {"tug", "mtst", "rollator"})
        if not protos:
            continue
        name = "ext_" + (_ID_BAD.sub("_", topic.strip("/")) or "bag")
        lines += [f"#   {name}: {{path: \"{path}\", topic: \"{topic}\", "
                  f"protocols: {protos}, legs: {{L: FILL_IN, R: FILL_IN}}}}"]
        res.todo.append(f"study.yaml: the sensor bags hold tracker topic {topic}; "
                        f"to validate that tracker, give the person id of each leg and "
                        f"uncomment external_methods.{name}")
    return lines


def _config_snippet(study: str, folder: Path) -> str:
    """What only the workflow config holds: where the study's sheet and subject table are,
    and ``run`` (the study's own settings, its external methods included, are in its
    study.yaml)."""
    sheet = (folder / "trials.csv").resolve()
    subjects = (folder / "subjects.csv").resolve()
    doc = {"studies": {study: {"trial_sheet": str(sheet), "subjects": str(subjects)}},
           "run": [study]}
    return ("# Workflow config of this study, written by gaitval init-study: pass it with\n"
            "#   python3 run.py report --configfile " + str((folder /
                                                           "gaitval.config.yaml").resolve())
            + "\n# (or snakemake --configfile ...); config/config.yaml stays as it is.\n"
            "# The study's own settings (external methods, calibration) are in its "
            "study.yaml.\n" + yaml.safe_dump(doc, sort_keys=False))
