# Input functions of legbench.smk (annotated recordings without mocap, issue 18).
import json

from gaitval.io.trialsheet import load_subjects

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


def legbench_args(w):
    """Topics of the trial (command-line options; empty when the sheet gives none)."""
    row = trial_row(w.study, w.trial)
    args = []
    if row["sensor_topic"]:
        args += ["--scan-topic", row["sensor_topic"]]
    if row["annotation_topic"]:
        args += ["--annotation-topic", row["annotation_topic"]]
    return args


def legbench_score_args(w):
    """The trial's scoring options: its published benchmark set (trial sheet `scenario`,
    one of gaitval.tables.legbench.BENCHMARK_SETS) and bearing sector (`sector_min_deg`,
    `sector_max_deg`; else the set's own, e.g. -80..12 for the general-tracking sets)."""
    from gaitval.tables.legbench import BENCHMARK_SETS

    row = trial_row(w.study, w.trial)
    bset = row.get("scenario") or ""
    args = ["--benchmark-set", bset] if bset in BENCHMARK_SETS else []
    sector = [row.get("sector_min_deg"), row.get("sector_max_deg")]
    sector = [float(v) for v in sector if v is not None and float(v) == float(v)]  # not NaN
    if len(sector) < 2 and bset in BENCHMARK_SETS:
        sector = list(BENCHMARK_SETS[bset]["sector_deg"] or ())
    if len(sector) == 2:
        args += ["--sector-deg", f"{sector[0]:g}", f"{sector[1]:g}"]
    return args


def legbench_leg_width(w):
    subj = load_subjects(subjects_path(w.study)).loc[trial_row(w.study, w.trial)["subject"]]
    return float(subj["leg_width_m"])


def legbench_eval_dirs(study):
    lb = legbench_cfg()
    return [
        f"{RESULTS}/{study}/legbench_eval/{m}/{i}/{t}"
        for t in legbench_trials(study)
        for m in lb["methods"]
        for i in lb["inits"]
    ]


def legbench_tasks(wildcards, input, output, params):
    """A (study, method, init) job's tasks: per trial, its track and then its CLEAR-MOT
    scores against its annotations."""
    tasks = []
    for t, sensor, ann, topics, score, width in zip(
            params.trials, input.sensors, input.annotations, params.topics, params.score,
            params.leg_width):
        track = f"{output.track}/{t}/track.parquet"
        tasks.append((t, [
            verb("legbench-track", "--sensor", sensor, "--annotations", ann, topics,
                 "--method", wildcards.method, "--init", wildcards.init,
                 "--leg-width-m", width, "--config", input.config, "--trial", t,
                 "--out", track),
            verb("legbench-evaluate", "--track", track, "--annotations", ann, topics, score,
                 "--match-m", params.match_m, "--min-false-s", params.min_false_s,
                 "--trial", t, "--out", f"{output.evaluate}/{t}"),
        ]))
    return tasks
