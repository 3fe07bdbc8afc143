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


def test_the_workflow_builds_its_dag_without_scipy(repo_root):
    """Snakemake imports gaitval's config checks, method registries and step constants to
    build the DAG, on one core before the first job (the simulation) can start: those
    imports pull no scipy (~0.5 s of scipy.stats, optimize and spatial before, issue 38).
    The modules are the ones `workflow/rules/*.smk` import at their top."""
    import re
    import subprocess
    import sys

    names = set()
    for smk in sorted((repo_root / "workflow" / "rules").glob("*.smk")):
        for line in smk.read_text().splitlines():
            m = re.match(r"from (gaitval[\w.]*) import", line)     # top level only
            if m:
                names.add(m.group(1))
    assert "gaitval.methods" in names
    code = "; ".join(f"import {n}" for n in sorted(names)) + \
        "; import sys; print(sorted({m.split('.')[0] for m in sys.modules}))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=repo_root, timeout=120, check=True).stdout
    assert "'scipy'" not in out and "'sklearn'" not in out and "'matplotlib'" not in out
