"""The package's import contracts (.importlinter): stages import one way, the simulator is
never needed by an analysis stage, no cycles.  A back-edge fails here, so it fails CI."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_are_kept():
    proc = subprocess.run(
        [sys.executable, "-c", "import sys; from importlinter.cli import lint_imports_command;"
         " sys.exit(lint_imports_command())", "--config", str(ROOT / ".importlinter"),
         "--no-cache"],
        cwd=ROOT, capture_output=True, text=True, timeout=300)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, out
    assert "Contracts: 5 kept, 0 broken" in out, out
