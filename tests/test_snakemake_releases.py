"""The workflow on the two Snakemake releases pyproject.toml allows (``snakemake>=8.0``):
the newest 8.x and the newest 9.x on the package index (issue 38).  9.x is the one
requirements.lock installs into ``.venv``; 8.x goes into ``.venv-snakemake8`` beside it
(made here on first use, ~15 s: a venv whose own site-packages hold Snakemake 8 and the
packages it needs in other versions, and that sees ``.venv``'s packages after them, so
numpy, pandas and gaitval are the same).  Each runs a dry run and the tiny study; the
tables of the two runs are byte-identical."""
from __future__ import annotations

import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the newest Snakemake 8 on the package index (2026-11)
SNAKEMAKE_8 = "8.30.0"
VENV_8 = ROOT / ".venv-snakemake8"
#: as tests/test_workflow.py: the peer data when ../shared is there, else no such table
PEER = (ROOT / ".." / "shared" / "realdata" / "peer-results" / "gailo_results.parquet").resolve()


def snakemake_8() -> Path:
    """``.venv-snakemake8/bin/snakemake`` at :data:`SNAKEMAKE_8`, made if missing."""
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


def _run(snakemake: Path, work: Path, *extra: str) -> subprocess.CompletedProcess:
    cmd = [str(snakemake), "--snakefile", str(ROOT / "Snakefile"),
           "--profile", str(ROOT / "workflow" / "profiles" / "default"),
           "--directory", str(work), "--cores", "2", "--force-use-threads",
           "--config", 'run=["tiny"]', f"data_dir={work / 'data'}", f"peer_results={PEER}", *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


@pytest.fixture(scope="module")
def releases():
    return {"9": Path(sys.executable).parent / "snakemake", "8": snakemake_8()}


@pytest.mark.slow
@pytest.mark.parametrize("release", ["8", "9"])
def test_dry_run(releases, release, tmp_path):
    version = subprocess.run([str(releases[release]), "--version"], capture_output=True,
                             text=True, check=True).stdout.strip()
    assert version.split(".")[0] == release, version
    res = _run(releases[release], tmp_path, "-n")
    assert res.returncode == 0, res.stderr[-3000:]
    assert "simulate" in res.stdout and "report" in res.stdout, res.stdout[-3000:]


@pytest.mark.slow
def test_the_tiny_study_on_both_releases_gives_the_same_tables(releases, tmp_path):
    tables = {}
    for release in ("8", "9"):
        work = tmp_path / release
        res = _run(releases[release], work)
        assert res.returncode == 0, (release, res.stdout[-3000:] + res.stderr[-3000:])
        found = sorted((work / "reports" / "tiny" / "tables").glob("*.csv"))
        assert len(found) >= 10, (release, found)
        tables[release] = {p.name: p.read_bytes() for p in found}
    assert tables["8"] == tables["9"]
