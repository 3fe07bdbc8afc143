"""Provenance of every table and figure: command, configuration hash, version, git commit.

Each pipeline step that writes report items calls :func:`stamp`, which writes one JSON
record ``reports/provenance/<step>.json`` listing the items it produced and how.  The report
index (:mod:`gaitval.report.index`) shows that record beside every item.  No wall-clock
time is recorded, so reruns with the same inputs stay byte-identical.
"""
from __future__ import annotations

import hashlib
import json
import shlex
import subprocess
import sys
from pathlib import Path

from gaitval import __version__
from gaitval.io.atomic import write_text

REPO = Path(__file__).resolve().parents[2]


def config_hash(config: dict) -> str:
    """First 12 hex digits of the SHA-256 of the canonical JSON of ``config``."""
    text = json.dumps(config, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def git_commit(repo: Path = REPO) -> str:
    """``git rev-parse HEAD`` of the checkout (``+dirty`` if tracked files changed).

    Returns ``"unknown"`` outside a git checkout.
    """
    try:
        head = subprocess.run(["git", "-C", str(repo), "rev-parse", "HEAD"],
                              capture_output=True, text=True, timeout=10, check=True
                              ).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(repo), "status", "--porcelain",
                                "--untracked-files=no"], capture_output=True, text=True,
                               timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head + ("+dirty" if dirty else "")


def command_line(argv: list[str] | None = None) -> str:
    """The command as a user would retype it (``gaitval <verb> ...``)."""
    argv = list(sys.argv if argv is None else argv)
    if argv and (argv[0].endswith("__main__.py") or argv[0].endswith("/gaitval")):
        argv[0] = "gaitval"
    return " ".join(shlex.quote(a) for a in argv)


def stamp(step: str, items: list[str | Path], reports_dir: str | Path, *,
          config_hash_: str = "", command: str | None = None) -> Path:
    """Write ``<reports_dir>/provenance/<step>.json`` for the report ``items``."""
    reports_dir = Path(reports_dir)
    rel = sorted(str(Path(p).resolve().relative_to(reports_dir.resolve()))
                 if Path(p).resolve().is_relative_to(reports_dir.resolve()) else str(p)
                 for p in items)
    rec = {"step": step, "items": rel, "command": command or command_line(),
           "config_hash": config_hash_, "gaitval_version": __version__,
           "git_commit": git_commit()}
    return write_text(reports_dir / "provenance" / f"{step}.json",
                      json.dumps(rec, indent=1, sort_keys=True) + "\n")


def load_all(reports_dir: str | Path) -> dict[str, dict]:
    """Map each report item (path relative to ``reports_dir``) to its provenance record."""
    out: dict[str, dict] = {}
    for p in sorted((Path(reports_dir) / "provenance").glob("*.json")):
        rec = json.loads(p.read_text())
        for item in rec.get("items", []):
            out[item] = rec
    return out
