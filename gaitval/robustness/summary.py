"""The robustness table: per verdict, the share of twins that reproduce it, its Wilson
95 % interval, the criterion's class and the free choices that move it most.

The criterion was stated before any ensemble ran (docs/robustness.md, "The
ensemble"): robust (reproduced) when the Wilson lower bound of the share is at least
:data:`ROBUST_SHARE`, robust (not reproduced) when the upper bound is at most
``1 - ROBUST_SHARE``, otherwise the verdict hinges on the set-up.  The choices that move
a verdict are ranked by |Spearman's ρ| (``scipy.stats.spearmanr``) between each choice's
drawn value (:func:`gaitval.robustness.design.coded`) and the verdict being reproduced.
"""
from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import spearmanr
from statsmodels.stats.proportion import proportion_confint

from gaitval.errors import ConfigError
from gaitval.io.atomic import write_text
from gaitval.report.robustness_share import KEY, config_digest
from gaitval.robustness.design import coded
from gaitval.tables.render import write_table

#: The stated criterion (docs/robustness.md): robust when the Wilson 95 % lower bound of
#: the share of reproducing twins is at least this.
ROBUST_SHARE = 0.8
#: How many choices each verdict names.
N_MOVERS = 3


def twin_outcomes(design: pd.DataFrame, reports_dir: str | Path) -> pd.DataFrame:
    """One row per (twin, verdict): the verdict's ``outcome`` in that twin's report
    (``<reports_dir>/<twin>/verdicts.csv``)."""
    frames = []
    for twin in design.index:
        f = Path(reports_dir) / twin / "verdicts.csv"
        if not f.is_file():
            raise ConfigError(f"twin {twin} has no verdicts.csv", path=f,
                              hint="run the ensemble first: python3 run.py robustness")
        v = pd.read_csv(f, keep_default_na=False).drop_duplicates(KEY)
        frames.append(v[KEY + ["outcome"]].assign(twin=twin))
    return pd.concat(frames, ignore_index=True)


def classify(lo: float, hi: float, comparable: int = 1) -> str:
    """The stated criterion's class of a share's 95 % interval; a verdict no twin could
    score (``comparable`` 0) is "not comparable in any twin", not a robust failure."""
    if not comparable:
        return "not comparable in any twin"
    if lo >= ROBUST_SHARE:
        return "robust: reproduced"
    if hi <= 1 - ROBUST_SHARE:
        return "robust: not reproduced"
    return "hinges on the set-up"


#: A choice named ``<protocol>_...`` can move only that protocol's verdicts; another
#: one (the study seed) any protocol's, unless its ``protocols:`` key in the
#: configuration names the ones it acts on (the leg width: the laser protocols).
PROTOCOLS = ("tug", "mtst", "rollator", "ultrasonic")


def relevant(columns, study: str, cfg: dict | None = None) -> list[str]:
    """The design's choices that can move a verdict of ``study``."""
    out = []
    for c in columns:
        spec = ((cfg or {}).get("factors") or {}).get(c) or {}
        acts = spec.get("protocols") or ([c.split("_")[0]] if c.split("_")[0] in PROTOCOLS
                                         else list(PROTOCOLS))
        if study in acts:
            out.append(c)
    return out


def movers(x: pd.DataFrame, y: pd.Series, k: int = N_MOVERS) -> str:
    """The ``k`` choices with the largest |Spearman ρ| against ``y`` (``name ρ=+0.62``),
    or why there are none."""
    if y.nunique() < 2:
        return "none: the same in every twin"
    rho = {}
    for c in x.columns:
        if x[c].nunique() < 2:
            continue
        res = spearmanr(x[c].to_numpy(), y.to_numpy())
        if np.isfinite(res.statistic):
            rho[c] = (float(res.statistic), float(res.pvalue))
    if not rho:
        return "none: no choice varies with it"
    top = sorted(rho, key=lambda c: -abs(rho[c][0]))[:k]
    return "; ".join(f"{c} ρ={rho[c][0]:+.2f}" + (f" (p {rho[c][1]:.2g})"
                                                    if np.isfinite(rho[c][1]) else "")
                     for c in top)


def robustness_table(design: pd.DataFrame, outcomes: pd.DataFrame, cfg: dict
                     ) -> pd.DataFrame:
    """One row per verdict: twins run and reproducing, share, Wilson 95 % interval,
    class, the choices that move it, and the twins' other outcomes counted."""
    x = coded(design, cfg)
    rows = []
    for key, g in outcomes.groupby(KEY, sort=False):
        g = g.set_index("twin").reindex(design.index)
        yes = (g["outcome"] == "reproduced").astype(float)
        n = int(g["outcome"].notna().sum())
        k = int(yes.sum())
        lo, hi = proportion_confint(k, n, alpha=0.05, method="wilson") if n else (0.0, 1.0)
        counts = g["outcome"].value_counts()
        scored = int(g["outcome"].isin(["reproduced", "not reproduced"]).sum())
        rows.append({**dict(zip(KEY, key)), "twins": n, "reproduced_in": k,
                     "share": f"{k}/{n}", "share_frac": k / n if n else np.nan,
                     "ci95_lo": float(lo), "ci95_hi": float(hi),
                     "ci95": f"{lo:.2f}–{hi:.2f}", "robustness": classify(lo, hi, scored),
                     "moved_most_by": movers(x[relevant(x.columns, key[0], cfg)], yes),
                     "outcomes": "; ".join(f"{o} {int(c)}" for o, c in counts.items())})
    return pd.DataFrame(rows)


def protocol_notes(tab: pd.DataFrame) -> list[str]:
    """Per protocol: which verdicts are robust either way, which hinge on a choice (and
    the choice that moves them most), and what that leaves of the paper's claims."""
    out = []
    for study, g in tab.groupby("study", sort=False):
        parts = []
        for cls, what in (("robust: reproduced", "robustly reproduced"),
                          ("robust: not reproduced", "robustly not reproduced"),
                          ("hinges on the set-up", "hinge on the set-up"),
                          ("not comparable in any twin", "not comparable in any twin")):
            h = g[g["robustness"] == cls]
            if len(h):
                names = "; ".join(f"{r.comparison}" + (f" [{r.moved_most_by.split(';')[0]}]"
                                                       if cls == "hinges on the set-up"
                                                       and "ρ=" in r.moved_most_by else "")
                                  for r in h.itertuples())
                parts.append(f"{len(h)} {what} ({names})")
        out.append(f"{study}: " + "; ".join(parts) + ". " + _meaning(g))
    return out


def _meaning(g: pd.DataFrame) -> str:
    """What the classes say about the paper's claims of one protocol."""
    c = g["robustness"].value_counts()
    yes, no = int(c.get("robust: reproduced", 0)), int(c.get("robust: not reproduced", 0))
    hinge = int(c.get("hinges on the set-up", 0))
    said = []
    if yes:
        said.append(f"{yes} of the paper's comparisons hold in every plausible set-up of the "
                    "replica: a property of the methods, not of one set-up")
    if no:
        said.append(f"{no} fail in every plausible set-up: the replica does not support them")
    if hinge:
        said.append(f"{hinge} depend on choices the paper does not report, so the paper's "
                    "data alone cannot settle them")
    return ("; ".join(said) + ".") if said else "No comparison could be scored."


def write_robustness(design: pd.DataFrame, reports_dir: str | Path, cfg: dict,
                     out_dir: str | Path) -> list[Path]:
    """Write ``robustness.{csv,md,tex,html}`` and ``robustness.json`` in ``out_dir``."""
    from gaitval.report.provenance import source_digest

    tab = robustness_table(design, twin_outcomes(design, reports_dir), cfg)
    n = len(design)
    caption = (f"Robustness of every verdict over {n} twins of the {cfg['base_preset']} study "
               "drawn jointly "
               "over the plausible ranges of the twin's free choices (a seeded design: the "
               "two-way choices a full factorial when the twins allow it, the ranges a "
               "Latin hypercube; docs/robustness.md): share of twins reproducing it, "
               "Wilson 95 % interval, class by the stated criterion, and the choices that "
               "move it most (Spearman's ρ between the choice and the verdict).")
    notes = [f"Robust: the Wilson 95 % lower bound of the share ≥ {ROBUST_SHARE} (robust: not "
             f"reproduced: upper bound ≤ {1 - ROBUST_SHARE:.1f}); stated before the ensemble ran.",
             "A twin where a verdict is not comparable counts as not reproducing it.",
             f"Moved most by: Spearman's ρ over the {n} twins with its p-value; with few "
             "twins every varied choice correlates by chance (two twins: ρ = ±1 for all), "
             "so a named choice is a lead to test, not a finding."] + protocol_notes(tab)
    out = Path(out_dir)
    files = write_table(tab, out / "robustness", caption=caption, notes=notes)
    files.append(write_text(out / "robustness.html", _html(tab, caption, notes)))
    meta = {"code_digest": source_digest(), "config_digest": config_digest(cfg.get("_path")),
            "config_path": str(Path(cfg["_path"]).resolve()) if cfg.get("_path") else None,
            "base_study": str(cfg.get("base_study", "default")), "n_twins": n,
            "twins": list(design.index)}
    files.append(write_text(out / "robustness.json", json.dumps(meta, indent=1) + "\n"))
    return files


def _html(tab: pd.DataFrame, caption: str, notes: list[str]) -> str:
    body = tab.to_html(index=False, escape=True, float_format=lambda v: f"{v:.3g}")
    items = "".join(f"<li>{html.escape(n)}</li>" for n in notes)
    return ("<!doctype html><html><head><meta charset='utf-8'><title>Robustness</title>"
            f"</head><body><h1>Robustness ensemble</h1><p>{html.escape(caption)}</p>"
            f"{body}<ul>{items}</ul></body></html>\n")
