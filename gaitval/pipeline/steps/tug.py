"""TUG steps: evaluate one tracked trial against its ground truth; gather the evaluations into
seed 000's tables and figures.
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from gaitval.io.atomic import write_parquet
from gaitval.io.parquet import read_parquet
from gaitval.pipeline.memo import FileMemo
from gaitval.pipeline.steps.config import load_json, method_definition, method_overrides


#: A trial's TUG phase bounds and true stance intervals, by its ground truth's identity and
#: the evaluation settings: the same for all six tracks of a trial.
_TRUTH_PHASES = FileMemo(16 * 2 ** 20)


def evaluate_tug_step(track_parquet, gt_parquet, registration_json, trial: str, method: str,
                      config_json, out_dir) -> pd.DataFrame:
    """Evaluate one tracked TUG trial against its registered ground truth.

    Writes ``frames.parquet``, ``events.parquet``, ``stance.parquet`` and
    ``summary.parquet`` (see :func:`gaitval.evaluate.tug.evaluate_tug_trial`).  A trial whose
    registration was refused gets an empty evaluation and ``category = not_registered``.
    """
    from gaitval.evaluate.tug import FRAME_COLUMNS, evaluate_tug_trial, truth_phases_of

    cfg = load_json(config_json)
    rec = load_json(registration_json)
    out = Path(out_dir)
    if rec.get("status") != "ok":
        res = {"frames": pd.DataFrame(columns=list(FRAME_COLUMNS)),
               "events": pd.DataFrame(columns=["trial", "method", "side", "kind"]),
               "stance": pd.DataFrame(columns=["trial", "method", "side", "identified"]),
               "summary": pd.DataFrame([{"trial": trial, "method": method, "success": False,
                                         "category": "not_registered"}])}
    else:
        track = read_parquet(track_parquet).drop(columns=["trial", "method"])
        gt = read_parquet(gt_parquet)
        ecfg = (cfg.get("evaluation") or {}).get("tug")
        phases = _TRUTH_PHASES.fetch(
            _TRUTH_PHASES.key(gt_parquet, json.dumps(ecfg, sort_keys=True, default=str)),
            lambda: truth_phases_of(gt, ecfg), lambda _: 4096)
        res = evaluate_tug_trial(track, gt, trial=trial, method=method, cfg=ecfg,
                                 truth_phases=(dict(phases[0]), phases[1].copy()))
    for name, df in res.items():
        write_parquet(df.reset_index(drop=True), out / f"{name}.parquet")
    return res["summary"]


def tug_tables_step(eval_dirs: list[str | Path], tables_dir, figures_dir, reports_dir,
                    config_hash: str = "", methods=("tug_m1", "tug_m2", "tug_m3"),
                    configs: list[str | Path] | None = None) -> list[Path]:
    """Gather per-trial TUG evaluations into seed 000 Tables 2-5 and the figures.

    Table 2 shows the method definitions actually run: ``tracking.methods`` and
    ``tracking.overrides`` of each study's ``config.json`` or of its method views
    ``results/<study>/config_views/tug/<method>.json`` (``configs``, which the workflow
    gives: the views, so that another section's change does not rerun these tables; default
    ``results/<study>/config.json`` above the ``evaluate/<method>/<trial>`` folders).  A
    method run with different parameters in different studies gets one set of rows per
    study, labelled ``<method> (<study>)``.
    """
    from gaitval.report.provenance import stamp
    from gaitval.report.tug_figures import write_tug_figures
    from gaitval.tables.tug import write_tug_tables

    frames, summaries, events = _gathered(eval_dirs)
    # Table 2: the definitions each study ran (config-defined methods, overrides applied)
    if configs is None:
        configs = [Path(d).parents[2] / "config.json" for d in eval_dirs
                   if len(Path(d).parents) > 2]
    used = _definitions_run(methods, _study_configs(configs))
    paths = write_tug_tables(frames, summaries, tables_dir, methods=used)
    stamp("tug_tables", paths, reports_dir, config_hash_=config_hash)
    figs = write_tug_figures(frames, summaries, events, figures_dir)
    stamp("tug_figures", figs, reports_dir, config_hash_=config_hash)
    return paths + figs


def _gathered(eval_dirs) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """The per-trial TUG evaluations' frames, summaries (trials not registered left out)
    and events, each pooled over ``eval_dirs``."""
    from gaitval.evaluate.tug import FRAME_COLUMNS

    parts: dict[str, list[pd.DataFrame]] = {"frames": [], "summary": [], "events": []}
    for d in eval_dirs:
        for name in parts:
            df = read_parquet(Path(d) / f"{name}.parquet")
            if len(df):
                parts[name].append(df)
    empty = {"frames": pd.DataFrame(columns=list(FRAME_COLUMNS)),
             "summary": pd.DataFrame(columns=["trial", "method", "success", "category"]),
             "events": pd.DataFrame(columns=["trial", "method", "side", "kind", "t_start_s",
                                             "t_end_s", "tug_phase"])}
    frames, summaries, events = (pd.concat(parts[n], ignore_index=True) if parts[n]
                                 else empty[n] for n in ("frames", "summary", "events"))
    summaries = summaries[summaries.get("category", "") != "not_registered"] \
        if len(summaries) else summaries
    return frames, summaries, events


def _study_configs(configs) -> dict[str, dict]:
    """study -> its config: a study's ``config.json``, or its method views merged
    (``tracking.methods``, ``overrides``, ``external``); ``{"": {}}`` without any."""
    found = sorted({Path(c) for c in configs if Path(c).is_file()})
    cfgs: dict[str, dict] = {}
    for c in found:                      # a study's config.json, or its views merged
        views = [p for p in c.parents if p.name == "config_views"]   # <study>/config_views/
        study = views[0].parent.name if views else c.parent.name
        cfg = load_json(c)
        if study not in cfgs:
            cfgs[study] = cfg
            continue
        tracking = cfgs[study].setdefault("tracking", {})
        for key in ("methods", "overrides", "external"):
            tracking[key] = {**(tracking.get(key) or {}),
                             **((cfg.get("tracking") or {}).get(key) or {})}
    return cfgs or {"": {}}


def _definitions_run(methods, cfgs: dict[str, dict]) -> dict[str, dict]:
    """Table 2's rows: each of gaitval's methods' definition as run (overrides applied),
    one set of rows per study, labelled ``<method> (<study>)``, where the studies differ;
    external trackers have none."""
    from gaitval.methods import get_method, set_params

    used: dict[str, dict] = {}
    for m in methods:
        if any(m in ((cfg.get("tracking") or {}).get("external") or {})
               for cfg in cfgs.values()):
            continue                    # an external tracker: no parameters of gaitval's
        runs = {study: set_params(get_method(method_definition(cfg, m)),
                                  method_overrides(cfg, m))
                for study, cfg in cfgs.items()}
        distinct = {json.dumps(d, sort_keys=True, default=str) for d in runs.values()}
        if len(distinct) == 1:
            used[m] = next(iter(runs.values()))
        else:
            used.update({f"{m} ({study})": d for study, d in runs.items()})
    return used
