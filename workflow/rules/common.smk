# Shared by all rule files -- config validation, paths, the trial sheet, provenance.
import re
import json
import sys
from pathlib import Path

import yaml
from snakemake.utils import update_config

from gaitval.configcheck import (check_config, check_study_file, display_path,
                                 load_schema, raise_problems, retype_command_line,
                                 run_problems, with_sources)
from gaitval.errors import ConfigError, GaitvalError
from gaitval.io.trialsheet import load_trial_sheet
from gaitval.report.provenance import config_hash, source_digest
from gaitval.methods import METHODS, get_method, set_params
from gaitval.overrides import override_problems
from gaitval.pipeline.steps.config import (ALL_SCOPE, ANALYSIS_SECTIONS, PROTOCOL_SCOPE, SCOPES,
                                           STUDY_VIEW, method_definition, method_view)
from gaitval.pipeline.steps.declarations import EXTERNAL_PROTOCOLS
from gaitval.tables.tug_evidence import method_reading


include: "config_common.smk"

RESULTS = config.get("results_dir", "results")
PRESETS = Path(workflow.basedir) / "config" / "studies"
# One report folder per set of pooled studies: reports/<run-name>/ with run-name = the
# `run` list joined by "+" (reports/tiny, reports/default, reports/tiny+replay), so a
# table that pools the studies of `run` (tug_table4, ...) never overwrites another run's,
# and changing `run` asks for files that do not exist yet -- Snakemake rebuilds them.
RUN_NAME = "+".join(config["run"])
REPORTS_ROOT = config.get("reports_dir", "reports")
REPORTS = f"{REPORTS_ROOT}/{RUN_NAME}"
# HOW JOBS RUN (docs/architecture.md, "How a job runs").  One Snakemake job per (study,
# stage) or (study, stage, method), not per trial: its `shell:` command is one gaitval verb
# (`gaitval track-trials ...`, gaitval.jobs.stages) that runs each trial's per-trial verbs
# in a process pool of the rule's `threads` and writes each trial's own files below the
# job's `directory()` outputs; its log lists every trial's command and messages.  A job's
# `python` is the one running Snakemake (its folder first on PATH: a venv need not be
# activated); with --software-deployment-method conda, the rule's environment's own
# (activated before the command).
import os as _os

from snakemake import __version__ as _SNAKEMAKE_VERSION

_os.environ.update(PATH=_os.pathsep.join([str(Path(sys.executable).parent),
                                          _os.environ.get("PATH", "")]))
# Every rule's software environment: the locked dependencies and gaitval itself.  Snakemake
# 8 asks conda for a job's environment when it reports a failed job (`conda info`, even
# without --software-deployment-method conda; jobs.Job.get_log_error_info), which fails
# where conda is absent, so under Snakemake 8 the rules declare none; Snakemake 9 asks only
# with that option.
CONDA_ENV = "../envs/gaitval.yaml" if int(_SNAKEMAKE_VERSION.split(".")[0]) >= 9 else None


def batch_threads():
    """The threads of a batch rule: every core Snakemake has (--cores; a cluster job: its
    cpus_per_task, set per rule by the profile)."""
    try:
        return max(1, int(workflow.cores))
    except Exception:                  # cores not set (a dry run, --list): Snakemake's default
        return 1


BATCH_THREADS = batch_threads()
# What a killed run left unfinished (outputs Snakemake still marks incomplete) is removed
# before Snakemake plans this run, so the jobs that make it run again: Snakemake 9 itself
# overlooks the marks of jobs it adds after a checkpoint (gaitval/jobs/resume.py).  Only in
# the main Snakemake (not a cluster job's), not on a dry run, and only when no Snakemake
# holds a lock here.
if workflow.is_main_process and not {"-n", "--dry-run", "--dryrun"} & set(sys.argv):
    from gaitval.jobs.resume import clear_interrupted

    _removed = clear_interrupted(".")
    if _removed:
        print(f"gaitval: removed {len(_removed)} output(s) an interrupted run left "
              f"unfinished; their jobs run again: {', '.join(_removed[:6])}"
              + (", ..." if len(_removed) > 6 else ""), file=sys.stderr)
# The jobs' processes end with this Snakemake (gaitval/jobs/lifeline.py): a job's `gaitval`
# verb and its pool's workers watch this pid.
_os.environ.update(GAITVAL_RUN_PID=str(_os.getpid()))


def first_or_empty(name):
    """Param function: input `name`'s first path, or "" when the job has none (an
    optional folder, e.g. the shared detections)."""

    def first(wildcards, input):
        paths = getattr(input, name, None) or []
        paths = [paths] if isinstance(paths, str) else list(paths)
        return paths[0] if paths else ""

    return first


def size_of(path):
    from gaitval.jobs.batch import file_size

    return file_size(path)


wildcard_constraints:
    study=r"[^/]+",
    method=r"[^/]+",
    trial=r"[^/]+",


# Hash of the analysis sections only: changing `run` or paths must not rerun the tables.
CONFIG_HASH = config_hash({k: config[k] for k in ANALYSIS_SECTIONS if k in config})
# gaitval's own files (code and data): part of every view's params below, so that new code
# reruns what it could change (Snakemake's `code` trigger sees a rule's own code only)
SOURCE_DIGEST = source_digest()



def analysis_sections_json(view=None, scope=ALL_SCOPE):
    """The analysis sections as canonical JSON (sorted keys), or one view of them
    (gaitval.pipeline.steps.config.method_view): the params of rules study_config and
    config_view, with gaitval's source digest (SOURCE_DIGEST: new code reruns the views,
    hence every job that reads one; study_config ignores the key)."""
    sections = {k: config[k] for k in ANALYSIS_SECTIONS if k in config}
    if view is not None:
        sections = method_view(sections, view, scope)
        # an external method's entries of each study (study.yaml's external_methods:, read
        # by the job from the study.yaml): here too, so that changing one (a topic, the
        # legs) reruns its view and jobs (a params change); study_config ignores the key
        in_config = view in ((config.get("tracking") or {}).get("external") or {})
        by_study = {s: e[view] for s, e in _EXTERNAL.items() if view in e}
        if by_study and not in_config:
            sections["external_methods_of_studies"] = by_study
    sections["gaitval_source"] = SOURCE_DIGEST
    return json.dumps(sections, sort_keys=True, default=str)


def study_configs(wildcards):
    """Input function: results/<study>/config.json of every study in `run` (the whole
    analysis config, for a step run by hand; the jobs read their views: config_view_file,
    study_views)."""
    return [f"{RESULTS}/{study}/config.json" for study in config["run"]]


def config_hash_when_run(wildcards, input):
    """Param function: CONFIG_HASH, the provenance stamp of a pooled table.  A param that
    takes `input` is evaluated when the job runs and is not one of Snakemake's params rerun
    triggers, so a table reruns when its inputs (evaluations, config views) change, not on
    every change of the configuration; the hash it stamps is the configuration's when the
    table was last built (docs/report.md)."""
    return CONFIG_HASH


def study_views(views, scope):
    """Input function: results/<study>/config_views/<scope>/<view>.json of every study in
    `run`, for each of `views` (method names or STUDY_VIEW): what the pooled tables read, so
    that a change of one method's parameters, or of another protocol family's section,
    does not rerun them (issue 13)."""

    def views_of_every_study(wildcards):
        return [
            f"{RESULTS}/{study}/config_views/{scope}/{view}.json"
            for study in config["run"]
            for view in views
        ]

    return views_of_every_study


def config_view_file(wildcards, scope=None):
    """Input function: the config view a job reads (made by the config_view rule), its
    {method}'s, or the study view for a job without a method, in the scope of its trial's
    protocol (gaitval.pipeline.steps.config.PROTOCOL_SCOPE) unless `scope` is given."""
    view = getattr(wildcards, "method", None) or STUDY_VIEW
    if scope is None:
        protocol = trial_row(wildcards.study, wildcards.trial)["protocol"]
        scope = PROTOCOL_SCOPE.get(protocol, ALL_SCOPE)
    return f"{RESULTS}/{wildcards.study}/config_views/{scope}/{view}.json"


def config_view_in(scope):
    """Input function: config_view_file in a given scope (jobs without a trial)."""

    def view_in_scope(wildcards):
        return config_view_file(wildcards, scope)

    return view_in_scope


# PRIORITIES (a rule's `priority:`) only order ready jobs, never change a file: what reads
# everything first (ingest, register, detect 20; the config views 200), the long chains
# early (ultrasonic_noise, rollator_train 100; ultrasonic_track 50), the one-process
# tables last (-10; ultrasonic_tables -5).  Measured reasons: docs/speed.md.

# Rule files add functions study -> [report items] here; rule `report` collects them.
REPORT_ITEM_FUNCS = []


def study_cfg(study):
    try:
        return config["studies"][study]
    except KeyError:
        raise ValueError(
            f"study {study!r} is not defined under `studies:` in the config "
            f"(known: {sorted(config['studies'])})"
        ) from None


def is_simulated(study):
    return "simulate" in study_cfg(study)


_SHEET_PATHS = {}


def sheet_path(study):
    """Trial sheet path; for a simulated study, wait for the `simulate` checkpoint.  Once
    known it is remembered: input functions ask for it thousands of times per DAG."""
    path = _SHEET_PATHS.get(study)
    if path is None:
        if is_simulated(study):
            path = checkpoints.simulate.get(study=study).output.sheet   # raises until done
        else:
            path = study_cfg(study)["trial_sheet"]
        _SHEET_PATHS[study] = path
    return path


def subjects_path(study):
    if is_simulated(study):
        return f"{DATA}/{study}/subjects.csv"
    return study_cfg(study)["subjects"]


_SHEETS = {}
_WORKDIR = Path.cwd().resolve()


def in_workdir(path):
    """A file below the workflow's directory as a path relative to it (the sheet gives
    absolute ones), anything else as given: Snakemake compares a job's input paths with
    the ones it last ran with, so a study folder copied or moved together with its
    results stays up to date."""
    if not path:
        return path
    try:
        return str(Path(path).relative_to(_WORKDIR))
    except ValueError:
        return path


def trials(study):
    """The validated trial sheet of a study (DataFrame indexed by trial id), its raw files'
    paths relative to the workflow's directory where they lie below it (in_workdir)."""
    path = sheet_path(study)
    if path not in _SHEETS:
        try:
            df = load_trial_sheet(path, subjects_path(study))
        except GaitvalError as exc:   # a file gone since the start: one line, no traceback
            sys.exit(f"gaitval: error: {exc}")
        for col in ("mocap_path", "sensor_path", "annotation_path"):
            df[col] = [in_workdir(p) for p in df[col]]
        _SHEETS[path] = df
    return _SHEETS[path]


def trial_ids(study, protocols=None):
    df = trials(study)
    if protocols is not None:
        df = df[df["protocol"].isin(protocols)]
    return sorted(df.index)


_ROWS = {}


def trial_row(study, trial):
    """One trial's row of the validated sheet, as a dict (column -> value)."""
    path = sheet_path(study)
    rows = _ROWS.get(path)
    if rows is None:
        rows = _ROWS[path] = trials(study).to_dict("index")
    return rows[trial]


def has_mocap(study, trial):
    """Whether a trial has a mocap file (a trial with annotations only has none)."""
    return bool(trial_row(study, trial)["mocap_path"])


def mocap_trial_ids(study):
    """The trials of a study with mocap: the ones ingest and register take (issue 11)."""
    return [t for t in trial_ids(study) if has_mocap(study, t)]


def trial_wildcards(study, trial, method=None):
    """What a per-trial input function reads from its wildcards, for one trial of a batch
    job (study, trial and, when given, method)."""
    from types import SimpleNamespace

    w = SimpleNamespace(study=study, trial=trial)
    if method is not None:
        w.method = method
    return w


def study_raw_files(study):
    """The raw files of every trial with mocap (what `ingest` reads): a new or edited file
    reruns the study's ingest."""
    files = []
    for t in mocap_trial_ids(study):
        row = trial_row(study, t)
        files += [p for p in (row["mocap_path"], row["sensor_path"], row["annotation_path"])
                  if p]
    return files


def trial_bytes(study, trial):
    """A trial's raw mocap and sensor bytes: how long its steps take, roughly (a batch
    starts the largest trials first)."""
    row = trial_row(study, trial)
    return sum(size_of(p) for p in (row["mocap_path"], row["sensor_path"]) if p)


def trial_sizes(study, trials):
    """trial_bytes of each trial: a stage verb's --sizes."""
    return [trial_bytes(study, t) for t in trials]


def report_items(wildcards):
    """Every table/figure the rule files registered, for every study in `run`."""
    return [item for study in config["run"] for f in REPORT_ITEM_FUNCS for item in f(study)]


def parent_of(name, up=0):
    """Param function: the folder of output `name` (`up` levels higher)."""
    return lambda wildcards, output: str(Path(output[name]).parents[up])


def tug_methods():
    """The TUG tracker methods to run (config tug.methods)."""
    return list(config.get("tug", {}).get("methods", ["tug_m1", "tug_m2", "tug_m3", "people",
                                                        "people_offline"]))


def _reading_variants():
    """seed000 eq. (3)-(4) can be read two ways (gaitval.gait.phases): each TUG method also
    runs under every other reading of tug.phase_readings, as <method>_<reading> = the
    method (built-in or tracking.methods, with its tracking.overrides) with
    phase__reading set.  They are added to tracking.methods, so the per-study config.json,
    the track jobs and Table 2 see the definition that ran."""
    readings = config.get("tug", {}).get("phase_readings", ["swing_first"])
    tracking = config.setdefault("tracking", {})
    variants = {}
    for m in tug_methods():
        base = set_params(get_method(method_definition(config, m)),
                          (tracking.get("overrides") or {}).get(m))
        if "phase" not in base:
            continue        # no phase role of its own (the people tracker): one reading
        own = method_reading(m, {m: base})[1]
        for r in readings:
            name = f"{m}_{r}"
            if r == own or name in (tracking.get("methods") or {}):
                continue
            variants[name] = set_params(base, {"phase__reading": r})
            variants[name]["label"] = f"{base.get('label', m)}, eq. (3)-(4) {r}"
    tracking["methods"] = {**(tracking.get("methods") or {}), **variants}
    return list(variants)


_READING_VARIANTS = _reading_variants()


def external_methods(protocol=None):
    """The external methods (issue 37): another tracker's tracks of each trial, read from
    files in the leg-track exchange format or a ROS bag (docs/formats.md), declared in
    tracking.external or in the studies' study.yaml (external_methods:, the same names in
    every study of run: _check_external); those of one protocol (an entry's `protocols`,
    default tug and mtst) when it is given."""
    entries = {}
    for study_entries in _EXTERNAL.values():
        for m, e in study_entries.items():
            entries.setdefault(m, e)
    return [m for m, e in entries.items()
            if protocol is None or protocol in ((e or {}).get("protocols") or EXTERNAL_PROTOCOLS)]


def external_tracks_file(wildcards):
    """Input function: the external method's track file of one trial (its path relative to
    the trial sheet's folder, {trial} replaced)."""
    from gaitval.pipeline.steps.declarations import external_track_path

    entry = _EXTERNAL[wildcards.study][wildcards.method]
    return str(external_track_path(sheet_path(wildcards.study), entry, wildcards.trial,
                                   wildcards.method))


def external_detectors():
    """The external leg detectors (issue 37): external_detections: of the studies'
    study.yaml / external.yaml (the same names in every study of run: _check_detections)."""
    return sorted({m for entries in _DETECTIONS.values() for m in entries})


def detection_trials(study, detector):
    """(trial, protocol) of every trial with mocap of the detector's protocols in the
    study (a trial without mocap has no legs to score against)."""
    from gaitval.pipeline.steps.declarations import DETECTION_PROTOCOLS

    prots = _DETECTIONS[study][detector].get("protocols") or DETECTION_PROTOCOLS
    return [(t, p) for p in prots for t in trial_ids(study, [p]) if has_mocap(study, t)]


def detection_file(study, detector, trial):
    """The detector's file of one trial (its path relative to the trial sheet's folder,
    {trial} replaced)."""
    from gaitval.pipeline.steps.declarations import external_track_path

    return str(external_track_path(sheet_path(study), _DETECTIONS[study][detector], trial,
                                   detector, field=f"external_detections.{detector}.path"))


def external_input_files(study):
    """The external trackers' and detectors' files of a study's trials (the report's
    provenance lists them with the study's other raw inputs); a ROS 2 bag folder by its
    files."""
    from gaitval.pipeline.steps.declarations import EXTERNAL_PROTOCOLS, external_track_path

    out = []
    for m, e in _EXTERNAL.get(study, {}).items():
        for t in trial_ids(study, list(e.get("protocols") or EXTERNAL_PROTOCOLS)):
            out.append(external_track_path(sheet_path(study), e, t, m))
    out += [Path(detection_file(study, d, t)) for d in _DETECTIONS.get(study, {})
            for t, _ in detection_trials(study, d)]
    return [str(f) for p in out for f in (sorted(x for x in p.rglob("*") if x.is_file())
                                          if p.is_dir() else [p])]


def tug_runs():
    """The TUG methods (tug.methods), their reading variants (tug.phase_readings) and the
    external methods (tracking.external)."""
    return tug_methods() + _READING_VARIANTS + external_methods("tug")


def pendulum_trials():
    return [(s, t) for s in config["run"] for t in trial_ids(s, ["pendulum"])]


def treadmill_trials():
    return [(s, t) for s in config["run"] for t in trial_ids(s, ["treadmill"])]


# the simulator's source digest, a param of the simulate checkpoint (simulate.smk): its
# files (names and bytes), gaitval.report.provenance.source_digest of gaitval/simulate/
TWIN = source_digest(Path(workflow.basedir) / "gaitval" / "simulate")
