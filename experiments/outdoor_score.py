"""Score the people method on the leg_tracker benchmark's outdoor bag, following mode.

A helper of the issue-36 benchmarks (``people_arrival.py``, ``scan_matching_fallback.py``,
``leg_forest_negatives.py``): the commands of docs/people.md *Results*, run in a
subprocess as a user would run them, with ``tracking.overrides.people`` from a JSON file.
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUTDOOR_BAG = ROOT.parent / "shared" / "realdata" / "lrs" / "person_following_outdoor_1.bag"


def score_outdoor(overrides: dict | None = None, bag: Path = OUTDOOR_BAG) -> str:
    """The summary line ``gaitval legbench-evaluate`` prints for ``gaitval legbench-track
    --method people`` on ``bag`` (``/scan_base2``, ``following_outdoor``) with the people
    method's ``overrides`` (role__param keys)."""
    gv = [sys.executable, "-m", "gaitval"]
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        cfg = d / "cfg.json"
        cfg.write_text(json.dumps({"tracking": {"overrides": {"people": overrides or {}}}}))
        subprocess.run(gv + ["legbench-track", "--sensor", str(bag), "--scan-topic",
                             "/scan_base2", "--method", "people", "--config", str(cfg),
                             "--out", str(d / "t.parquet")], check=True, capture_output=True)
        out = subprocess.run(
            gv + ["legbench-evaluate", "--track", str(d / "t.parquet"), "--annotations",
                  str(bag), "--annotation-topic", "/ground_truth_people_tracks",
                  "--scan-topic", "/scan_base2", "--benchmark-set", "following_outdoor",
                  "--out", str(d / "e")], check=True, capture_output=True, text=True)
    return out.stdout.strip().splitlines()[-1]
