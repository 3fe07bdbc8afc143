"""Provenance: per step (command, configuration hash, version, git commit) and per report.

Each pipeline step that writes report items calls :func:`stamp`, which writes one JSON
record ``<report>/provenance/<step>.json`` listing the items it produced and how.  The
report index (:mod:`gaitval.report.index`) names that record beside every item.

Once per report (:func:`write_report_provenance`, called when the index is built) the
folder ``<report>/provenance/`` also gets what a reviewer needs to rerun it elsewhere:

* ``config.yaml``: the resolved configuration (written by the workflow); its hash is
  ``report.json``'s ``config_hash``.  Each ``<step>.json`` has the hash of the part of it
  that step read (its config view, ``results/<study>/config_views/``), so the two differ.
* ``inputs.sha256``: every raw input file of the pooled studies (the workflow lists them
  in ``inputs.txt``), paths relative to the working folder (the checkout), so
  ``sha256sum -c reports/<run>/provenance/inputs.sha256`` there works on any machine.
* ``requirements.lock``: the repository's hashed lock file the environment was built
  from (``python3 run.py`` installs it), and ``environment.txt``: the versions actually
  installed (gaitval itself left out), with ``report.json`` saying whether they are the
  lock's.
* ``tables.sha256``: the tables (``tables/``), relative to the report folder.
* ``reproduce.sh``: clones the repository at the commit, builds the environment from the
  lock, reruns the report's command and checks the inputs and tables against the two
  manifests.
* ``report.json``: git commit, repository, versions, and the command that rebuilt it.

No wall-clock time is recorded, so reruns with the same inputs stay byte-identical.
"""
from __future__ import annotations

import hashlib
import json
import os
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


def source_digest(package: Path | None = None) -> str:
    """First 12 hex digits of the SHA-256 over gaitval's own files: every file of the
    package (its code and its data, e.g. the leg forests), by relative path and content,
    ``__pycache__`` left out.  The workflow puts it in every job's config-view params, so
    a change of gaitval's code (a new version, an edited method) reruns the jobs whose
    results it could change, as a change of the config does; a rerun with the same code
    and config still does nothing."""
    root = Path(package) if package is not None else Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for f in sorted(p for p in root.rglob("*")
                    if p.is_file() and "__pycache__" not in p.parts):
        h.update(f.relative_to(root).as_posix().encode() + b"\0")
        h.update(hashlib.sha256(f.read_bytes()).digest())
    return h.hexdigest()[:12]


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
    # an absolute path of this machine, relative to the working folder (portable records)
    argv = [relative_path(a) if _is_local_path(a) else a for a in argv]
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


def relative_path(path: str | Path, start: str | Path | None = None) -> str:
    """``path`` relative to ``start`` (default: the working folder), ``../`` where it is
    outside, so that a manifest checks on another machine with the same layout.  Symbolic
    links are kept (``../shared`` stays ``../shared`` when it links elsewhere)."""
    return Path(os.path.relpath(os.path.abspath(path),
                                os.path.abspath(start or os.getcwd()))).as_posix()


#: Distributions a plain ``pip install -r`` does not take from a lock: the project itself
#: and pip's own tools.
_NOT_LOCKED = {"gaitval", "pip", "setuptools", "wheel"}


def _norm(name: str) -> str:
    return name.lower().replace("_", "-").replace(".", "-")


def environment_lines() -> list[str]:
    """``name==version`` of every installed distribution but gaitval and pip's tools
    (``pip freeze`` style: installable with ``pip install -r``)."""
    from importlib.metadata import distributions

    seen = {}
    for d in distributions():
        name = (d.metadata["Name"] or "").strip()
        if name and _norm(name) not in _NOT_LOCKED:
            seen.setdefault(name.lower(), f"{name}=={d.version}")
    return [seen[k] for k in sorted(seen)]


def lock_versions(text: str) -> dict[str, str]:
    """``{normalised name: version}`` of a pip-compile lock file."""
    out = {}
    for ln in text.splitlines():
        if "==" in ln and not ln.startswith((" ", "#", "-")):
            name, ver = ln.split("==", 1)
            out[_norm(name.strip())] = ver.split()[0].rstrip("\\").strip().split(";")[0]
    return out


def environment_vs_lock(env: list[str], lock_text: str) -> dict:
    """What of the installed ``env`` (``name==version`` lines) differs from the lock."""
    locked = lock_versions(lock_text)
    have = {_norm(n): v for n, v in (ln.split("==", 1) for ln in env)}
    return {"differ": sorted(f"{n}=={have[n]} (lock {locked[n]})" for n in have
                             if n in locked and have[n] != locked[n]),
            "not_in_lock": sorted(f"{n}=={have[n]}" for n in have if n not in locked),
            "missing": sorted(f"{n}=={locked[n]}" for n in locked if n not in have)}


def tables_manifest(reports_dir: str | Path) -> str:
    """``sha256sum`` lines of every file under ``<reports_dir>/tables``, relative to the
    report folder."""
    rd = Path(reports_dir)
    files = sorted(p for p in (rd / "tables").rglob("*") if p.is_file())
    return "".join(f"{sha256_file(p)}  {p.relative_to(rd).as_posix()}\n" for p in files)


def git_origin(repo: Path = REPO) -> str:
    """The repository the checkout was cloned from (``remote.origin.url``), else its own
    folder."""
    try:
        url = subprocess.run(["git", "-C", str(repo), "remote", "get-url", "origin"],
                             capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        url = ""
    return url or str(repo)


def is_remote_url(url: str) -> bool:
    """A repository address another machine can clone (``https://``, ``ssh://``,
    ``git@host:path``), not a folder of this machine."""
    import re

    return bool(re.match(r"^[A-Za-z][A-Za-z0-9+.-]*://", url)
                or re.match(r"^[\w.-]+@[\w.-]+:", url))


def reproduce_script(rec: dict, reports_rel: str, repo_from_prov: str | None = None) -> str:
    """``reproduce.sh``: a new checkout of the commit, the environment from the lock,
    the report's command, then its inputs and tables checked against the manifests.

    Every value is quoted for the shell (:func:`shlex.quote`), outside any double quotes.
    The repository defaults to the report's ``repository`` when that is an address
    another machine can clone, else to the checkout found from the script's own folder
    (``repo_from_prov``: the checkout relative to ``provenance/``); the script holds no
    absolute path of the machine that built it."""
    commit = str(rec.get("git_commit", "unknown"))
    plain = commit.removesuffix("+dirty")
    args = shlex.split(rec.get("command") or "python3 run.py report")
    keep, skip = [], False
    for a in args:                        # the new checkout is the working folder
        if skip:
            skip = False
        elif a == "--directory":
            skip = True
        elif not a.startswith("--directory="):
            keep.append(a)
    command = " ".join(shlex.quote(a) for a in keep)
    q = shlex.quote
    origin = str(rec.get("repository") or "")
    if is_remote_url(origin):
        repo_line = f"REPO=${{1:-{q(origin)}}}"
    else:
        rel = repo_from_prov or "../../.."
        repo_line = ('REPO=${1:-$(cd "$PROV"/' + q(rel) + ' 2>/dev/null && git rev-parse '
                     '--show-toplevel 2>/dev/null || true)}')
    lines = [
        "#!/usr/bin/env bash",
        f"# Rebuild the gaitval report {reports_rel!r} from nothing and check that its",
        "# inputs and tables are identical: a new checkout of the commit, the environment",
        "# built from the hashed lock, the report's own command.  Written by gaitval",
        "# (gaitval/report/provenance.py).",
        "#",
        "#   bash reproduce.sh [REPOSITORY] [FOLDER]",
        "#",
        "# REPOSITORY  gaitval's git repository, a URL or a folder (default: the one the",
        "#             report was made from, found relative to this script when it was a",
        "#             folder)",
        "# FOLDER      a new folder for the checkout (default: ./gaitval-<commit>); data the",
        "#             studies read from outside the checkout (../shared/...) must sit",
        "#             beside it as they did beside the original",
        "set -euo pipefail",
        'PROV=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)',
        f"COMMIT={q(plain)}",
        repo_line,
        'if [ -z "$REPO" ]; then echo "reproduce.sh: no gaitval repository found beside '
        'this report; give it: bash reproduce.sh REPOSITORY [FOLDER]" >&2; exit 2; fi',
        f"DEST=${{2:-{q('gaitval-' + plain[:12])}}}",
        'if [ -e "$DEST" ]; then echo "reproduce.sh: $DEST exists; name a new folder" >&2;'
        " exit 2; fi",
    ]
    if commit.endswith("+dirty"):
        lines.append('echo "reproduce.sh: the report was made from a checkout with '
                     'uncommitted changes; the commit alone may not rebuild it" >&2')
    lines += [
        'git clone --quiet "$REPO" "$DEST"',
        'cd "$DEST"',
        'git -c advice.detachedHead=false checkout --quiet "$COMMIT"',
        "# the environment: run.py builds .venv from requirements.lock, the report's lock",
        'cmp -s requirements.lock "$PROV/requirements.lock" || '
        '{ echo "reproduce.sh: requirements.lock at $COMMIT is not the one the report '
        'was made with" >&2; exit 1; }',
        command,
        'sha256sum -c --quiet "$PROV/inputs.sha256"',
        f'(cd {q(reports_rel)} && sha256sum -c --quiet "$PROV/tables.sha256")',
        # the values as printf's arguments, each quoted: none is ever read as shell code
        "printf 'reproduce.sh: inputs and tables identical to those of the report "
        "(%s/%s)\\n' \"$DEST\" " + q(reports_rel),
    ]
    return "\n".join(lines) + "\n"


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
        rec["config_hash_note"] = (
            "config_hash: the whole resolved configuration (provenance/config.yaml); a "
            "step record's config_hash: the part of it that step read (its config view)")
    lock = REPO / "requirements.lock"
    if lock.is_file():
        text = lock.read_text(encoding="utf-8")
        write_text(prov / "requirements.lock", text)
        diff = environment_vs_lock(env, text)
        rec.update(lock="provenance/requirements.lock",
                   lock_sha256=hashlib.sha256(text.encode()).hexdigest(),
                   environment_is_lock=not (diff["differ"] or diff["missing"]),
                   environment_vs_lock=diff)
    write_text(prov / "tables.sha256", tables_manifest(reports_dir))
    rec.update(environment="provenance/environment.txt", n_distributions=len(env),
               git_commit=git_commit(), repository=_portable_origin(reports_dir),
               gaitval_version=__version__, python=platform.python_version(),
               platform=f"{platform.system()} {platform.machine()}",
               tables="provenance/tables.sha256", reproduce="provenance/reproduce.sh")
    rel = relative_path(reports_dir)
    write_text(prov / "reproduce.sh",
               reproduce_script(rec, rel, relative_path(REPO, prov.resolve())))
    os.chmod(prov / "reproduce.sh", 0o755 & ~_umask())
    write_text(prov / "report.json", json.dumps(rec, indent=1, sort_keys=True) + "\n")
    return rec


def _portable_origin(reports_dir) -> str:
    """The repository for ``report.json``: its clone address when it has one another
    machine can reach, else the checkout relative to the report folder (no absolute path
    of this machine in a report)."""
    origin = git_origin()
    if is_remote_url(origin):
        return origin
    return relative_path(origin if Path(origin).is_dir() else REPO,
                         Path(reports_dir).resolve())


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


# -- what the workflow hands over -------------------------------------------------------
def study_input_files(sheet: str | Path, subjects: str | Path, trials) -> list[str]:
    """The raw files of one study: trial sheet, subject table, ``study.yaml`` and
    ``external.yaml`` beside the sheet, and each trial's mocap, sensor and annotation file (``trials``: the validated
    trial sheet, :func:`gaitval.io.trialsheet.load_trial_sheet`)."""
    files = [str(sheet), str(subjects)]
    for name in ("study.yaml", "external.yaml"):   # external.yaml: external trackers and
        if (Path(sheet).parent / name).is_file():  # detectors (issue 37)
            files.append(str(Path(sheet).parent / name))
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
    base, work = Path(repo).resolve(), Path(workdir).resolve()

    def portable(path, start=base) -> str:     # relative: no absolute path of this machine
        return relative_path(path, start) if Path(path).is_absolute() else str(path)

    if work != base:                             # run.py works in the checkout
        args += ["--directory", portable(workdir)]
    for f in configfiles:
        args += ["--configfile", portable(f)]
    if overrides:                                # Snakemake reads these in the work folder
        args.append("--config")
        args += [f"{k}={portable(v, work) if _is_local_path(v) else v}"
                 if isinstance(v, str) else f"{k}={json.dumps(v)}"
                 for k, v in overrides.items()]
    return " ".join(shlex.quote(a) for a in args)


def _portable(value):
    """``value`` (a resolved config) with every string that is an absolute path of this
    machine made relative to the working folder, as Snakemake reads it there: no report
    holds the building machine's absolute paths."""
    if isinstance(value, dict):
        return {k: _portable(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_portable(v) for v in value]
    return relative_path(value) if _is_local_path(value) else value


def _is_local_path(value) -> bool:
    """An absolute path of an existing file or folder (a --config value such as
    ``peer_results=/home/me/...``): written relative instead."""
    if not isinstance(value, str) or not value.startswith(("/", "\\")) and ":" not in value:
        return False
    try:
        return Path(value).is_absolute() and Path(value).exists()
    except (OSError, ValueError):
        return False


def write_workflow_record(config: dict, inputs, output, log: str, *, command: str,
                          chash: str) -> None:
    """The workflow's half of a report's provenance (rule ``report_config``): the resolved
    config as YAML (``output.config``), the list of input files (``output.inputs``) and
    the rebuild command (``output.rebuild``)."""
    import yaml

    resolved = _portable(json.loads(json.dumps(config, default=str)))
    write_text(output.config, yaml.safe_dump(resolved, sort_keys=True))
    write_text(output.inputs, "".join(f"{relative_path(p)}\n" for p in inputs))
    write_text(output.rebuild, json.dumps(
        {"command": command, "studies": list(config.get("run", [])),
         "config_hash": chash}, indent=1, sort_keys=True) + "\n")
    write_text(log, f"{len(list(inputs))} input files listed in {output.inputs}\n")
