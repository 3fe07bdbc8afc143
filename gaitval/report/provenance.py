"""Provenance: per step (command, configuration hash, version, git commit) and per report.

Each pipeline step that writes report items calls :func:`stamp`, which writes one JSON
record ``<report>/provenance/<step>.json`` listing the items it produced and how.  The
report index (:mod:`gaitval.report.index`) names that record beside every item.

Once per report (:func:`write_report_provenance`, called when the index is built) the
folder ``<report>/provenance/`` also gets what a reviewer needs to rerun it:
``config.yaml`` (the resolved configuration, written by the workflow),
``inputs.sha256`` (``sha256sum -c`` format: every raw input file of the pooled studies,
listed by the workflow in ``inputs.txt``), ``environment.txt`` (``pip freeze`` style exact
versions of the installed distributions, from :mod:`importlib.metadata`) and
``report.json`` (git commit, gaitval and Python versions, and the one command that
rebuilds the report, from the workflow's ``rebuild.json``).  No wall-clock time is
recorded, so reruns with the same inputs stay byte-identical.
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
    """Map each report item (path relative to ``reports_dir``) to its step's provenance
    record (with ``record``: the record file, relative to ``reports_dir``)."""
    out: dict[str, dict] = {}
    for p in sorted((Path(reports_dir) / "provenance").glob("*.json")):
        rec = json.loads(p.read_text())
        if not isinstance(rec, dict) or "step" not in rec:
            continue                                  # report.json, rebuild.json
        rec["record"] = f"provenance/{p.name}"
        for item in rec.get("items", []):
            out[item] = rec
    return out


# -- once per report -----------------------------------------------------------------------
def sha256_file(path: str | Path, chunk: int = 1 << 20) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(chunk):
            h.update(block)
    return h.hexdigest()


def input_manifest(paths: list[str | Path]) -> tuple[str, int, int]:
    """``sha256sum``-format lines (``<hex>  <path>``) of every file in ``paths`` (folders,
    e.g. a ROS 2 bag, file by file), sorted by path; also the file count and total bytes.
    A listed path that does not exist is a line ``MISSING  <path>``."""
    files: set[str] = set()
    missing: set[str] = set()
    for p in map(Path, paths):
        if p.is_dir():
            files.update(str(q) for q in p.rglob("*") if q.is_file())
        elif p.is_file():
            files.add(str(p))
        else:
            missing.add(str(p))
    lines = [f"{sha256_file(f)}  {f}" for f in sorted(files)]
    lines += [f"MISSING  {m}" for m in sorted(missing)]
    return "".join(ln + "\n" for ln in lines), len(files), sum(Path(f).stat().st_size
                                                             for f in files)


def environment_lines() -> list[str]:
    """``name==version`` of every installed distribution (``pip freeze`` without pip)."""
    from importlib.metadata import distributions

    seen = {}
    for d in distributions():
        name = (d.metadata["Name"] or "").strip()
        if name:
            seen.setdefault(name.lower(), f"{name}=={d.version}")
    return [seen[k] for k in sorted(seen)]


def write_report_provenance(reports_dir: str | Path) -> dict | None:
    """Write ``inputs.sha256``, ``environment.txt`` and ``report.json`` into
    ``<reports_dir>/provenance`` from the workflow's ``inputs.txt`` and ``rebuild.json``;
    return the ``report.json`` record (None when the workflow wrote neither, e.g. an index
    rebuilt by hand)."""
    import platform

    prov = Path(reports_dir) / "provenance"
    listing, rebuild = prov / "inputs.txt", prov / "rebuild.json"
    if not listing.is_file() and not rebuild.is_file():
        return None
    rec: dict = json.loads(rebuild.read_text()) if rebuild.is_file() else {}
    if listing.is_file():
        paths = [ln for ln in listing.read_text(encoding="utf-8").splitlines() if ln]
        text, n, size = input_manifest(paths)
        write_text(prov / "inputs.sha256", text)
        rec.update(inputs="provenance/inputs.sha256", n_input_files=n, input_bytes=size,
                   inputs_sha256=hashlib.sha256(text.encode()).hexdigest())
    env = environment_lines()
    write_text(prov / "environment.txt", "".join(ln + "\n" for ln in env))
    if (prov / "config.yaml").is_file():
        rec["config"] = "provenance/config.yaml"
    rec.update(environment="provenance/environment.txt", n_distributions=len(env),
               git_commit=git_commit(), gaitval_version=__version__,
               python=platform.python_version(),
               platform=f"{platform.system()} {platform.machine()}")
    write_text(prov / "report.json", json.dumps(rec, indent=1, sort_keys=True) + "\n")
    return rec


# -- what the workflow hands over -------------------------------------------------------
def study_input_files(sheet: str | Path, subjects: str | Path, trials) -> list[str]:
    """The raw files of one study: trial sheet, subject table, ``study.yaml`` beside the
    sheet, and each trial's mocap, sensor and annotation file (``trials``: the validated
    trial sheet, :func:`gaitval.io.trialsheet.load_trial_sheet`)."""
    files = [str(sheet), str(subjects)]
    if (Path(sheet).parent / "study.yaml").is_file():
        files.append(str(Path(sheet).parent / "study.yaml"))
    for col in ("mocap_path", "sensor_path", "annotation_path"):
        if col in trials:
            files += [str(v) for v in trials[col] if isinstance(v, (str, Path)) and str(v)]
    return files


def rebuild_command(configfiles: list[str | Path], overrides: dict, workdir: str | Path,
                    repo: str | Path = REPO) -> str:
    """The one command that rebuilds a report: ``python3 run.py report`` with the
    ``--configfile``/``--config`` the run was given (and ``--directory`` when it did not
    run in the checkout)."""
    args = ["python3", "run.py", "report"]
    if Path(workdir).resolve() != Path(repo).resolve():
        args += ["--directory", str(workdir)]
    for f in configfiles:
        args += ["--configfile", str(f)]
    if overrides:
        args.append("--config")
        args += [f"{k}={v if isinstance(v, str) else json.dumps(v)}"
                 for k, v in overrides.items()]
    return " ".join(shlex.quote(a) for a in args)


def write_workflow_record(config: dict, inputs, output, log: str, *, command: str,
                          chash: str) -> None:
    """The workflow's half of a report's provenance (rule ``report_config``): the resolved
    config as YAML (``output.config``), the list of input files (``output.inputs``) and
    the rebuild command (``output.rebuild``)."""
    import yaml

    resolved = json.loads(json.dumps(config, default=str))
    write_text(output.config, yaml.safe_dump(resolved, sort_keys=True))
    write_text(output.inputs, "".join(f"{Path(p).resolve()}\n" for p in inputs))
    write_text(output.rebuild, json.dumps(
        {"command": command, "studies": list(config.get("run", [])),
         "config_hash": chash}, indent=1, sort_keys=True) + "\n")
    write_text(log, f"{len(list(inputs))} input files listed in {output.inputs}\n")
