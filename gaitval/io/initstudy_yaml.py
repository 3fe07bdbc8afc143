"""The ``study.yaml`` ``gaitval init-study`` writes (:mod:`gaitval.io.initstudy`): the study
calibration to fill in, the external trackers' track files and the trackers and leg
detectors recorded in the sensor bags as ``external_methods:`` / ``external_detections:``
entries (or, beside an existing study.yaml, the same as lines to add), and the workflow
config snippet.
"""
from __future__ import annotations

from pathlib import Path

import yaml

from gaitval.errors import GaitvalError
from gaitval.io.initstudy_files import _ID_BAD, FILL_IN, Found, InitResult


#: the protocols an external file of each kind can cover (leg tracks: a fixed or moving
#: laser; heel trajectories: the treadmill, docs/formats_external.md "Foot trajectories")
EXTERNAL_KINDS = {"tracks": {"tug", "mtst", "rollator"}, "foot": {"treadmill"}}


def study_yaml_text(trials: list[dict], files: list[Found], res: InitResult,
                external: dict | None = None, bag_lines: list[str] = (),
                detections: dict | None = None) -> str:
    """study.yaml: the MTST target layouts when every MTST trial has one in one folder;
    the rollator's sensor mount as a key to fill in; the external trackers' track files as
    ``external_methods:`` (:func:`external_method_entries`), a tracker recorded in the sensor
    bags as commented entries (:func:`bag_tracker_lines`)."""
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
        tail += ["# A tracker recorded in the sensor bags (docs/formats_external.md, 'External "
                 "methods'):", "# to validate it, fill in each leg's person id and "
                 "uncomment its entry"]
        tail += ["# external_methods:"] * (not external) + list(bag_lines)
    tracks = sorted({f.rel for f in files if f.kind == "tracks"})
    if tracks and not external:
        tail += ["# External trackers' tracks were found, not named by trial ids "
                 "(docs/formats_external.md, 'External methods'); declare each as a method, e.g.",
                 "# external_methods:",
                 f"#   my_tracker: {{path: \"{tracks[0]}\"}}   # {{trial}} for the trial id"]
    return "\n".join(lines) + "\n" + body + "".join(f"{t}\n" for t in tail)


def external_todo(yaml_path: Path, external: dict, bag_lines: list[str],
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


def bag_detection_entries(trials: list[dict], bag_detectors: dict[str, list[str]],
                    res: InitResult, yaml_path: Path) -> dict:
    """leg_tracker's leg detections (``LegArray``) recorded in the sensor bags: one
    ``external_detections:`` entry per topic whose bags are the trials' sensor bags, named
    by trial id in one folder (the TUG and MTST trials'; nothing for the user to fill in:
    detections have no legs to map), each checked against the schema."""
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
        problem = _add_checked(out, "external_detections", name, entry, yaml_path)
        if problem:
            res.todo.append(f"study.yaml external_detections.{name}: {problem}")
        else:
            res.notes.append(f"study.yaml external_detections.{name}: leg detections "
                             f"{topic} of the sensor bags, scored in the detection table")
    return out


def _add_checked(out: dict, section: str, name: str, entry: dict,
                 yaml_path: Path) -> str | None:
    """``out[name] = entry`` when study.yaml's ``section: {name: entry}`` passes the schema
    a hand-written entry is checked against (:func:`gaitval.configcheck.check_study_file`);
    otherwise what is wrong with it (``out`` unchanged)."""
    from gaitval.configcheck import check_study_file

    try:
        check_study_file({section: {name: entry}}, yaml_path)
    except GaitvalError as exc:
        return str(exc)
    out[name] = entry
    return None


def external_method_entries(trials: list[dict], files: list[Found], res: InitResult,
                      yaml_path: Path) -> dict:
    """External trackers' files (``<folder>/<trial>.tracks.csv`` or ``.parquet``, and
    foot-tracking systems' ``<folder>/<trial>.foot.csv`` or ``.parquet``): one method per
    folder and suffix whose files are named by trial ids, named after the folder; its
    protocols those of its trials (:data:`EXTERNAL_KINDS`) (docs/formats_external.md, *External methods*): the
    study.yaml's ``external_methods:``, each entry checked against the schema a
    hand-written one is (:func:`gaitval.configcheck.check_study_file`)."""
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
        problem = _add_checked(out, "external_methods", name, entry, yaml_path)
        if problem:
            res.unpaired.append(f"{parent}/*{suffix}: not declared ({problem})")
            continue
        res.notes.append(f"study.yaml external_methods.{name}: {path} "
                         f"({', '.join(protos)} trials)")
        if missing:
            res.todo.append(f"study.yaml external_methods.{name}: no file for trial(s) "
                            f"{', '.join(missing[:5])}{' ...' if len(missing) > 5 else ''} "
                            "(every trial of its protocols needs one; narrow protocols or "
                            "add the files)")
    return out


def bag_tracker_lines(trials: list[dict], bag_trackers: dict[str, list[str]],
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


def config_snippet(study: str, folder: Path) -> str:
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
