# The configuration checked before any job runs (included by common.smk): every key
# against workflow/schemas/config.schema.yaml, each study's study.yaml, tracking.overrides,
# and the external methods' and detectors' files.

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
    external_declarations): a name that is not already a method, the same names in every
    study of run, and every trial's file there, inside the study's folder, before any job
    runs.  tracking.external in a study.yaml is refused (external_methods: is the key).
    Returns {study: {method: entry}}."""
    from gaitval.pipeline.steps.declarations import (external_declarations,
                                                     missing_external_files)

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
                              "--configfile; docs/formats_external.md, Leg tracks)")
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
    from gaitval.pipeline.steps.declarations import (
        DETECTION_PROTOCOLS, detection_topic_problems, external_declarations,
        missing_external_files)

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
