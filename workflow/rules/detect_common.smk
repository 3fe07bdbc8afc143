# Helpers of workflow/rules/detect.smk: which methods share a
# detector, and the folders and arguments of their shared detections.
from collections import Counter

from gaitval.pipeline.detections import canonical, detector_key, method_detector
from gaitval.pipeline.steps.config import analysis_config

_DETECTION_PLANS = {}


def detection_plan(study, family):
    """({method: detector folder name}, {name: spec}) of the `family` (tug or mtst) methods
    of `study` whose detector spec another of them shares (the config and the study's
    study.yaml, as the method views give them to the track steps)."""
    key = (study, family)
    if key not in _DETECTION_PLANS:
        methods = (tug_methods() + _READING_VARIANTS if family == "tug" else mtst_methods())
        plan, specs = {}, {}
        if trial_ids(study, [family]):
            cfg = analysis_config(config, sheet_path(study))
            found = {m: method_detector(cfg, m) for m in methods}
            count = Counter(canonical(s) for s in found.values() if s is not None)
            for m, spec in found.items():
                if spec is not None and count[canonical(spec)] > 1:
                    plan[m] = detector_key(spec)
                    specs[plan[m]] = spec
        _DETECTION_PLANS[key] = (plan, specs)
    return _DETECTION_PLANS[key]


def detections_dir(family):
    """Input function: the detect job's folder a (study, method) track job reads, or none."""

    def shared_detections(wildcards):
        name = detection_plan(wildcards.study, family)[0].get(wildcards.method)
        return [f"{RESULTS}/{wildcards.study}/detect/{family}/{name}"] if name else []

    return shared_detections


def detect_inputs(wildcards):
    """What a detect job reads: the sheet, the family's study view (leg width default, scan
    period), the ingest folder, and an MTST trial's raw scan log when it has no mocap."""
    study, family = wildcards.study, wildcards.family
    trials = trial_ids(study, [family])
    files = {
        "sheet": sheet_path(study),
        "view": f"{RESULTS}/{study}/config_views/{family}/{STUDY_VIEW}.json",
        "raw": [trial_row(study, t)["sensor_path"] for t in trials if not has_mocap(study, t)],
    }
    if any(has_mocap(study, t) for t in trials):
        files["ingest"] = f"{RESULTS}/{study}/ingest"
    return files


def detect_sensor(study, family, trial):
    """The scan log a trial's track step reads."""
    if family == "mtst":
        return mtst_trial_files(study, trial)["sensor"]
    return f"{RESULTS}/{study}/ingest/{trial}/sensor.parquet"


def detector_spec_json(wildcards):
    """Param function: the spec of the job's detector folder, as JSON text."""
    specs = detection_plan(wildcards.study, wildcards.family)[1]
    if wildcards.detector not in specs:
        raise ValueError(f"no method of study {wildcards.study!r} ({wildcards.family}) "
                         f"shares the detector {wildcards.detector!r}")
    return canonical(specs[wildcards.detector])
