"""The papers' example figures (verb ``paper-figures``): one protocol's figures from the
run's per-trial results, read by their place in the results folder.

Per protocol, from the first of the given ``results/<study>`` folders that has its results:

========== ============================================== =================================
protocol   reads                                          writes (figures/)
========== ============================================== =================================
tug        ``evaluate/<m>/<trial>/{frames,events,summary}`` ``tug_fig12.png``,
           for ``tug_m1..3``, ``ingest/<trial>/sensor``    ``tug_fig13.png``
mtst       ``mtst_eval/<m>/<trial>/*``,                    ``mtst_fig6a.png``,
           ``mtst_track/<m>/<trial>``, ingest, register    ``mtst_fig8.png``, ``mtst_fig9.png``
rollator   ``rollator/<kf|pf>/<trial>/frames``, its         ``rollator_fig5.png``
           ``.track.parquet``, ingest
ultrasonic ``ultrasonic/{track,gait}/<trial>.parquet``     ``ultrasonic_fig2..4.png``
========== ============================================== =================================

A figure the run's data cannot give (no tracked trial of the methods it compares) is
written as a PNG that says so (:func:`not_produced`: the workflow declares every figure);
the step stamps what it wrote (``provenance/<protocol>_paper_figures.json``).
"""
from __future__ import annotations

import functools
from pathlib import Path

import pandas as pd

from gaitval.errors import GaitvalError
from gaitval.io.parquet import read_parquet

PROTOCOLS = ("tug", "mtst", "rollator", "ultrasonic")
#: The figures each protocol's step can write (the workflow's declared outputs).
FIGURES = {"tug": ["tug_fig12", "tug_fig13"],
           "mtst": ["mtst_fig6a", "mtst_fig8", "mtst_fig9"],
           "rollator": ["rollator_fig5"],
           "ultrasonic": ["ultrasonic_fig2", "ultrasonic_fig3", "ultrasonic_fig4"]}


def _concat(paths) -> pd.DataFrame:
    dfs = [d for d in (read_parquet(p) for p in paths) if len(d)]
    return pd.concat(dfs, ignore_index=True) if dfs else pd.DataFrame()


@functools.lru_cache(maxsize=8)
def _scans(path: str):
    from gaitval.io.scanlog import read_scanlog
    return read_scanlog(path)


def _scans_of(study_dir: Path):
    def get(trial: str):
        p = study_dir / "ingest" / str(trial) / "sensor.parquet"
        return _scans(str(p)) if p.is_file() else None
    return get


def _truth_of(study_dir: Path):
    def get(trial: str):
        hits = sorted((study_dir / "register").glob(f"*/{trial}/groundtruth.parquet"))
        if not hits:
            return None
        g = read_parquet(hits[0])
        return g[g["valid"].astype(bool)] if "valid" in g else g
    return get


def _obs_of(study_dir: Path, family: str, scans_of, sheet, subjects):
    """``(trial, method) -> observations``: the method's detector (its config view's
    definition, :func:`gaitval.pipeline.detections.method_detector`) run on the trial's
    scans with the leg width its track step uses; None for a method that detects scan by
    scan, or without the trial sheet and subject table."""
    if not sheet or not subjects:
        return None
    from gaitval.detect import DETECTORS
    from gaitval.pipeline.detections import method_detector
    from gaitval.pipeline.steps.config import load_json
    from gaitval.pipeline.steps.tracking import tug_leg_width
    from gaitval.pipeline.steps.trials import trial_and_subject

    def get(trial: str, method: str):
        view = study_dir / "config_views" / family / f"{method}.json"
        cfg = load_json(view if view.is_file() else study_dir / "config.json")
        spec = method_detector(cfg, method)
        scans = scans_of(trial)
        if spec is None or scans is None:
            return None
        _, subj = trial_and_subject(sheet, subjects, trial)
        width = (tug_leg_width(subj, cfg) if family == "tug"
                 else float(subj["leg_width_m"]))
        return DETECTORS.build(spec).detect(scans, float(width))
    return get


def tug_figures(study_dir: Path, out: Path, methods=("tug_m1", "tug_m2", "tug_m3"),
                sheet=None, subjects=None):
    from gaitval.report.paper_figures_tug import write_tug_paper_figures

    dirs = [d for m in methods for d in sorted((study_dir / "evaluate" / m).glob("*/"))]
    if not dirs:
        return None
    frames, events, summary = (_concat(d / f"{n}.parquet" for d in dirs
                                       if (d / f"{n}.parquet").is_file())
                               for n in ("frames", "events", "summary"))
    if len(summary) and "category" in summary:
        summary = summary[summary["category"].astype(str) != "not_registered"]
    if frames.empty:
        return []
    scans_of = _scans_of(study_dir)
    return write_tug_paper_figures(frames, events, summary, scans_of, out,
                                   _obs_of(study_dir, "tug", scans_of, sheet, subjects))


def mtst_figures(study_dir: Path, out: Path, config_json=None,
                 methods=("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed"), sheet=None,
                 subjects=None):
    from gaitval.evaluate.mtst_trial import settings
    from gaitval.report.paper_figures_mtst import write_mtst_paper_figures

    dirs = [d for m in methods for d in sorted((study_dir / "mtst_eval" / m).glob("*/"))]
    if not dirs:
        return None
    data = {n: _concat(d / f"{n}.parquet" for d in dirs if (d / f"{n}.parquet").is_file())
            for n in ("contacts", "targets", "events", "summary", "gates")}
    tracks = _concat(p for m in methods
                     for p in sorted((study_dir / "mtst_track" / m).glob("*.parquet")))
    from gaitval.pipeline.steps.config import load_json
    s = settings(load_json(config_json) if config_json else {})
    full = _scans_of(study_dir)
    kept: dict[str, object] = {}

    def scans_of(trial: str):           # the scans the MTST methods track (mtst.scan_period_s)
        from gaitval.pipeline.mtst import keep_every
        if trial not in kept:
            sc = full(trial)
            kept[trial] = (keep_every(sc, float(s["scan_period_s"]), trial=trial)
                           if sc is not None else None)
        return kept[trial]
    return write_mtst_paper_figures(data, tracks, scans_of, _truth_of(study_dir), out, s,
                                    _obs_of(study_dir, "mtst", scans_of, sheet, subjects))


def rollator_figures(study_dir: Path, out: Path, kf="rollator_kf", pf="rollator_pf"):
    from gaitval.report.paper_figures_rollator import write_rollator_paper_figures

    dirs = [d for m in (kf, pf) for d in sorted((study_dir / "rollator" / m).glob("*/"))]
    if not dirs:
        return None
    frames = _concat(d / "frames.parquet" for d in dirs if (d / "frames.parquet").is_file())
    tracks = _concat(p for m in (kf, pf)
                     for p in sorted((study_dir / "rollator" / m).glob("*.track.parquet")))
    if frames.empty:
        return []
    return write_rollator_paper_figures(frames, tracks, _scans_of(study_dir), out, kf, pf)


def ultrasonic_figures(study_dir: Path, out: Path, config_json=None):
    from gaitval.pipeline.steps.config import load_json
    from gaitval.report.paper_figures_ultrasonic import write_ultrasonic_paper_figures

    gait = sorted((study_dir / "ultrasonic" / "gait").glob("*.parquet"))
    if not gait:
        return None
    tracks = {p.stem: read_parquet(p)
              for p in sorted((study_dir / "ultrasonic" / "track").glob("*.parquet"))}
    cfg = (load_json(config_json).get("ultrasonic") or {}) if config_json else {}
    return write_ultrasonic_paper_figures(tracks, _concat(gait), out, cfg)


def paper_figures_step(protocol: str, results_dirs, figures_dir, reports_dir,
                       config_hash: str = "", config_json=None, sheet=None,
                       subjects=None) -> list[Path]:
    """One protocol's figures (module table) from the first results folder with its
    results; stamps what it wrote.  ``sheet`` and ``subjects`` (that study's trial sheet
    and subject table) give the leg widths the TUG and MTST detectors ran with, so the
    snapshots show the methods' observations; without them they are left out.  Raises
    when no folder has the protocol's results."""
    from gaitval.report.provenance import stamp

    if protocol not in PROTOCOLS:
        raise GaitvalError(f"paper-figures: unknown protocol {protocol!r}; known: "
                           f"{', '.join(PROTOCOLS)}")
    out = Path(figures_dir)
    make = {"tug": lambda d: tug_figures(d, out, sheet=sheet, subjects=subjects),
            "mtst": lambda d: mtst_figures(d, out, config_json, sheet=sheet,
                                           subjects=subjects),
            "rollator": lambda d: rollator_figures(d, out),
            "ultrasonic": lambda d: ultrasonic_figures(d, out, config_json)}[protocol]
    for d in map(Path, results_dirs):
        paths = make(d)
        if paths is not None:
            made = {p.stem for p in paths}
            paths += [not_produced(out / f"{stem}.png", stem, d.name)
                      for stem in FIGURES[protocol] if stem not in made]
            stamp(f"{protocol}_paper_figures", paths, reports_dir, config_hash_=config_hash)
            return paths
    raise GaitvalError(f"paper-figures: no {protocol} results under "
                       f"{', '.join(map(str, results_dirs))}")


def not_produced(path: Path, stem: str, study: str) -> Path:
    """A PNG that says the figure could not be drawn from this run (the workflow declares
    every figure, so one the data cannot give is a statement, not a missing file)."""
    from gaitval.report.figures import plt, save_figure

    fig, ax = plt.subplots(figsize=(6, 1.6))
    ax.axis("off")
    ax.text(0.5, 0.5, f"{stem}: not drawn — study {study} has no trial showing the "
            "situation\n(no tracked trial of the methods it compares, or no contact near a "
            "target)", ha="center", va="center", fontsize=9, wrap=True)
    return save_figure(fig, path)
