"""The robustness ensemble's share beside each verdict of the report it was run for.

``python3 run.py robustness`` writes ``<reports>/robustness/robustness.csv`` and
``robustness.json`` (the code digest, the configuration digest and the study whose
report it annotates).  :func:`share_column` gives each verdict its share of reproducing
twins when that record matches the code and configuration the report is built with, and
``not run`` otherwise: a share of another code or design is never shown.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[2]
KEY = ["study", "comparison", "source"]
NOT_RUN = "not run"


def config_digest(robustness_cfg: str | Path | None = None, repo: Path = REPO) -> str:
    """First 12 hex digits of the SHA-256 over the workflow configuration, the
    ensemble's configuration and every study preset at the top of config/studies."""
    h = hashlib.sha256()
    files = [repo / "config" / "config.yaml",
             Path(robustness_cfg) if robustness_cfg else repo / "config" / "robustness.yaml",
             *sorted((repo / "config" / "studies").glob("*.yaml"))]
    for f in files:
        h.update(f.name.encode() + b"\0")
        h.update(f.read_bytes() if f.is_file() else b"")
    return h.hexdigest()[:12]


def _record(reports_root: Path) -> tuple[dict, pd.DataFrame] | None:
    d = reports_root / "robustness"
    meta, table = d / "robustness.json", d / "robustness.csv"
    if not (meta.is_file() and table.is_file()):
        return None
    return (json.loads(meta.read_text(encoding="utf-8")),
            pd.read_csv(table, keep_default_na=False))


def current(meta: dict) -> bool:
    """The record was made by this code (gaitval's source digest) and configuration."""
    from gaitval.report.provenance import source_digest

    return (meta.get("code_digest") == source_digest()
            and meta.get("config_digest") == config_digest(meta.get("config_path")))


def share_column(verdicts: pd.DataFrame, tables_dir: str | Path) -> list[str]:
    """Per verdict row, ``"k/n (95% CI lo-hi): class"`` from the ensemble of the same code
    and configuration, for the report of the study it was run for; ``not run`` otherwise
    (also for a verdict the ensemble did not compute)."""
    report_dir = Path(tables_dir).parent
    rec = _record(report_dir.parent)
    if (rec is None or rec[0].get("base_study") != report_dir.name
            or not current(rec[0])):
        return [NOT_RUN] * len(verdicts)
    tab = rec[1].drop_duplicates(KEY).set_index(KEY)
    out = []
    for key in verdicts[KEY].itertuples(index=False, name=None):
        if key in tab.index:
            r = tab.loc[key]
            out.append(f"{r['share']} ({r['ci95']}): {r['robustness']}")
        else:
            out.append(NOT_RUN)
    return out
