"""CPU of a study's TUG and MTST tracks with and without the shared detections (issue 38).

Usage::

    .venv/bin/python benchmarks/shared_detections.py --directory <a finished run folder>

In one process, ``--repeat`` times (the two ways in turn, the first first on odd
repeats, second first on even ones: the process's file memos favour the later one): every trial of the run's study tracked by
every method whose detector another method shares (the run's own plan:
``results/<study>/detect/<family>/<detector>/``), (a) each method detecting itself, as
the track verb does without ``--detections``, and (b) the detector run once per trial
(the ``detect`` verb's step) and every method tracking from that file.  Prints the CPU
seconds of (a) and (b) per family and repeat; the tracks of (a) and (b) are compared
byte for byte.  One process, so the comparison is not blurred by the run's scheduling;
on a shared machine CPU seconds still move by some per cent with the load.
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path


def _runs(run: Path, study: str, family: str):
    """(trial, sensor, [methods], detector spec) of each trial the run detected once."""
    import pandas as pd

    from gaitval.pipeline.detections import method_detector

    res = run / "results" / study
    views = res / "config_views" / family
    folders = sorted((res / "detect" / family).iterdir())
    methods_of = {}
    for view in sorted(views.glob("*.json")):
        if view.stem == "study":
            continue
        spec = method_detector(json.loads(view.read_text()), view.stem)
        if spec is not None:
            methods_of.setdefault(json.dumps(spec, sort_keys=True), []).append(view.stem)
    sheet = run / "data" / study / "trials.csv"
    trials = sorted(pd.read_csv(sheet).query("protocol == @family")["trial"])
    out = []
    for folder in folders:
        probe = next(folder.glob("*.parquet"))
        import pyarrow.parquet as pq
        spec = json.loads(pq.read_schema(probe).metadata[b"gaitval.detector"])
        methods = methods_of[json.dumps(spec, sort_keys=True)]
        out.append((spec, methods, trials))
    return out, sheet


def _track(family, run, study, sheet, trial, method, out, detections=None):
    from gaitval.pipeline import mtst
    from gaitval.pipeline.steps import tracking as steps

    res = run / "results" / study
    subjects = sheet.parent / "subjects.csv"
    view = res / "config_views" / family / f"{method}.json"
    if family == "tug":
        steps.track_step(res / "ingest" / trial / "sensor.parquet", sheet, subjects, trial,
                         method, view, out, detections=detections)
    else:
        reg = res / "register" / trial / "registration.json"
        mtst.mtst_track_step(res / "ingest" / trial / "sensor.parquet", sheet, subjects,
                             trial, method, view, reg if reg.is_file() else None, out,
                             detections=detections)


def _detect(family, run, study, sheet, trial, spec, out):
    from gaitval.pipeline import mtst
    from gaitval.pipeline.steps import tracking as steps

    res = run / "results" / study
    view = res / "config_views" / family / "study.json"
    step = steps.detect_step if family == "tug" else mtst.mtst_detect_step
    step(res / "ingest" / trial / "sensor.parquet", sheet, sheet.parent / "subjects.csv",
         trial, json.dumps(spec), view, out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--directory", type=Path, required=True)
    ap.add_argument("--study", default="default")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    run = args.directory.resolve()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for family in ("tug", "mtst"):
            groups, sheet = _runs(run, args.study, family)
            for r in range(args.repeat):
                cpu = {}
                for mode in (("own", "shared") if r % 2 == 0 else ("shared", "own")):
                    c0 = time.process_time()
                    for spec, methods, trials in groups:
                        for trial in trials:
                            det = None
                            if mode == "shared":
                                det = tmp / f"{trial}.det.parquet"
                                _detect(family, run, args.study, sheet, trial, spec, det)
                            for m in methods:
                                _track(family, run, args.study, sheet, trial, m,
                                       tmp / f"{mode}-{m}-{trial}.parquet", det)
                    cpu[mode] = time.process_time() - c0
                same = all((tmp / f"own-{p.name[len('shared-'):]}").read_bytes()
                           == p.read_bytes() for p in tmp.glob("shared-*.parquet"))
                n = sum(len(m) * len(t) for _, m, t in groups)
                print(f"{family} repeat {r + 1}: {n} tracks of "
                      f"{sum(len(m) for _, m, _ in groups)} methods: each method detects "
                      f"{cpu['own']:.2f} cpu-s, detected once per trial {cpu['shared']:.2f} "
                      f"cpu-s ({cpu['shared'] - cpu['own']:+.2f}); tracks byte-identical: "
                      f"{same}", flush=True)


if __name__ == "__main__":
    main()
