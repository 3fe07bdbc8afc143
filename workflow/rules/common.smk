# Shared by all rule files -- config validation, paths, the trial sheet, provenance.
import re
import json
import shlex
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


def _load_config_file(path):
    """A YAML (or JSON) config file as a dict; a file that is no mapping is refused."""
    with open(path, encoding="utf-8") as fh:
        doc = yaml.safe_load(fh)
    if doc is None:
        return {}
    if not isinstance(doc, dict):
        raise ConfigError(f"[file {display_path(Path(path))}] a config file holds keys at "
                          f"its top level, not a {type(doc).__name__}")
    return doc


def _cli_configfiles():
    """The --configfile paths as Snakemake holds them (absolute; its ConfigSettings)."""
    return list(workflow.config_settings.configfiles)


def _cli_config():
    """--config as Snakemake parsed it (Snakemake's ConfigSettings.config)."""
    return dict(workflow.config_settings.config or {})


def _config_layers():
    """(name, dict) of every config source, lowest precedence first: the Snakefile's
    configfile, each --configfile, then --config (so a problem names where its key is)."""
    cli = [Path(f).resolve() for f in _cli_configfiles()]
    files = [Path(f).resolve() for f in workflow.configfiles]
    files = [f for f in files if f not in cli] + cli
    layers = [(display_path(f), _load_config_file(f)) for f in files if f.is_file()]
    return layers + [("--config", _command_line_config())]


def _command_line_config():
    """--config as Snakemake parsed it, its nested scalars typed as in a config file
    (gaitval.configcheck.retype_command_line: {"pf_seed": "2018"} -> {"pf_seed": 2018})."""
    return retype_command_line(_cli_config())


def _method_definitions(cfg):
    """Every method an override may name: the built-in ones, tracking.methods, and the
    TUG reading variants <method>_<reading> (made from their base, _reading_variants)."""
    defs = {m: m for m in METHODS}
    defs.update((cfg.get("tracking") or {}).get("methods") or {})
    for m in (cfg.get("tug") or {}).get("methods") or []:
        for r in (cfg.get("tug") or {}).get("phase_readings") or []:
            defs.setdefault(f"{m}_{r}", defs.get(m, m))
    return defs


def _check_study_files(schema):
    """study.yaml of each study in `run` whose trial sheet is already there (a simulated
    study's is checked again when its config is built, rule study_config), its
    tracking.overrides too."""
    for study in config["run"]:
        entry = config["studies"].get(study) or {}
        sheet = Path(entry.get("trial_sheet") or Path(DATA) / study / "trials.csv")
        cal = sheet.parent / "study.yaml"
        # external.yaml beside it (external methods and detectors; never written by gaitval)
        from gaitval.pipeline.steps.declarations import study_side_problems
        study_side_problems(sheet, schema=schema)
        if cal.is_file():
            own = _load_config_file(cal)
            check_study_file(own, cal, schema=schema)
            merged = {k: {**(config.get(k) or {}), **((own or {}).get(k) or {})}
                      for k in ("tracking", "tug")}
            raise_problems(with_sources(
                override_problems((own.get("tracking") or {}).get("overrides"),
                                  _method_definitions(merged)),
                [(display_path(cal), own)]))


def _sheet_of(cfg, study):
    entry = cfg["studies"].get(study) or {}
    return Path(entry.get("trial_sheet") or Path(DATA) / study / "trials.csv")


#: gaitval's ultrasonic UKF as a system of the treadmill agreement table (external.smk)
UKF_SYSTEM = "ultrasonic_ukf"


def _check_external(cfg):
    """External methods (issue 37): tracking.external of the workflow config (every study
    of run) and external_methods: of each study's study.yaml (gaitval.pipeline.steps.
    declarations.external_declarations): a name that is not already a method, the same
    names in every study of run, and every trial's file there, inside the study's folder,
    before any job runs.  tracking.external in a study.yaml is refused (external_methods:
    is the key).  Returns {study: {method: entry}}."""
    from gaitval.pipeline.steps.declarations import external_declarations, missing_external_files

    names = _method_definitions(cfg)
    names.update(dict.fromkeys((cfg.get("tug") or {}).get("methods") or []))
    names.update(dict.fromkeys((cfg.get("mtst") or {}).get("methods") or []))
    names[UKF_SYSTEM] = None          # gaitval's own row of the treadmill agreement table
    config_external = (cfg.get("tracking") or {}).get("external") or {}
    for m in config_external:
        if m in names:
            raise ConfigError(f"tracking.external.{m}: {m!r} is already a tracking method; "
                              "give the external tracker another name")
    sheets = {study: _sheet_of(cfg, study) for study in cfg["run"]}
    for study, sheet in sheets.items():
        cal = sheet.parent / "study.yaml"
        if cal.is_file() and ((_load_config_file(cal) or {}).get("tracking") or {}).get(
                "external"):
            raise ConfigError(f"[file {display_path(cal)}] tracking.external: a study "
                              "declares its external methods under external_methods: "
                              "(tracking.external is declared in the workflow config, a "
                              "--configfile; docs/formats.md, Leg tracks)")
    per_study = external_declarations(config_external, sheets, names)
    for study, entries in per_study.items():
        where = declared_in(sheets[study], "external_methods")
        for m, entry in entries.items():
            src = ("tracking.external" if m in config_external else
                   f"[file {where[m]}] external_methods")
            missing_external_files(sheets[study], {m: entry}, f"study {study}: {src}",
                                   key=None if m in config_external else "external_methods")
    return per_study


def _check_detections(cfg, per_study_methods):
    """External leg detectors (issue 37): external_detections: of each study's study.yaml
    or external.yaml, checked as _check_external checks the external methods (a name that
    is no method nor external method, the same names in every study of run, every trial's
    file there and inside the study's folder) and each bag's LegArray topic, before any
    job runs.  Returns {study: {detector: entry}}."""
    from gaitval.pipeline.steps.declarations import (DETECTION_PROTOCOLS, detection_topic_problems,
                                                     external_declarations, missing_external_files)

    names = _method_definitions(cfg)
    names.update(dict.fromkeys((cfg.get("tug") or {}).get("methods") or []))
    names.update(dict.fromkeys((cfg.get("mtst") or {}).get("methods") or []))
    for entries in per_study_methods.values():
        names.update(dict.fromkeys(entries))
    sheets = {study: _sheet_of(cfg, study) for study in cfg["run"]}
    per_study = external_declarations({}, sheets, names, key="external_detections",
                                      protocols=DETECTION_PROTOCOLS)
    for study, entries in per_study.items():
        where = declared_in(sheets[study], "external_detections")
        for m, entry in entries.items():
            src = f"study {study}: [file {where[m]}] external_detections"
            missing_external_files(sheets[study], {m: entry}, src,
                                   protocols=DETECTION_PROTOCOLS, what="detection files",
                                   key="external_detections", mocap_only=True)
            detection_topic_problems(sheets[study], {m: entry}, src)
    return per_study


def declared_in(sheet, key):
    """name -> the file (study.yaml or external.yaml beside the sheet) declaring it."""
    from gaitval.pipeline.steps.declarations import declared_entries

    return {m: display_path(f) for m, (_, f) in declared_entries(sheet, key).items()}


DATA = config.get("data_dir", "data")
# Numbers nested in a --config value as numbers (Snakemake leaves them strings).
update_config(config, _command_line_config())
# Every key against workflow/schemas/config.schema.yaml, then the studies' study.yaml: a
# typo stops the run here with the file, the key's path and the nearest valid key
# (gaitval.configcheck), as one message.
try:
    _SCHEMA = load_schema(Path(workflow.basedir) / "workflow/schemas/config.schema.yaml")
    check_config(config, _config_layers(), schema=_SCHEMA)
    raise_problems(with_sources(run_problems(config), _config_layers()))   # run: [studies]
    # tracking.overrides: each key a role and parameter of its method (gaitval.methods)
    raise_problems(with_sources(
        override_problems((config.get("tracking") or {}).get("overrides"),
                          _method_definitions(config)), _config_layers()))
    _check_study_files(_SCHEMA)
    _EXTERNAL = _check_external(config)
    _DETECTIONS = _check_detections(config, _EXTERNAL)
except ConfigError as exc:
    sys.exit(f"ConfigError: {exc}")

RESULTS = config.get("results_dir", "results")
PRESETS = Path(workflow.basedir) / "config" / "studies"
# One report folder per set of pooled studies: reports/<run-name>/ with run-name = the
# `run` list joined by "+" (reports/tiny, reports/default, reports/tiny+replay), so a
# table that pools the studies of `run` (tug_table4, ...) never overwrites another run's,
# and changing `run` asks for files that do not exist yet -- Snakemake rebuilds them.
RUN_NAME = "+".join(config["run"])
REPORTS_ROOT = config.get("reports_dir", "reports")
REPORTS = f"{REPORTS_ROOT}/{RUN_NAME}"
# HOW JOBS RUN (issue 38; docs/speed.md).  One Snakemake job per (study, stage) or
# (study, stage, method), not per trial: its `run:` block hands the trials to
# gaitval.jobs.batch.run_batch, which runs each trial's gaitval verbs (the CLI's, with
# the same arguments as `python -m gaitval VERB ...` by hand) in a process pool of the
# rule's `threads`, forked from the standard library's forkserver that imported numpy,
# pandas, scipy and gaitval once.  Every trial still writes its own files, in the same
# places; a job's outputs are the stage's folders (`directory()`), and its log lists every
# trial's messages.  The simulation runs through Snakemake's `shell:`, with GV, the
# interpreter running Snakemake (so a venv's bin/ need not be on PATH).
GV = f"{shlex.quote(sys.executable)} -m gaitval"   # a checkout path with a space


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
# The jobs' processes end with this Snakemake (gaitval/jobs/lifeline.py): a shell job's
# `python -m gaitval` watches this pid, as the batch pool's workers do.
import os as _os

_os.environ.update(GAITVAL_RUN_PID=str(_os.getpid()))


# The batch jobs' pool: its forkserver imports numpy, pandas, scipy and gaitval (~2 CPU-s)
# once per run.  Started when Snakemake begins to run jobs (not on a dry run, nor when
# nothing is to be done), it imports beside the first jobs (the simulation's own start-up
# leaves a core free) instead of inside the first batch job with one core idle
# (docs/speed.md).  Only where the jobs run in this process: on a cluster each job is a
# process of its own (Snakemake's `local_exec`, False for a cluster executor).
onstart:
    if getattr(workflow, "local_exec", True):
        from gaitval.jobs.batch import warm

        warm()


def verb(*words):
    """One gaitval verb's command line, as a list of words (nested lists flattened, so an
    optional ``[flag, value]`` param goes in as is)."""
    out = []
    for w in words:
        if isinstance(w, (list, tuple)):
            out.extend(verb(*w))
        else:
            out.append(str(w))
    return out


def run_trials(tasks, threads, log, sizes=None, outdirs=()):
    """Run a batch job's tasks (label, [verb, ...]) in the pool (gaitval.jobs.batch),
    largest first when their ``sizes`` are given.  ``outdirs``: the job's `directory()`
    outputs, made first (a batch of no trial still leaves its folder).  A job killed
    half-way leaves them marked incomplete by Snakemake, and the next run removes and
    redoes them (gaitval.jobs.resume)."""
    from gaitval.jobs.batch import Task, by_size, run_batch, run_verbs

    for d in outdirs:
        Path(d).mkdir(parents=True, exist_ok=True)
    tasks = [Task(label, run_verbs, {"argvs": argvs}) for label, argvs in tasks]
    if sizes is not None:
        tasks = by_size(tasks, sizes)
    run_batch(tasks, threads, log)


def run_verb_job(argv, log):
    """A job of one verb (a table, the report): in one process of the pool."""
    run_trials([(argv[0], [argv])], 1, log)


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


# PRIORITIES.  Snakemake starts ready jobs by priority (default 0), not by how much waits
# on them.  The default report's critical path (benchmarks/report_end_to_end.py, the run's
# Snakemake log) was the ultrasonic chain: the noise identification (one ~30 CPU-s job)
# started only when every other trial was done, then its 30 tracks, gait parameters and
# tables ran alone for ~90 s; the rollator PF likewise waited for its trained models.  So:
# ultrasonic_noise and rollator_train 100, ultrasonic_track (with the gait parameters) 50,
# ingest, register and detect (everything's inputs) 20.  The tables are one process each
# (tug 2.4, mtst 2.3, rollator 1.1, ultrasonic 5.8 CPU-s), and a batch job takes every
# core, so a table started while batch jobs wait ran with the other core idle (~7 core-s
# in a default run, benchmarks/batch_tails.py and the run's Snakemake log); at -10 they
# wait until no batch job is left and then run two at a time, ultrasonic_tables (-5, the
# longest) beside the three others in turn: 5.8 against 5.8 CPU-s.  registration_summary
# (0.1 s) is at -10 too: at 0 it started, for its large input, as soon as the last MTST
# track ended, on one core, a table took the other, and the TUG tracks, which need both,
# waited 4.6 s (the run's Snakemake log, issue 38).
# config_view 200: the views take milliseconds each, but at priority 0 they ran only when
# a core was free of batch jobs, so the jobs that read them waited -- the ultrasonic chain
# (noise 100, tracks 50) started only after every MTST track, and its table then ran alone
# with a core idle (benchmarks/report_end_to_end.py, the run's Snakemake log).  (With the
# per-trial jobs of before issue 38 the same priority made every registration ready at
# once and cost Snakemake ~5 CPU-s of scheduling rounds; with ~50 jobs it costs nothing.)
# Order only: same jobs, same files.

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


def trials(study):
    """The validated trial sheet of a study (DataFrame indexed by trial id)."""
    path = sheet_path(study)
    if path not in _SHEETS:
        try:
            _SHEETS[path] = load_trial_sheet(path, subjects_path(study))
        except GaitvalError as exc:   # a file gone since the start: one line, no traceback
            sys.exit(f"gaitval: error: {exc}")
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
