"""What ``gaitval validate`` reports of a study's own files beside its trial sheet: the
study.yaml against the config schema, and the external methods' and detectors' entries and
files.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from gaitval.errors import FileFormatError, GaitvalError
from gaitval.pipeline.steps.declarations import (DETECTION_PROTOCOLS, EXTERNAL_PROTOCOLS,
                                                 declared_entries, detection_topic_problems,
                                                 entry_trials, external_track_path,
                                                 foot_entry_problem, is_foot_entry,
                                                 missing_external_files, sheet_trials,
                                                 study_side_problems)
from gaitval.pipeline.steps.external import read_external, read_external_detections


def study_yaml_problems(sheet) -> list:
    """The ``study.yaml`` beside a trial sheet against the config schema, as the run checks
    it at start (``_check_study_files`` in workflow/rules/common.smk): a typo is one problem
    naming the file, the key and the nearest valid one."""
    from gaitval.configcheck import check_study_file

    f = Path(sheet).parent / "study.yaml"
    if not f.is_file():
        return []
    try:
        with open(f, encoding="utf-8") as fh:
            doc = yaml.safe_load(fh)
        check_study_file({} if doc is None else doc, f)
    except GaitvalError as exc:
        return [exc]
    except (OSError, yaml.YAMLError) as exc:
        return [f"[file {f}] cannot be read: {exc}"]
    return []


#: Leg positions whose median lies farther than this from the origin of their frame (the
#: laser or the mocap origin, metres) are no gait laboratory's: millimetres declared as metres.
MAX_TRACK_DISTANCE_M = 100.0


def _units_problem(rows: pd.DataFrame, meta: dict, path, trial: str) -> None:
    """A track file whose positions cannot be in the units its header declares (checked
    without the trial's registration, so against any room's size; the run checks them
    against the laser's range once registered)."""
    x = rows["x_m" if "x_m" in rows else "x"].to_numpy(float)
    y = rows["y_m" if "y_m" in rows else "y"].to_numpy(float)
    d = np.hypot(x, y)
    d = d[np.isfinite(d)]
    if d.size and np.median(d) > MAX_TRACK_DISTANCE_M:
        raise FileFormatError(
            f"the leg positions lie a median {np.median(d):,.0f} m from the origin of their "
            f"frame ({meta.get('frame', 'sensor')!r}), beyond any room (header units "
            f"{meta.get('units', 'm')!r})", path=path, trial=trial,
            hint="positions in millimetres need 'units: mm' in the header")


def external_problems(sheet, deep: bool = False) -> list[str]:
    """What ``gaitval validate`` reports of the study's own external methods and leg
    detectors (``external_methods:``, ``external_detections:`` of the study.yaml or
    :data:`.STUDY_SIDE_FILE` beside ``sheet``): the entries against the schema, each
    trial's file present and inside the folder (a detector's bags: its topic), and with
    ``deep`` every file read (:func:`.read_external`, :func:`.read_external_detections`:
    header, columns, rows, a bag's topic and legs; the clock and frame conversion needs the
    registration and is checked when the run imports it).  One text per problem."""
    from gaitval.configcheck import check_study_file

    out = []
    for key, check, default in (("external_methods", "external_method", EXTERNAL_PROTOCOLS),
                                ("external_detections", "external_detection",
                                 DETECTION_PROTOCOLS)):
        try:
            decl = declared_entries(sheet, key)
            if not decl:
                continue
            study_side_problems(sheet)
            for m, (entry, f) in decl.items():
                check_study_file({key: {m: entry}}, f)
                if key == "external_methods":
                    foot_entry_problem(m, entry, f"[file {f}] {key}")
        except GaitvalError as exc:
            out.append(str(exc))
            continue
        except (OSError, yaml.YAMLError) as exc:
            out.append(f"[file {Path(sheet).parent}] {key} cannot be read: {exc}")
            continue
        for m, (entry, f) in decl.items():
            try:
                missing_external_files(sheet, {m: entry}, f"[file {f}] {key}",
                                       protocols=default, key=key,
                                       what=("detection files" if key != "external_methods"
                                             else "heel trajectories" if is_foot_entry(entry)
                                             else "track files"),
                                       mocap_only=key == "external_detections")
                if key == "external_detections":
                    detection_topic_problems(sheet, {m: entry}, f"[file {f}] {key}")
            except GaitvalError as exc:
                out.append(str(exc))
                continue
            if not deep:
                continue
            df = sheet_trials(sheet)
            prots = entry.get("protocols") or default
            for t in entry_trials(df, prots, key == "external_detections"):
                try:
                    path = external_track_path(sheet, entry, t, m)
                    if key == "external_methods" and is_foot_entry(entry):
                        from gaitval.io.foot import read_foot
                        read_foot(path, trial=t)
                    elif key == "external_methods":
                        rows, meta = read_external(path, entry, t)
                        _units_problem(rows, meta, path, t)
                    else:
                        read_external_detections(path, entry.get("topic"), t)
                except GaitvalError as exc:
                    out.append(f"{key}.{m}: {exc}")
    return out
