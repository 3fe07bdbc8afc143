# Input functions of legbench.smk (annotated recordings without mocap, issue 18).
LEGBENCH_WC = {"study": "[^/]+", "method": "[^/]+", "init": "own|annotation", "trial": "[^/]+"}
# the legbench section is not one of steps.ANALYSIS_SECTIONS: its own provenance hash
LEGBENCH_HASH = config_hash(
    {**{k: config[k] for k in ANALYSIS_SECTIONS if k in config},
     "legbench": config.get("legbench", {})}
)


def legbench_cfg():
    lb = dict(config.get("legbench") or {})
    lb.setdefault("methods", ["tug_m1", "tug_m2", "tug_m3"])
    lb.setdefault("inits", ["own", "annotation"])
    lb.setdefault("match_m", 0.75)
    lb.setdefault("min_false_s", 0.5)
    return lb


def legbench_trials(study):
    return trial_ids(study, ["legbench"])


def legbench_annotations(study, trial):
    """The annotation source of a trial: its annotation_file, else its bag (topic)."""
    row = trial_row(study, trial)
    return row["annotation_path"] or row["sensor_path"]


def legbench_eval_dirs(study):
    lb = legbench_cfg()
    return [
        f"{RESULTS}/{study}/legbench_eval/{m}/{i}/{t}"
        for t in legbench_trials(study)
        for m in lb["methods"]
        for i in lb["inits"]
    ]
