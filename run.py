#!/usr/bin/env python3
"""gaitval's two commands, for a fresh machine with only Python 3.11+.

    python3 run.py report   # generate the default study (first time) and build reports/index.html
    python3 run.py test     # run the test suite

Each creates ``.venv`` and installs gaitval into it (``pip install -e .[test]``) on first
use, and again only when ``pyproject.toml`` changes.  Extra arguments go to Snakemake
(``report``) or pytest (``test``), e.g. ``python3 run.py report --config 'run=["tiny"]'``.
Also: ``python3 run.py bench benchmarks/NAME.py`` (installs the benchmark-only extras).
"""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PY = BIN / ("python.exe" if os.name == "nt" else "python")


def ensure_env(extras: str) -> None:
    if sys.version_info < (3, 11):
        sys.exit(f"gaitval needs Python 3.11 or newer (this is {sys.version.split()[0]})")
    key = hashlib.sha256((ROOT / "pyproject.toml").read_bytes() + extras.encode()).hexdigest()
    stamp = VENV / f".gaitval-installed-{extras or 'base'}"
    if PY.exists() and stamp.exists() and stamp.read_text() == key:
        return
    if not PY.exists():
        print(f"[run.py] creating {VENV} ...", flush=True)
        venv.EnvBuilder(with_pip=True).create(VENV)
    print(f"[run.py] installing gaitval[{extras}] into {VENV} (first run only) ...", flush=True)
    subprocess.run([str(PY), "-m", "pip", "install", "--quiet", "--upgrade", "pip"],
                   check=True)
    subprocess.run([str(PY), "-m", "pip", "install", "--quiet", "-e",
                    f"{ROOT}[{extras}]" if extras else str(ROOT)], check=True)
    stamp.write_text(key)


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in ("report", "test", "bench"):
        print(__doc__)
        return 2
    verb, rest = argv[0], argv[1:]
    os.chdir(ROOT)
    env = dict(os.environ, MPLBACKEND="Agg", PATH=f"{BIN}{os.pathsep}{os.environ['PATH']}")
    if verb == "report":
        ensure_env("test")
        cmd = [str(BIN / "snakemake"), "--profile", "workflow/profiles/default", *rest]
    elif verb == "test":
        ensure_env("test")
        cmd = [str(PY), "-m", "pytest", *rest]
    else:
        ensure_env("test,bench")
        cmd = [str(PY), *rest]
    print("[run.py] " + " ".join(cmd), flush=True)
    return subprocess.call(cmd, env=env)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
