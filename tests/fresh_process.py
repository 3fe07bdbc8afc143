"""Run test code in a fresh Python process (e.g. to see what numba compiles there)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def run_fresh(code: str, cwd: Path) -> str:
    """Run ``code`` with this interpreter, the tests folder on ``sys.path``; its stdout.
    Fails the test with the end of its stderr when it exits non-zero."""
    head = f"import sys\nsys.path.insert(0, {str(Path(__file__).parent)!r})\n"
    out = subprocess.run([sys.executable, "-c", head + code], capture_output=True,
                         text=True, cwd=cwd, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout
