"""External trackers and leg detectors a study declares (``tracking.external`` of the workflow
config, ``external_methods:`` / ``external_detections:`` of the study.yaml or
:data:`STUDY_SIDE_FILE` beside its trial sheet): where each trial's file is, and the
checks the run makes before any job (docs/formats_external.md, "Leg tracks").
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd
import yaml

from gaitval.errors import ConfigError


def external_track_path(sheet, entry: dict, trial: str, method: str = "",
                        field: str | None = None) -> Path:
    """The external track file of one trial: ``entry["path"]`` relative to the trial
    sheet's folder, ``{trial}`` replaced by the trial id.  Like the sheet's own paths it
    must stay inside that folder unless the study.yaml beside the sheet sets
    ``allow_outside_paths: true``.  ``field`` names the entry in the error (default
    ``tracking.external.<method>.path``)."""
    from gaitval.io.trialsheet import _allows_outside

    base = Path(sheet).parent
    path = base / str(entry["path"]).replace("{trial}", trial)
    if not path.resolve().is_relative_to(base.resolve()) and not _allows_outside(Path(sheet)):
        raise ConfigError(f"{field or f'tracking.external.{method}.path'}: {str(path)!r} "
                          f"(trial {trial}) leads outside the trial sheet's folder {base}",
                          hint="put the files beside the sheet, or set "
                               "allow_outside_paths: true in the study.yaml beside it")
    return path


EXTERNAL_PROTOCOLS = ("tug", "mtst")
#: the protocols an external detector's entry covers by default (a fixed laser; the
#: ground truth of these families is in the laser's frame on its clock)
DETECTION_PROTOCOLS = ("tug", "mtst")
#: a study's own declarations beside its trial sheet: study.yaml (written by the
#: simulator for a simulated study) and this side file, which gaitval never writes
#: (a simulated study's external methods and detectors, declared before its first run)
STUDY_SIDE_FILE = "external.yaml"
#: the keys a study declares external trackers and detectors under
DECLARATION_KEYS = ("external_methods", "external_detections")


#: the protocol whose external files are heel trajectories (*.foot.csv, gaitval.io.foot),
#: not leg tracks: an entry covering it covers no other protocol
FOOT_PROTOCOL = "treadmill"


def foot_entry_problem(method: str, entry: dict, where: str = "external_methods") -> None:
    """An external method whose ``protocols`` name the treadmill and another protocol:
    one file template cannot be heel trajectories there and leg tracks elsewhere
    (ConfigError naming the key)."""
    prots = list((entry or {}).get("protocols") or EXTERNAL_PROTOCOLS)
    if FOOT_PROTOCOL in prots and len(prots) > 1:
        raise ConfigError(f"{where}.{method}.protocols: {prots}: a treadmill method's files "
                          "are heel trajectories (*.foot.csv), the other protocols' are leg "
                          "tracks; declare two methods",
                          hint="e.g. my_feet: {path: ..., protocols: [treadmill]} beside "
                               "my_legs: {path: ..., protocols: [tug, mtst]}")


def is_foot_entry(entry: dict) -> bool:
    """The entry covers the treadmill trials (heel trajectories, :mod:`gaitval.io.foot`)."""
    return FOOT_PROTOCOL in ((entry or {}).get("protocols") or ())


def declared_entries(sheet, key: str) -> dict:
    """``key`` (:data:`DECLARATION_KEYS`) of the ``study.yaml`` and the
    :data:`STUDY_SIDE_FILE` beside a trial sheet: name -> (entry, the file declaring it).
    A name declared in both files is an error naming both."""
    from gaitval.configcheck import display_path

    out: dict = {}
    for f in (Path(sheet).parent / "study.yaml", Path(sheet).parent / STUDY_SIDE_FILE):
        if not f.is_file():
            continue
        with open(f, encoding="utf-8") as fh:
            doc = yaml.safe_load(fh) or {}
        entries = (doc.get(key) or {}) if isinstance(doc, dict) else {}
        for m, e in (entries.items() if isinstance(entries, dict) else ()):
            if m in out:
                raise ConfigError(f"[file {display_path(f)}] {key}.{m}: {m!r} is also "
                                  f"declared in {display_path(out[m][1])}; declare it in "
                                  "one place")
            out[m] = (e, f)
    return out


def study_external(sheet, key: str = "external_methods") -> dict:
    """``external_methods:`` (or another of :data:`DECLARATION_KEYS`) of the study's
    ``study.yaml`` and its :data:`STUDY_SIDE_FILE` beside a trial sheet: the study's own
    entries, name -> entry as in ``tracking.external`` ({} without)."""
    return {m: e for m, (e, _) in declared_entries(sheet, key).items()}


def study_side_problems(sheet, schema: dict | None = None) -> None:
    """The :data:`STUDY_SIDE_FILE` beside a trial sheet, when there, against the config
    schema's ``$defs/external_file`` (only :data:`DECLARATION_KEYS`), raising one
    ConfigError naming the file and key."""
    from gaitval.configcheck import check_study_file

    f = Path(sheet).parent / STUDY_SIDE_FILE
    if f.is_file():
        with open(f, encoding="utf-8") as fh:
            doc = yaml.safe_load(fh)
        check_study_file({} if doc is None else doc, f, schema=schema,
                         definition="external_file")


def external_declarations(config_external: dict | None, sheets: dict, taken,
                          key: str = "external_methods",
                          protocols: tuple = EXTERNAL_PROTOCOLS) -> dict:
    """Each study's external methods: ``tracking.external`` of the workflow config (every
    study of ``run``) and ``external_methods:`` of the study's own ``study.yaml`` or
    :data:`STUDY_SIDE_FILE`; with ``key="external_detections"`` (and no config entries)
    its external leg detectors alike.

    ``sheets``: study -> its trial sheet's path (the study.yaml beside it need not exist
    yet: a simulated study before its simulation); ``taken``: the names of gaitval's own
    methods (and, for detectors, of the external methods).  Returns
    ``{study: {method: entry}}``.

    Raises
    ------
    ConfigError
        Naming the file and key: a name that is already a method or also declared in
        the workflow config; a name declared by some studies of ``run`` and not by
        another, or with other ``protocols`` there (the tables pool the studies of
        ``run``, one row per method, so every study needs the method's files).
    """
    from gaitval.configcheck import display_path

    config_external = dict(config_external or {})
    decl = {s: declared_entries(sheet, key) for s, sheet in sheets.items()}
    own = {s: {m: e for m, (e, _) in d.items()} for s, d in decl.items()}
    cal = {s: display_path(Path(sheets[s]).parent / "study.yaml") for s in sheets}

    def where(s, m):
        return display_path(decl[s][m][1]) if m in decl[s] else cal[s]

    if key == "external_methods":
        for m, e in config_external.items():
            foot_entry_problem(m, e, "tracking.external")
        for s, entries in own.items():
            for m, e in entries.items():
                foot_entry_problem(m, e, f"[file {where(s, m)}] {key}")
    _check_names_taken(own, taken, config_external, key, where)
    _check_every_study_declares(own, sheets, key, protocols, where, cal)
    return {s: {**config_external, **own[s]} for s in sheets}


def _check_names_taken(own: dict, taken, config_external: dict, key: str, where) -> None:
    """A study's declared name is neither one of ``taken`` nor also in the workflow
    config's ``tracking.external`` (:func:`external_declarations`)."""
    for s, entries in own.items():
        for m in entries:
            if m in taken:
                what = ("a tracking method; give the external tracker" if
                        key == "external_methods" else
                        "a method name; give the external detector")
                raise ConfigError(f"[file {where(s, m)}] {key}.{m}: {m!r} is already "
                                  f"{what} another name")
            if m in config_external:
                raise ConfigError(f"[file {where(s, m)}] {key}.{m}: {m!r} is also "
                                  "declared in the workflow config (tracking.external); "
                                  "declare it in one place")


def _check_every_study_declares(own: dict, sheets: dict, key: str, protocols: tuple, where,
                                cal: dict) -> None:
    """Every study of ``run`` declares each name, covering the same protocols
    (:func:`external_declarations`)."""
    names = sorted({m for entries in own.values() for m in entries})
    for m in names:
        have = [s for s in sheets if m in own[s]]
        lack = [s for s in sheets if m not in own[s]]
        if lack:
            raise ConfigError(
                f"[file {where(have[0], m)}] {key}.{m}: study {lack[0]!r} of run "
                f"{list(sheets)} does not declare it (its study.yaml: {cal[lack[0]]})",
                hint="the tables pool the studies of run, one row per method: declare it "
                     f"in every study's study.yaml or {STUDY_SIDE_FILE}, or run the study "
                     "alone")
        prot = {s: sorted(own[s][m].get("protocols") or protocols) for s in have}
        if len({tuple(v) for v in prot.values()}) > 1:
            raise ConfigError(f"[file {where(have[1], m)}] {key}.{m}.protocols: "
                              f"{prot[have[1]]} here, {prot[have[0]]} in "
                              f"{where(have[0], m)}; one method covers the same protocols "
                              "in every study of run")


def entry_trials(df: pd.DataFrame, prots, mocap_only: bool) -> list[str]:
    """The trials of a sheet (``trial, protocol[, mocap_path]`` as text) of ``prots``;
    with ``mocap_only`` those with a mocap file (a detector is scored against it)."""
    keep = df["protocol"].str.strip().isin(prots)
    if mocap_only and "mocap_path" in df:
        keep &= df["mocap_path"].str.strip() != ""
    return sorted(df.loc[keep, "trial"].str.strip())


def sheet_trials(sheet) -> pd.DataFrame | None:
    try:
        return pd.read_csv(sheet, usecols=lambda c: c in ("trial", "protocol", "mocap_path"),
                           dtype=str, keep_default_na=False)
    except (OSError, ValueError):
        return None


def missing_external_files(sheet, entries: dict, source: str = "", *,
                           protocols: tuple = EXTERNAL_PROTOCOLS,
                           what: str = "track files", key: str | None = None,
                           mocap_only: bool = False) -> None:
    """Check, before any job runs, that every trial of each external method's protocols
    has its file, inside the sheet's folder (:func:`external_track_path`).  A sheet that
    cannot be read yet (a simulated study before its simulation; a broken sheet, which its
    own check reports) is skipped.  ``protocols``: an entry's default; ``what``: the files'
    name in the message; ``key``: the declaration key, named when a path leads outside;
    ``mocap_only``: only the trials with a mocap file (an external detector's).

    Raises
    ------
    ConfigError
        One message per method naming where it is declared, how many files are missing
        and the first few of them."""
    df = sheet_trials(sheet)
    if df is None or not {"trial", "protocol"} <= set(df.columns):
        return
    for m, entry in entries.items():
        prots = (entry or {}).get("protocols") or protocols
        trials = entry_trials(df, prots, mocap_only)
        paths = [external_track_path(sheet, entry, t, m,
                                     field=f"{key}.{m}.path" if key else None)
                 for t in trials]
        missing = [p for p in paths if not p.exists()]
        if missing:
            shown = ", ".join(str(p) for p in missing[:3])
            raise ConfigError(
                f"{source or 'external method'} {m}: {len(missing)} of {len(paths)} "
                f"trials' {what} are missing ({shown}"
                f"{', ...' if len(missing) > 3 else ''})",
                hint=f"path {entry['path']!r} is relative to the trial sheet's folder "
                     f"{Path(sheet).parent}; every trial of {', '.join(prots)} needs its "
                     "file")


def detection_topic_problems(sheet, entries: dict, source: str = "") -> None:
    """Each external detector's bags (the trials with mocap of its protocols) opened
    before any job
    runs: its ``topic`` (or, without one, exactly one ``leg_tracker/LegArray`` topic) must
    be in every bag and be a ``LegArray``.  Files that are no bag are read by the job
    (their header and rows; ``gaitval validate --deep`` reads them first).  Skipped, like
    :func:`missing_external_files`, while the sheet cannot be read.

    Raises
    ------
    ConfigError
        Naming where the detector is declared, the bag, and the topics it has."""
    from gaitval.io.rosbag import _norm, is_rosbag
    from gaitval.io.tracks.bag import BAG_LEG_DETECTIONS

    df = sheet_trials(sheet)
    if df is None or not {"trial", "protocol"} <= set(df.columns):
        return
    for m, entry in entries.items():
        prots = (entry or {}).get("protocols") or DETECTION_PROTOCOLS
        topic = (entry or {}).get("topic")
        for t in entry_trials(df, prots, mocap_only=True):
            path = external_track_path(sheet, entry, t, m,
                                       field=f"external_detections.{m}.path")
            if not is_rosbag(path):
                continue
            from rosbags.highlevel import AnyReader
            try:
                with AnyReader([path]) as r:
                    have = {c.topic: c.msgtype for c in r.connections}
            except Exception as exc:          # noqa: BLE001 - any unreadable bag
                raise ConfigError(f"{source} {m}: trial {t}: {path} is not a readable ROS "
                                  f"bag ({type(exc).__name__}: {exc})") from None
            if topic:
                got = {k: v for k, v in have.items() if _norm(k) == _norm(str(topic))}
                if not got:
                    raise ConfigError(f"{source} {m}.topic: {topic!r} is not in {path} "
                                      f"(trial {t}); its topics: {sorted(have)}")
                bad = [v for v in got.values() if v != BAG_LEG_DETECTIONS]
                if bad:
                    raise ConfigError(f"{source} {m}.topic: {topic!r} in {path} (trial "
                                      f"{t}) holds {bad[0]}, not {BAG_LEG_DETECTIONS}")
            elif sum(v == BAG_LEG_DETECTIONS for v in have.values()) != 1:
                raise ConfigError(f"{source} {m}: {path} (trial {t}) has "
                                  f"{sum(v == BAG_LEG_DETECTIONS for v in have.values())} "
                                  f"topics of type {BAG_LEG_DETECTIONS}; its topics: "
                                  f"{sorted(have)}", hint="name the topic (topic: ...)")
