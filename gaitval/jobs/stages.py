"""The trial loop of each workflow stage: ``gaitval <stage>-trials``.

A workflow rule runs one command per (study, stage[, method]) job, for example::

    gaitval track-trials --trials T01 T02 --ingest results/s/ingest \\
        --register results/s/register/tug --sheet ... --subjects ... --config ... \\
        --method tug_m1 --out results/s/track/tug_m1 results/s/evaluate/tug_m1 \\
        --threads 2 --log logs/track/s/tug_m1.log

The verb makes its output folders, builds each trial's per-trial verbs (the same
``gaitval VERB ...`` a user runs by hand for one trial; the log lists each as ``$ gaitval
...``) with :data:`STAGES`, and runs the trials in a process pool of ``--threads``
(:func:`gaitval.jobs.batch.run_batch`), the largest first when ``--sizes`` are given.
Where each trial's files go is the stage's own layout below the ``--out`` folders; a
trial's inputs are the given folders' ``<trial>/...`` files or, where they differ per
trial, a list aligned with ``--trials`` (``--files``, ``--sensors``, ``--models``,
``--protocols``).

A job killed half-way leaves its output folders marked incomplete by Snakemake; the next
run removes them and runs the job again (:mod:`gaitval.jobs.resume`).  No second
mechanism: a folder is the job's output, and no trial is resumed inside it.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

from gaitval.errors import GaitvalError

Argv = list[str]


class StageError(GaitvalError):
    """A stage command's arguments do not fit together (e.g. a per-trial list of another
    length than --trials)."""


def _opt(flag: str, value) -> list[str]:
    """``[flag, value]`` when a value is given, else nothing."""
    return [flag, str(value)] if value else []


def aligned(a, name: str) -> list[str]:
    """The per-trial list ``--name``, one entry per trial of --trials."""
    values = list(getattr(a, name) or [])
    if len(values) != len(a.trials):
        raise StageError(f"--{name}: {len(values)} value(s) for {len(a.trials)} trial(s) "
                         f"({', '.join(a.trials[:4])}{', ...' if len(a.trials) > 4 else ''})")
    return values


def _detections(a, t: str) -> list[str]:
    return _opt("--detections", a.detections and f"{a.detections}/{t}.parquet")


def _evaluate_tug(a, t: str, track: str) -> Argv:
    reg = f"{a.register}/{t}"
    return ["evaluate-tug", "--track", track, "--groundtruth", f"{reg}/groundtruth.parquet",
            "--registration", f"{reg}/registration.json", "--trial", t,
            "--method", a.method, "--config", a.config, "--out", f"{a.out[1]}/{t}"]


def ingest(a) -> list[tuple[str, list[Argv]]]:
    """Each trial with mocap: raw files -> results/<study>/ingest/<trial>/."""
    return [(t, [["ingest", "--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
                  "--out", f"{a.out[0]}/{t}"]]) for t in a.trials]


def register(a) -> list[tuple[str, list[Argv]]]:
    """Each trial with mocap of one protocol family: registration and ground truth."""
    return [(t, [["register", "--ingest", f"{a.ingest}/{t}", "--sheet", a.sheet,
                  "--subjects", a.subjects, "--trial", t, "--config", a.config,
                  "--out", f"{a.out[0]}/{t}"]]) for t in a.trials]


def detect(a) -> list[tuple[str, list[Argv]]]:
    """Each trial's leg observations by one shared detector (``--family`` tug or mtst)."""
    name = "detect" if a.family == "tug" else "mtst-detect"
    return [(t, [[name, "--sensor", s, "--sheet", a.sheet, "--subjects", a.subjects,
                  "--trial", t, "--detector", a.detector, "--config", a.config,
                  "--out", f"{a.out[0]}/{t}.parquet"]])
            for t, s in zip(a.trials, aligned(a, "sensors"))]


def track(a) -> list[tuple[str, list[Argv]]]:
    """Each TUG trial tracked by one method, then evaluated (--out TRACK EVALUATE)."""
    tasks = []
    for t in a.trials:
        out = f"{a.out[0]}/{t}.parquet"
        tasks.append((t, [["track", "--sensor", f"{a.ingest}/{t}/sensor.parquet",
                           "--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
                           "--method", a.method, "--config", a.config, *_detections(a, t),
                           "--out", out], _evaluate_tug(a, t, out)]))
    return tasks


def _import_tracks(a, t: str, tracks: str, out: str, *flags: str) -> Argv:
    """An external tracker's file of trial ``t`` converted to gaitval's track (``flags``:
    e.g. ``--moving-sensor`` on the rollator)."""
    return ["import-tracks", "--tracks", tracks, "--sensor", f"{a.ingest}/{t}/sensor.parquet",
            "--registration", f"{a.register}/{t}/registration.json", "--trial", t,
            "--method", a.method, "--config", a.config, *flags, "--out", out]


def track_external(a) -> list[tuple[str, list[Argv]]]:
    """Each TUG trial's external track (--files) converted, then evaluated."""
    tasks = []
    for t, f in zip(a.trials, aligned(a, "files")):
        out = f"{a.out[0]}/{t}.parquet"
        tasks.append((t, [_import_tracks(a, t, f, out), _evaluate_tug(a, t, out)]))
    return tasks


def mtst(a) -> list[tuple[str, list[Argv]]]:
    """Each MTST trial tracked (or, with --files, an external track converted), then
    evaluated; --mocap-trials have a registration and ground truth under --register."""
    files = aligned(a, "files") if a.files else [None] * len(a.trials)
    mocap = set(a.mocap_trials or [])
    tasks = []
    for t, sensor, f in zip(a.trials, aligned(a, "sensors"), files):
        reg = f"{a.register}/{t}" if t in mocap else None
        registration = _opt("--registration", reg and f"{reg}/registration.json")
        out = f"{a.out[0]}/{t}.parquet"
        common = ["--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
                  "--method", a.method, "--config", a.config, *registration]
        first = (["import-tracks", "--tracks", f, "--sensor", sensor, *registration,
                  "--trial", t, "--method", a.method, "--config", a.config, "--out", out]
                 if f is not None else
                 ["mtst-track", "--sensor", sensor, *common, *_detections(a, t), "--out", out])
        tasks.append((t, [first, ["mtst-evaluate", "--track", out, *common,
                                  *_opt("--groundtruth", reg and f"{reg}/groundtruth.parquet"),
                                  "--out", f"{a.out[1]}/{t}"]]))
    return tasks


def rollator_train(a) -> list[tuple[str, list[Argv]]]:
    """The PF model of each held-out subject (--trials: the subjects)."""
    return [(s, [["rollator-train", "--results", a.results, "--sheet", a.sheet,
                  "--subjects", a.subjects, "--subject", s, "--config", a.config,
                  "--out", f"{a.out[0]}/{s}.json"]]) for s in a.trials]


def _rollator_evaluate(a, t: str, track_file: str) -> Argv:
    reg = f"{a.register}/{t}"
    return ["rollator-evaluate", "--track", track_file,
            "--groundtruth", f"{reg}/groundtruth.parquet",
            "--registration", f"{reg}/registration.json", "--ingest", f"{a.ingest}/{t}",
            "--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
            "--method", a.method, "--config", a.config, "--out", f"{a.out[0]}/{t}"]


def rollator_track(a) -> list[tuple[str, list[Argv]]]:
    """Each rollator trial tracked (--models: the PF's model of the trial's held-out
    subject, "-" for none), then evaluated."""
    models = aligned(a, "models") if a.models else ["-"] * len(a.trials)
    tasks = []
    for t, model in zip(a.trials, models):
        out = f"{a.out[0]}/{t}.track.parquet"
        tasks.append((t, [["rollator-track", "--sensor", f"{a.ingest}/{t}/sensor.parquet",
                           "--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
                           "--method", a.method, "--config", a.config,
                           *_opt("--model", model != "-" and model), "--out", out],
                          _rollator_evaluate(a, t, out)]))
    return tasks


def rollator_external(a) -> list[tuple[str, list[Argv]]]:
    """Each rollator trial's external track (--files, the laser's frame) converted, then
    evaluated."""
    tasks = []
    for t, f in zip(a.trials, aligned(a, "files")):
        out = f"{a.out[0]}/{t}.track.parquet"
        tasks.append((t, [_import_tracks(a, t, f, out, "--moving-sensor"),
                          _rollator_evaluate(a, t, out)]))
    return tasks


def leg_detections(a) -> list[tuple[str, list[Argv]]]:
    """Each trial's external leg detections (--files) scored against its mocap legs
    (--protocols: each trial's protocol; its registration under --register/<protocol>)."""
    tasks = []
    for t, p, f in zip(a.trials, aligned(a, "protocols"), aligned(a, "files")):
        reg = f"{a.register}/{p}/{t}"
        tasks.append((t, [["leg-detections", "--detections", f, *_opt("--topic", a.topic),
                           "--groundtruth", f"{reg}/groundtruth.parquet",
                           "--registration", f"{reg}/registration.json",
                           "--sensor", f"{a.ingest}/{t}/sensor.parquet", "--trial", t,
                           "--method", a.method, "--protocol", p,
                           *(["--moving-sensor"] if p == "rollator" else []),
                           "--out", f"{a.out[0]}/{t}"]]))
    return tasks


def ultrasonic_track(a) -> list[tuple[str, list[Argv]]]:
    """Each treadmill trial's UKF track, then its gait parameters (--out/track, /gait)."""
    tasks = []
    for t in a.trials:
        out = f"{a.out[0]}/track/{t}.parquet"
        tasks.append((t, [["ultrasonic-track", "--ingest", f"{a.ingest}/{t}", "--trial", t,
                           "--config", a.config, "--noise", a.noise, "--out", out],
                          ["gait-parameters", "--track", out, "--ingest", f"{a.ingest}/{t}",
                           "--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
                           "--config", a.config, "--out", f"{a.out[0]}/gait/{t}.parquet"]]))
    return tasks


def ultrasonic_external(a) -> list[tuple[str, list[Argv]]]:
    """Each treadmill trial's external heel trajectory (--files): its gait parameters."""
    return [(t, [["external-gait-parameters", "--foot", f, "--ingest", f"{a.ingest}/{t}",
                  "--sheet", a.sheet, "--subjects", a.subjects, "--trial", t,
                  "--method", a.method, "--config", a.config,
                  "--out", f"{a.out[0]}/{t}.parquet"]])
            for t, f in zip(a.trials, aligned(a, "files"))]


def _legbench_score(row: dict) -> Argv:
    """A recording's scoring options: its published benchmark set (trial sheet
    ``scenario``, one of :data:`gaitval.tables.legbench.BENCHMARK_SETS`) and bearing sector
    (``sector_min_deg``, ``sector_max_deg``; else the set's own, e.g. -80..12 for the
    general-tracking sets)."""
    from gaitval.tables.legbench import BENCHMARK_SETS

    bset = row.get("scenario") or ""
    args = ["--benchmark-set", bset] if bset in BENCHMARK_SETS else []
    sector = [row.get("sector_min_deg"), row.get("sector_max_deg")]
    sector = [float(v) for v in sector if v is not None and float(v) == float(v)]  # not NaN
    if len(sector) < 2 and bset in BENCHMARK_SETS:
        sector = list(BENCHMARK_SETS[bset]["sector_deg"] or ())
    if len(sector) == 2:
        args += ["--sector-deg", f"{sector[0]:g}", f"{sector[1]:g}"]
    return args


def legbench(a) -> list[tuple[str, list[Argv]]]:
    """Each annotated recording tracked by one method and initialisation (--init), then
    scored with CLEAR-MOT against its annotations (--out TRACK EVALUATE); the recording,
    its annotations (the annotation file, else the bag), topics, benchmark set, sector and
    the subject's leg width are the trial sheet's."""
    from gaitval.io.trialsheet import load_subjects, load_trial_row

    widths = load_subjects(a.subjects)["leg_width_m"]
    tasks = []
    for t in a.trials:
        row = load_trial_row(a.sheet, a.subjects, t)
        ann = row["annotation_path"] or row["sensor_path"]
        topics = (_opt("--scan-topic", row["sensor_topic"])
                  + _opt("--annotation-topic", row["annotation_topic"]))
        track = f"{a.out[0]}/{t}/track.parquet"
        tasks.append((t, [
            ["legbench-track", "--sensor", row["sensor_path"], "--annotations", ann, *topics,
             "--method", a.method, "--init", a.init,
             "--leg-width-m", str(float(widths.loc[row["subject"]])), "--config", a.config,
             "--trial", t, "--out", track],
            ["legbench-evaluate", "--track", track, "--annotations", ann, *topics,
             *_legbench_score(row), "--match-m", str(a.match_m),
             "--min-false-s", str(a.min_false_s), "--trial", t, "--out", f"{a.out[1]}/{t}"]]))
    return tasks


#: verb name -> (the tasks of its trials, help)
STAGES: dict[str, tuple[Callable, str]] = {
    "ingest-trials": (ingest, "ingest every trial of a study (one folder per trial)"),
    "register-trials": (register, "register every trial of one protocol family"),
    "detect-trials": (detect, "every trial's leg observations by one shared detector"),
    "track-trials": (track, "track and evaluate every TUG trial with one method"),
    "import-tracks-trials": (track_external, "an external method's TUG tracks, converted "
                             "and evaluated"),
    "mtst-trials": (mtst, "track (or import) and evaluate every MTST trial with one method"),
    "rollator-train-subjects": (rollator_train, "the PF model of every held-out subject"),
    "rollator-trials": (rollator_track, "track and evaluate every rollator trial with one "
                        "method"),
    "rollator-import-trials": (rollator_external, "an external method's rollator tracks, "
                               "converted and evaluated"),
    "leg-detections-trials": (leg_detections, "an external leg detector scored on every "
                              "trial with mocap"),
    "ultrasonic-trials": (ultrasonic_track, "every treadmill trial's UKF track and gait "
                          "parameters"),
    "external-gait-trials": (ultrasonic_external, "an external system's gait parameters "
                             "on every treadmill trial"),
    "legbench-trials": (legbench, "every annotated recording tracked by one method and "
                        "initialisation, then scored with CLEAR-MOT"),
}


#: what a stage's trials import (and the trackers' compiled kernels they run), loaded once
#: before the pool forks its workers from this process
#: (a module a task imports lazily, e.g. scikit-learn's K-means in the rollator detector or
#: scipy.signal in the ground truth's filter, would otherwise be imported by every worker)
IMPORTS = {"mtst-trials": ("gaitval.pipeline.mtst",), "detect-trials": ("gaitval.pipeline.mtst",),
           "register-trials": ("gaitval.groundtruth",),
           "ultrasonic-trials": ("gaitval.groundtruth",),
           "rollator-train-subjects": ("gaitval.pipeline.rollator",),
           "rollator-trials": ("gaitval.pipeline.rollator", "sklearn.cluster"),
           "rollator-import-trials": ("gaitval.pipeline.rollator",),
           "legbench-trials": ("gaitval.pipeline.legbench",)}
#: the compiled kernels (modules with a ``warm_up``) each stage's built-in methods run:
#: seed 002's PF on the rollator, seed 003's UKF on the treadmill, the initialisers' motion
#: check in the TUG, MTST and rollator trackers and the people tracker.  A study's own
#: method that runs another kernel loads it in each worker on first use (from numba's
#: cache; slower, not different).
KERNELS = {"track-trials": ("init_motion_kernel",), "mtst-trials": ("init_motion_kernel",),
           "rollator-trials": ("init_motion_kernel", "pf"), "ultrasonic-trials": ("ukf",),
           "legbench-trials": ("init_motion_kernel",)}


def preload(stage: str) -> None:
    """Import the stage's modules (and load its trackers' compiled kernels) in this process,
    so that the workers forked from it start with them: ~1 CPU-s once per job instead of
    once per worker.  Matplotlib is told to draw off-screen through its environment
    variable, so that a stage that draws nothing does not import it."""
    import importlib

    os.environ["MPLBACKEND"] = "Agg"
    for name in ("gaitval.pipeline.steps", "pyarrow.parquet", *IMPORTS.get(stage, ())):
        importlib.import_module(name)
    for name in KERNELS.get(stage, ()):
        importlib.import_module(f"gaitval.track.{name}").warm_up()


#: the options of every stage verb: name -> (argparse keywords, help)
OPTIONS: dict[str, dict] = {
    "trials": dict(nargs="*", default=[], help="the trial ids (rollator-train-subjects: "
                   "the held-out subjects), in the order of every per-trial list"),
    "out": dict(nargs="+", required=True, help="the job's output folder(s), made first: "
                "TRACK EVALUATE for track-trials, import-tracks-trials and mtst-trials"),
    "threads": dict(type=int, default=1, help="trials run at a time (default 1)"),
    "log": dict(default=None, help="the job's log: every trial's command and messages"),
    "sizes": dict(nargs="*", default=None, help="per trial: its input bytes (the largest "
                  "start first)"),
    "sheet": dict(help="the study's trials.csv"),
    "subjects": dict(help="the study's subjects.csv"),
    "config": dict(help="the config view the trials' verbs read"),
    "method": dict(help="the method (or external detector) name"),
    "ingest": dict(help="results/<study>/ingest (one folder per trial)"),
    "register": dict(help="results/<study>/register/<family> (leg-detections-trials: "
                     "results/<study>/register)"),
    "detections": dict(default=None, help="a detect job's folder (<trial>.parquet each) "
                       "the tracks read instead of detecting again"),
    "files": dict(nargs="*", default=None, help="per trial: the external file"),
    "sensors": dict(nargs="*", default=None, help="per trial: the scan log"),
    "models": dict(nargs="*", default=None, help="per trial: the PF model ('-' for none)"),
    "protocols": dict(nargs="*", default=None, help="per trial: its protocol"),
    "mocap_trials": dict(nargs="*", default=[], help="the trials with a registration"),
    "family": dict(choices=["tug", "mtst"], help="the detector's protocol family"),
    "detector": dict(help="the detector spec as JSON"),
    "results": dict(help="results/<study> (rollator-train-subjects)"),
    "noise": dict(help="the noise identification JSON (ultrasonic-trials)"),
    "topic": dict(default="", help="the bag topic of the detections (leg-detections)"),
    "init": dict(default="own", choices=["own", "annotation"],
                 help="legbench-trials: the tracks' initialisation"),
    "match_m": dict(type=float, default=0.75, help="legbench-trials: CLEAR-MOT's match "
                    "distance (m)"),
    "min_false_s": dict(type=float, default=0.5, help="legbench-trials: the shortest "
                        "false leg track counted (s)"),
}
