"""``gaitval init-study FOLDER``: a trial sheet, a subject table, a ``study.yaml`` and a
workflow config snippet from a folder of recordings (issue 37).

The folder holds what a lab exported: C3D files, laser logs (``*.scan.parquet``, ROS bags),
ultrasonic logs (``*.us.parquet``), rater annotations (``*.annotations.csv``,
``*.positions.csv``), MTST target layouts (``*.targets.csv``) and external trackers' tracks
(``*.tracks.csv``/``*.tracks.parquet``).  :func:`~gaitval.io.initstudy_files.scan_folder`
finds them; :func:`init_study` pairs each sensor file with its C3D — by name (the same
stem) first, then by time (the files' modification times, closest first, within
``max_time_gap_s``) — and reads what the files say about each trial:

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

What the files cannot say and a table needs is written as
:data:`~gaitval.io.initstudy_files.FILL_IN` — the shank width at the sensor's height
(``leg_width_m``), a subject's height for the MTST foot model, whether an MTST participant
walked with a stick, a study calibration such as the rollator's sensor mount — so that
``gaitval validate`` refuses the sheet, naming the row and the column, until the user has
filled it in.  Nothing is guessed silently: every filled value's source and every cell left
to the user are listed in the report (:class:`~gaitval.io.initstudy_files.InitResult`).
"""
from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

from gaitval.errors import GaitvalError
from gaitval.io.atomic import write_text
from gaitval.io.initstudy_files import (FILL_IN, InitResult, as_id, bag_topics, c3d_facts,
                                        pair_recordings, scan_folder, scanlog_height,
                                        trial_from_name, unique_id)
from gaitval.io.initstudy_yaml import (bag_detection_entries, bag_tracker_lines, config_snippet,
                                       external_method_entries, external_todo, study_yaml_text)


TRIAL_COLUMNS = ("study", "protocol", "subject", "trial", "sensor_kind", "mocap_file",
                 "sensor_file", "sensor_topic", "annotation_file", "sensor_height_m",
                 "sensor_x_m", "sensor_y_m", "sensor_yaw_deg", "clock_offset_s", "speed",
                 "speed_mps", "stick", "scenario", "repetition")
SUBJECT_COLUMNS = ("subject", "group", "age_y", "sex", "height_m", "mass_kg", "leg_width_m",
                   "knee_width_m", "ankle_width_m", "leg_length_m", "shank_length_m",
                   "stick")


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


def init_study(folder, *, study: str | None = None, force: bool = False,
               max_time_gap_s: float = 300.0, validate: bool = True) -> InitResult:
    """Write ``trials.csv``, ``subjects.csv``, ``study.yaml`` (when absent) and
    ``gaitval.config.yaml`` into ``folder`` from the recordings in it (module docstring);
    run ``gaitval validate`` on the result.  Existing ``trials.csv``/``subjects.csv`` are
    replaced only with ``force``; an existing ``study.yaml`` is always kept."""
    folder = Path(folder)
    if not folder.is_dir():
        raise GaitvalError(f"init-study: {folder} is not a folder")
    study = study or as_id(folder.resolve().name, "study")
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
    found = _Gathered(folder, study, files)
    trials = _trials(found, max_time_gap_s, res)
    subjects = _subject_rows(trials, found.facts, res)
    _write_study_yaml(found, trials, res)
    write_text(sheet, _csv(trials, TRIAL_COLUMNS))
    write_text(subjects_csv, _csv(subjects, SUBJECT_COLUMNS))
    res.written += [sheet, subjects_csv]
    snippet = folder / "gaitval.config.yaml"
    write_text(snippet, config_snippet(study, folder))
    res.written.append(snippet)
    res.notes.append(f"{len(trials)} trials, {len(subjects)} subjects; run with "
                     f"`python3 run.py report --configfile {snippet}`")
    if validate:
        from gaitval.io.trialsheet import sheet_problems
        _, problems = sheet_problems(sheet, subjects_csv)
        res.problems = [str(p) for p in problems]
    return res


@dataclass
class _Gathered:
    """What :func:`init_study` gathers from the folder's files, trial by trial."""

    folder: Path
    study: str
    files: list
    facts: dict[str, dict] = field(default_factory=dict)          # C3D -> its facts
    bag_trackers: dict[str, list[str]] = field(default_factory=dict)   # tracker topic ->
    bag_detectors: dict[str, list[str]] = field(default_factory=dict)  # bags with it
    ids: set[str] = field(default_factory=set)
    id_source: dict[str, list[str]] = field(default_factory=dict)  # where subject ids came from


def _trials(found: _Gathered, max_time_gap_s: float, res: InitResult) -> list[dict]:
    """One trial-sheet row per sensor file, paired with its C3D (by name, then by time),
    sorted by trial id."""
    files = found.files
    c3ds = [f for f in files if f.kind == "c3d"]
    sensors = [f for f in files if f.kind in ("scanlog", "bag", "ultrasonic")]
    by_kind_stem = {(f.kind, f.stem): f for f in files}
    pairs, notes = pair_recordings(sensors, c3ds, max_time_gap_s)
    res.notes += notes
    paired_c3d = {c.rel for c in pairs.values()}
    res.unpaired += [f"{c.rel}: a C3D without a sensor file of the same name or time"
                     for c in c3ds if c.rel not in paired_c3d]
    trials = [_trial_row(found, s, pairs.get(s.rel), by_kind_stem, res) for s in sensors]
    for src, stems in found.id_source.items():
        res.notes.append(f"subject ids from {src}: {len(stems)} trial"
                         f"{'s' * (len(stems) != 1)} ({', '.join(stems[:3])}"
                         f"{', ...' if len(stems) > 3 else ''})")
    _number_repetitions(trials)
    trials.sort(key=lambda r: (r["trial"]))
    return trials


def _trial_row(found: _Gathered, s, c3d, by_kind_stem: dict, res: InitResult) -> dict:
    """The trial-sheet row of sensor file ``s`` and its C3D (None without one)."""
    folder, id_source = found.folder, found.id_source
    f = {"labels": []}
    if c3d:
        try:
            f = c3d_facts(folder / c3d.rel)
        except GaitvalError as exc:               # a file gaitval cannot read: said
            res.unpaired.append(f"{c3d.rel}: {exc}")
    if c3d:
        found.facts[c3d.rel] = f
    info = trial_from_name(s.stem, s.kind, f["labels"])
    if info.get("subject"):
        id_source.setdefault("the file name", []).append(s.stem)
    elif f.get("subject") and info.get("protocol") != "pendulum":
        info["subject"] = f["subject"]           # the name has no subject word
        id_source.setdefault("the C3D's SUBJECTS:NAMES", []).append(s.stem)
    trial = unique_id([as_id(s.stem, "trial"),
                       as_id(s.rel.rsplit(".", 2)[0].replace("/", "_"), "trial")], found.ids)
    row = {"study": found.study, "trial": trial, "sensor_file": s.rel,
           "sensor_kind": "ultrasonic" if s.kind == "ultrasonic" else "lrs",
           "mocap_file": c3d.rel if c3d else "", **info}
    ann = by_kind_stem.get(("annotations", s.stem)) or by_kind_stem.get(("positions",
                                                                          s.stem))
    if ann:
        row["annotation_file"] = ann.rel
    if s.kind == "bag":
        _bag_columns(found, s, row, res)
    if row["sensor_kind"] == "lrs":
        _laser_columns(folder, s, c3d, f["labels"], row, res)
    if not c3d and not ann:
        res.unpaired.append(f"{s.rel}: no C3D and no annotations (a trial needs one of "
                            "them)")
    _words_to_fill_in(row, res)
    return row


def _bag_columns(found: _Gathered, s, row: dict, res: InitResult) -> None:
    """A bag's LaserScan topic into ``row``; the tracker and leg-detection topics it
    records, gathered for the study.yaml."""
    trial = row["trial"]
    try:
        topic, trackers, detectors = bag_topics(found.folder / s.rel)
    except GaitvalError as exc:
        res.unpaired.append(f"{s.rel}: {exc}")
        topic, trackers, detectors = None, [], []
    for tt in trackers:
        found.bag_trackers.setdefault(tt, []).append(s.rel)
    for tt in detectors:
        found.bag_detectors.setdefault(tt, []).append(s.rel)
    row["sensor_topic"] = topic or FILL_IN
    if topic is None:
        res.todo.append(f"trials.csv {trial}: sensor_topic (the bag has none or "
                        "several LaserScan topics; `gaitval inspect` lists them)")


def _laser_columns(folder: Path, s, c3d, labels: list[str], row: dict,
                   res: InitResult) -> None:
    """A laser trial's sensor height, and its manual pose to fill in when the C3D has no
    calibration poles."""
    trial = row["trial"]
    h = scanlog_height(folder / s.rel) if s.kind == "scanlog" else None
    if h is not None:
        row["sensor_height_m"] = h
    else:
        row["sensor_height_m"] = FILL_IN
        res.todo.append(f"trials.csv {trial}: sensor_height_m (the log does not "
                        "give the scan plane's height)")
    poles = [lab for lab in labels if re.fullmatch(r"POLE\d+", lab)]
    if c3d and len(poles) < 2 and row.get("protocol") != "rollator":
        for col in ("sensor_x_m", "sensor_y_m", "sensor_yaw_deg"):
            row[col] = FILL_IN
        res.todo.append(f"trials.csv {trial}: sensor_x_m, sensor_y_m, sensor_yaw_deg"
                        " (the C3D has no POLE1/POLE2 markers: measure the sensor's "
                        "pose in the mocap frame)")


def _words_to_fill_in(row: dict, res: InitResult) -> None:
    """The protocol, subject (and an MTST trial's stick) the names did not give."""
    trial = row["trial"]
    for col in ("protocol", "subject"):
        if not row.get(col):
            row[col] = FILL_IN
            res.todo.append(f"trials.csv {trial}: {col} (not in the file name"
                            f"{' or the C3D' if col == 'subject' else ''})")
    if row.get("protocol") == "mtst" and "stick" not in row:
        row["stick"] = FILL_IN
        res.todo.append(f"trials.csv {trial}: stick (true/false; MTST Tables 1, 3 and 4 "
                        "group by it)")


def _write_study_yaml(found: _Gathered, trials: list[dict], res: InitResult) -> None:
    """The study.yaml with the external methods and detectors found, or, beside an
    existing one (kept), the entries to add as things to do."""
    files, yaml_path = found.files, found.folder / "study.yaml"
    external = external_method_entries(trials, files, res, yaml_path)
    bag_lines = bag_tracker_lines(trials, found.bag_trackers, res)
    detections = bag_detection_entries(trials, found.bag_detectors, res, yaml_path)
    if yaml_path.exists():
        res.kept.append(yaml_path)
        # not written there: the entries to add are in the todo list instead
        res.notes = [n for n in res.notes if not n.startswith(
            ("study.yaml external_methods.", "study.yaml external_detections."))]
        external_todo(yaml_path, external, bag_lines, res, detections)
    else:
        write_text(yaml_path, study_yaml_text(trials, files, res, external, bag_lines,
                                              detections))
        res.written.append(yaml_path)


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
