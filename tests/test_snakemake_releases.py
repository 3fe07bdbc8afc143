"""The workflow on the two Snakemake releases pyproject.toml allows (``snakemake>=8.0``):
the newest 8.x and the newest 9.x on the package index (issue 38).  9.x is the one
requirements.lock installs into ``.venv``; 8.x goes into ``.venv-snakemake8`` beside it
(made here on first use, ~15 s: a venv whose own site-packages hold Snakemake 8 and the
packages it needs in other versions, and that sees ``.venv``'s packages after them, so
numpy, pandas and gaitval are the same).  Each runs a dry run and the tiny study; the
tables of the two runs are byte-identical.  The 9.x run is the session's ``tiny_run`` and
the 8.x run ``tiny_run_snakemake8`` (tests/conftest.py), which other tests read too."""
from __future__ import annotations

import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
from conftest import SNAKEMAKE, tiny_workflow

ROOT = Path(__file__).resolve().parents[1]
#: the newest Snakemake 8 on the package index (2026-11)
SNAKEMAKE_8 = "8.30.0"
VENV_8 = ROOT / ".venv-snakemake8"


def snakemake_8() -> Path:
    """``.venv-snakemake8/bin/snakemake`` at :data:`SNAKEMAKE_8`, made if missing (by one
    process at a time: pytest-xdist's workers may both ask)."""
    import hashlib
    import tempfile

    from filelock import FileLock

    key = hashlib.sha256(str(VENV_8).encode()).hexdigest()[:12]
    with FileLock(str(Path(tempfile.gettempdir()) / f"gaitval-venv-snakemake8-{key}.lock")):
        return _snakemake_8()


def _snakemake_8() -> Path:
    py = VENV_8 / "bin" / "python"
    check = [str(py), "-c", "import snakemake, gaitval; print(snakemake.__version__)"]
    # (from another folder than the checkout: gaitval must come from the venv, not cwd)
    if py.exists():
        got = subprocess.run(check, capture_output=True, text=True, cwd="/")
        if got.returncode == 0 and got.stdout.strip() == SNAKEMAKE_8:
            return VENV_8 / "bin" / "snakemake"
    subprocess.run([sys.executable, "-m", "venv", "--clear", str(VENV_8)], check=True)
    own = subprocess.run([str(py), "-c", "import sysconfig; "
                          "print(sysconfig.get_paths()['purelib'])"],
                         capture_output=True, text=True, check=True).stdout.strip()
    # after its own site-packages: this venv's (numpy, pandas, gaitval, ...), as a site
    # folder, so that its own .pth files (gaitval's editable install) count too
    Path(own, "zz-gaitval-venv.pth").write_text(
        f"import site; site.addsitedir({sysconfig.get_paths()['purelib']!r})\n")
    subprocess.run([str(py), "-m", "pip", "install", "--quiet", f"snakemake=={SNAKEMAKE_8}"],
                   check=True, timeout=900)
    got = subprocess.run(check, capture_output=True, text=True, check=True, cwd="/")
    assert got.stdout.strip() == SNAKEMAKE_8, got
    return VENV_8 / "bin" / "snakemake"


@pytest.fixture(scope="module")
def releases():
    return {"9": SNAKEMAKE, "8": snakemake_8()}


def version_of(snakemake: Path) -> str:
    return subprocess.run([str(snakemake), "--version"], capture_output=True, text=True,
                          check=True).stdout.strip()


@pytest.mark.slow
@pytest.mark.parametrize("release", ["8", "9"])
def test_dry_run(releases, release, tmp_path):
    version = version_of(releases[release])
    assert version.split(".")[0] == release, version
    res = tiny_workflow(tmp_path, "-n", snakemake=releases[release])
    assert res.returncode == 0, res.stderr[-3000:]
    assert "simulate" in res.stdout and "report" in res.stdout, res.stdout[-3000:]


@pytest.mark.slow
def test_the_tiny_study_on_both_releases_gives_the_same_tables(releases, tiny_run,
                                                               tiny_run_snakemake8):
    assert version_of(releases["9"]).split(".")[0] == "9"
    tables = {}
    for release, work in (("8", tiny_run_snakemake8), ("9", tiny_run)):
        found = sorted((work / "reports" / "tiny" / "tables").glob("*.csv"))
        assert len(found) >= 10, (release, found)
        assert (work / "reports" / "tiny" / "index.html").is_file(), release
        tables[release] = {p.name: p.read_bytes() for p in found}
    assert tables["8"] == tables["9"]
