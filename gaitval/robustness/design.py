"""The robustness ensemble's twins: free choices of the twin drawn jointly over their
plausible ranges by a seeded Latin hypercube (``scipy.stats.qmc.LatinHypercube``; the
two-or-more-way choices as a full factorial when the twins allow it), each twin written as
a study preset and declared as a study of the workflow.

``config/robustness.yaml`` names the factors (docs/robustness.md, "Plausible ranges" and
"The ensemble"); :func:`design` draws the table of twins, :func:`twin_presets`
turns each row into the base preset with those choices, :func:`write_ensemble` writes
the presets (``config/studies/<ensemble>/<twin>.yaml``) and a Snakemake config file that
declares every twin as a simulated study (``--configfile``), so a twin is an ordinary
study of the workflow (locally or on a cluster profile).
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import math
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from scipy.stats import qmc

from gaitval.errors import ConfigError
from gaitval.io.atomic import write_text

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "config" / "robustness.yaml"
PRESET_DIR = ROOT / "config" / "studies"
#: The MTST mat's goal end and half width (m; gaitval.simulate.mtst).
MTST_GOAL_X_M, MTST_HALF_WIDTH_M = 5.85, 0.575
#: The MTST sensor's plausible places (docs/robustness.md): on the walking line 0.5-1.5 m
#: beyond the goal facing the walker, or beside the mat 0.8-1.5 m from its edge at
#: x = 2.0 m looking across it.
MTST_PLACES = {"line": (0.5, 1.5), "beside": (0.8, 1.5)}
#: The TUG turn marker (the sensor looks at it; gaitval.simulate.tug.TUG_MARKER_XY).
TUG_MARKER_XY = (3.0, 0.0)


def load_config(path: str | Path | None = None) -> dict:
    """The ensemble's configuration (``config/robustness.yaml`` by default), checked."""
    p = Path(path) if path else CONFIG
    if not p.is_file():
        raise ConfigError("no robustness configuration", path=p,
                          hint="config/robustness.yaml names n_twins, design_seed, factors")
    cfg = yaml.safe_load(p.read_text(encoding="utf-8")) or {}
    for key in ("n_twins", "design_seed", "base_preset", "factors"):
        if key not in cfg:
            raise ConfigError(f"robustness configuration lacks {key!r}", path=p)
    for name, f in cfg["factors"].items():
        if sum(k in f for k in ("range", "choices", "integer")) != 1:
            raise ConfigError(f"factor {name!r} needs exactly one of range, choices, "
                              "integer", path=p)
    cfg["_path"] = str(p)
    return cfg


def _value(spec: dict, u: float):
    """A factor's value at the unit-cube coordinate ``u``."""
    if "range" in spec:
        lo, hi = (float(v) for v in spec["range"])
        return lo + u * (hi - lo)
    if "choices" in spec:
        ch = list(spec["choices"])
        return ch[min(int(u * len(ch)), len(ch) - 1)]
    lo, hi = (int(v) for v in spec["integer"])
    return int(lo + min(int(u * (hi - lo + 1)), hi - lo))


def design(cfg: dict) -> pd.DataFrame:
    """One row per twin (index: the twin's study name), one column per factor: a Latin
    hypercube of ``n_twins`` points over the factors, seeded by ``design_seed``; the
    ``choices`` factors, when ``n_twins`` is a multiple of the number of their
    combinations, as a full factorial instead (:func:`_factorial_choices`)."""
    names = list(cfg["factors"])
    n = int(cfg["n_twins"])
    if n < 1:
        raise ConfigError(f"n_twins must be >= 1, got {n}", path=cfg.get("_path"))
    u = qmc.LatinHypercube(d=len(names), seed=int(cfg["design_seed"])).random(n)
    rows = [{nm: _value(cfg["factors"][nm], float(u[i, j])) for j, nm in enumerate(names)}
            for i in range(n)]
    for row, combo in zip(rows, _factorial_choices(cfg, n)):
        row.update(combo)
    prefix = str(cfg.get("name_prefix", "rob"))
    return pd.DataFrame(rows, index=pd.Index([f"{prefix}_{i:02d}" for i in range(n)],
                                             name="twin"))


def _factorial_choices(cfg: dict, n: int) -> list[dict]:
    """The ``choices`` factors as a full factorial replicated ``n / (number of
    combinations)`` times, rows in a seeded random order; ``[]`` (keep the hypercube's
    draws) when ``n`` is not a multiple of the number of combinations.

    A Latin hypercube balances each factor alone but pairs two choices at random: with 16
    twins, 14 paired the MTST sensor on the line with the attendant on the left, so the
    two could not be told apart.  In a full factorial every combination of the choices
    occurs equally often, so a choice's share is never another's."""
    choice = {nm: list(f["choices"]) for nm, f in cfg["factors"].items() if "choices" in f}
    combos = list(itertools.product(*choice.values()))
    if not choice or n % len(combos):
        return []
    order = np.random.default_rng(int(cfg["design_seed"])).permutation(n)
    full = combos * (n // len(combos))
    return [dict(zip(choice, full[i])) for i in order]


def _set(preset: dict, dotted: str, value) -> None:
    node = preset
    *path, last = dotted.split(".")
    for k in path:
        node = node.setdefault(k, {})
    node[last] = value.item() if hasattr(value, "item") else value


def _poses(preset: dict, row: dict) -> None:
    """The composed factors: the TUG sensor looking at the marker from (behind, lateral),
    the MTST sensor at its place and distance, the MTST target rows' spacing range shifted
    (gaitval.simulate.mtst.TARGETS_DEFAULT's 1.0-1.4 m by -0.2 to +0.2 m: rows 0.8-1.6 m
    apart)."""
    if "mtst" in preset and "mtst_target_row_shift_m" in row:
        from gaitval.simulate.mtst import TARGETS_DEFAULT

        d = float(row["mtst_target_row_shift_m"])
        preset["mtst"].setdefault("targets", {})["row_spacing_m"] = [
            round(v + d, 4) for v in TARGETS_DEFAULT["row_spacing_m"]]
    if "tug" in preset and {"tug_sensor_behind_m", "tug_sensor_lateral_m"} <= row.keys():
        x, y = float(row["tug_sensor_behind_m"]), float(row["tug_sensor_lateral_m"])
        yaw = math.atan2(TUG_MARKER_XY[1] - y, TUG_MARKER_XY[0] - x)
        preset["tug"]["sensor_nominal_pose"] = [round(x, 4), round(y, 4), round(yaw, 4)]
    if "mtst" in preset and "mtst_sensor_place" in row:
        place = row["mtst_sensor_place"]
        lo, hi = MTST_PLACES[place]
        d = lo + float(row.get("mtst_sensor_distance", 0.5)) * (hi - lo)
        pose = ([MTST_GOAL_X_M + d, 0.0, math.pi] if place == "line"
                else [2.0, MTST_HALF_WIDTH_M + d, -math.pi / 2])
        preset["mtst"]["sensor_nominal_pose"] = [round(v, 4) for v in pose]


def twin_presets(cfg: dict, base: dict, table: pd.DataFrame) -> dict[str, dict]:
    """Each twin's preset: ``base`` with its row's choices (a protocol the base lacks is
    left out, so are its factors)."""
    out = {}
    for twin, row in table.iterrows():
        p = copy.deepcopy(base)
        p["study"] = twin
        for name, spec in cfg["factors"].items():
            where = spec.get("set")
            if where and (where.split(".")[0] in p or "." not in where):
                _set(p, where, row[name])
        _poses(p, row.to_dict())
        out[twin] = p
    return out


def ensemble_name(cfg: dict) -> str:
    """``robustness_<8 hex>``: a digest of the configuration and the base preset, so a
    changed design never reuses another design's twins."""
    base = (PRESET_DIR / f"{cfg['base_preset']}.yaml").read_bytes()
    body = yaml.safe_dump({k: v for k, v in cfg.items() if k != "_path"}, sort_keys=True)
    return "robustness_" + hashlib.sha256(body.encode() + base).hexdigest()[:8]


def write_ensemble(cfg: dict, out_dir: str | Path) -> tuple[pd.DataFrame, Path]:
    """Write the twins' presets, ``design.csv`` and the Snakemake config file declaring
    the twins as studies (``<out_dir>/ensemble.yaml``); return the design and that file."""
    from gaitval.simulate.study import load_preset

    table = design(cfg)
    name = ensemble_name(cfg)
    presets = twin_presets(cfg, load_preset(cfg["base_preset"]), table)
    studies = {}
    for twin, p in presets.items():
        write_text(PRESET_DIR / name / f"{twin}.yaml", yaml.safe_dump(p, sort_keys=False))
        studies[twin] = {"simulate": {"preset": f"{name}/{twin}", "seed": int(p["seed"])}}
    out = Path(out_dir)
    write_text(out / "design.csv", table.to_csv())
    conf = write_text(out / "ensemble.yaml", yaml.safe_dump({"studies": studies},
                                                            sort_keys=True))
    return table, conf


def read_design(out_dir: str | Path) -> pd.DataFrame:
    """The design an ensemble wrote (``<out_dir>/design.csv``)."""
    f = Path(out_dir) / "design.csv"
    if not f.is_file():
        raise ConfigError("no design of a robustness ensemble here", path=f,
                          hint="gaitval robustness design --out DIR writes it")
    return pd.read_csv(f, index_col="twin")


def coded(table: pd.DataFrame, cfg: dict) -> pd.DataFrame:
    """The design as numbers for a rank correlation: a choice by its place in the
    factor's ``choices`` (0 for the first), a numeric factor as it is."""
    out = {}
    for c in table.columns:
        spec = cfg["factors"].get(c, {})
        if "choices" in spec:
            out[c] = table[c].map({v: i for i, v in enumerate(spec["choices"])})
        else:
            out[c] = table[c]
    return pd.DataFrame(out, index=table.index).astype(np.float64)
