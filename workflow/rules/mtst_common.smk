# Input functions of the MTST rules (workflow/rules/mtst.smk).
import yaml


def mtst_methods():
    """The MTST tracker methods to run (config mtst.methods)."""
    return list(
        config.get("mtst", {}).get(
            "methods", ["mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed"]
        )
    )


def mtst_sensor(wildcards):
    """The ingested scan log, or the raw one for a trial without mocap."""
    if has_mocap(wildcards.study, wildcards.trial):
        return f"{RESULTS}/{wildcards.study}/ingest/{wildcards.trial}/sensor.parquet"
    return trial_row(wildcards.study, wildcards.trial)["sensor_path"]


def mtst_registration(wildcards):
    """registration.json and groundtruth.parquet when the trial has mocap."""
    if not has_mocap(wildcards.study, wildcards.trial):
        return {}
    reg = registration_dir(wildcards.study, wildcards.trial)
    return {
        "reg": f"{reg}/registration.json",
        "gt": f"{reg}/groundtruth.parquet",
    }


_TARGET_PATTERNS = {}


def mtst_target_pattern(study):
    """mtst.targets of the study's study.yaml, else of the config (read once per study)."""
    if study not in _TARGET_PATTERNS:
        sheet = Path(sheet_path(study))
        pattern = (config.get("mtst") or {}).get("targets")
        cal = sheet.parent / "study.yaml"
        if cal.is_file():
            pattern = ((yaml.safe_load(cal.read_text()) or {}).get("mtst") or {}).get(
                "targets", pattern
            )
        _TARGET_PATTERNS[study] = pattern
    return _TARGET_PATTERNS[study]


def mtst_targets_file(wildcards):
    """The trial's target layout (mtst.targets of study.yaml or the config), when it exists."""
    sheet = Path(sheet_path(wildcards.study))
    pattern = mtst_target_pattern(wildcards.study)
    if not pattern:
        return []
    path = sheet.parent / str(pattern).replace("{trial}", wildcards.trial)
    return [str(path)] if path.is_file() else []


def mtst_trial_files(study, trial):
    """One trial's paths for its verbs: the scan log, ``[--registration, path]`` and
    ``[--groundtruth, path]`` (empty for a trial without mocap)."""
    w = trial_wildcards(study, trial)
    reg = mtst_registration(w)
    return {
        "sensor": mtst_sensor(w),
        "reg": ["--registration", reg["reg"]] if reg else [],
        "gt": ["--groundtruth", reg["gt"]] if reg else [],
    }


def mtst_batch_inputs(wildcards):
    """What a (study, method) job reads: the method's view, the sheet, the study's ingest
    and register folders (when a trial has mocap), the raw scan logs of the trials without,
    the target layouts and the rater annotations."""
    study = wildcards.study
    trials = trial_ids(study, ["mtst"])
    files = {
        "config": f"{RESULTS}/{study}/config_views/mtst/{wildcards.method}.json",
        "sheet": sheet_path(study),
        "targets": [p for t in trials for p in mtst_targets_file(trial_wildcards(study, t))],
        "annotations": [trial_row(study, t)["annotation_path"] for t in trials
                        if trial_row(study, t)["annotation_path"]],
        "raw": [trial_row(study, t)["sensor_path"] for t in trials if not has_mocap(study, t)],
    }
    if any(has_mocap(study, t) for t in trials):
        files["ingest"] = f"{RESULTS}/{study}/ingest"
        files["register"] = register_dir(study, "mtst")
    # the trials' observations, when another method shares this one's detector (detect.smk)
    files["detections"] = detections_dir("mtst")(wildcards)
    return files


def mtst_sensors(wildcards):
    """Param function: each MTST trial's scan log (ingested, or raw without mocap)."""
    return [mtst_trial_files(wildcards.study, t)["sensor"]
            for t in trial_ids(wildcards.study, ["mtst"])]


def mtst_summaries(wildcards):
    return [
        f"{RESULTS}/{study}/mtst_eval/{method}/{trial}/summary.parquet"
        for study in config["run"]
        for method in mtst_methods() + external_methods("mtst")
        for trial in trial_ids(study, ["mtst"])
    ]
