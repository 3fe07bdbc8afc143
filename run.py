#!/usr/bin/env python3
"""gaitval's two commands, for a fresh machine with only Python 3.11+.

    python3 run.py report   # generate the default study (first time), build reports/default/index.html
    python3 run.py test     # run the test suite

Each creates ``.venv`` and installs into it, on first use and again only when
``pyproject.toml`` or ``requirements.lock`` changes, the exact versions of
``requirements.lock`` (hashed, ``pip install --require-hashes``; made with pip-tools, see
the file's head) and then gaitval itself (``pip install --no-deps -e .``).  Extra arguments go to Snakemake
(``report``) or pytest (``test``), e.g. ``python3 run.py report --config 'run=["tiny"]'``.
``report`` prints one line per finished step (Snakemake's full output goes to its log file,
named at the start and the end); ``report -v`` (or ``GAITVAL_CONSOLE=raw``) shows
Snakemake's own console instead.
Also: ``python3 run.py bench benchmarks/NAME.py`` (installs the benchmark-only extras), and
``python3 run.py sensitivity`` (the default report beside the same study under each
alternative free choice of the simulated replica: ``reports/default/tables/sensitivity.*``).
``python3 run.py robustness [--ensemble FILE]`` (twins of the default study drawn over the
free choices' plausible ranges, config/robustness.yaml: ``reports/robustness/robustness.*``).

Resuming after a kill (power cut, killed cluster job): ``report`` finds Snakemake's lock
left behind in ``.snakemake/locks``; when no live Snakemake works in this folder it
removes it (``snakemake --unlock``), ends the job processes the dead run left behind
(they would keep writing; a job's processes also end by themselves with their Snakemake,
``gaitval/jobs/lifeline.py``), and goes on.  The workflow then removes the outputs the
dead run left marked incomplete before Snakemake plans (``gaitval/jobs/resume.py``), so
the jobs that were cut off run again, and the report rule refuses to write the index while
a table or figure is missing: the tables come out byte-identical to an uninterrupted run.
"""
from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PY = BIN / ("python.exe" if os.name == "nt" else "python")


#: The exact, hashed versions of gaitval's dependencies and its test extra
#: (``pip-compile --generate-hashes --extra test``; the file's head has the command).
LOCK = ROOT / "requirements.lock"


def ensure_env(extras: str) -> None:
    if sys.version_info < (3, 11):
        sys.exit(f"gaitval needs Python 3.11 or newer (this is {sys.version.split()[0]})")
    lock = LOCK.read_bytes() if LOCK.is_file() else b""
    key = hashlib.sha256((ROOT / "pyproject.toml").read_bytes() + lock
                         + extras.encode()).hexdigest()
    stamp = VENV / f".gaitval-installed-{extras or 'base'}"
    if PY.exists() and stamp.exists() and stamp.read_text() == key:
        return
    if not PY.exists():
        print(f"[run.py] creating {VENV} ...", flush=True)
        venv.EnvBuilder(with_pip=True).create(VENV)
    pip = [str(PY), "-m", "pip", "install", "--quiet"]
    if lock:
        # the locked versions, each file checked against its hash, then gaitval itself
        print(f"[run.py] installing {LOCK.name} into {VENV} (first run only) ...", flush=True)
        subprocess.run([*pip, "--require-hashes", "--no-deps", "-r", str(LOCK)], check=True)
        subprocess.run([*pip, "--no-deps", "-e", str(ROOT)], check=True)
        rest = [e for e in extras.split(",") if e and e != "test"]   # test is locked
        if rest:                                  # e.g. bench: on top, not locked
            subprocess.run([*pip, "-e", f"{ROOT}[{','.join(rest)}]"], check=True)
    else:
        print(f"[run.py] installing gaitval[{extras}] into {VENV} (first run only) ...",
              flush=True)
        subprocess.run([*pip, "-e", f"{ROOT}[{extras}]" if extras else str(ROOT)],
                       check=True)
    # the particle filter's, the UKF's and the motion check's numba kernels, compiled into
    # their cache now (~15 s CPU) rather than by each worker of the first report (warm_up
    # in gaitval/track/pf.py, ukf.py and init_motion_kernel.py)
    print("[run.py] compiling the trackers' kernels (first run only) ...", flush=True)
    subprocess.run([str(PY), "-c", "from gaitval.track import init_motion_kernel, pf, ukf; "
                    "pf.warm_up(); ukf.warm_up(); init_motion_kernel.warm_up()"], check=False)
    stamp.write_text(key)


# -- resuming after a kill ---------------------------------------------------------------
def _workdir(args: list[str]) -> Path:
    """The folder Snakemake works in: --directory/-d, else this checkout."""
    for i, a in enumerate(args):
        if a in ("--directory", "-d") and i + 1 < len(args):
            return Path(args[i + 1]).resolve()
        if a.startswith("--directory="):
            return Path(a.split("=", 1)[1]).resolve()
    return ROOT


def _processes() -> dict[int, tuple[int, str, str]]:
    """pid -> (parent pid, command line, working folder) of the processes we may see."""
    out = {}
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            cmd = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            ppid = int((d / "stat").read_text().rsplit(")", 1)[1].split()[1])
            cwd = os.readlink(d / "cwd")
        except (OSError, ValueError, IndexError):
            continue
        out[int(d.name)] = (ppid, cmd, cwd)
    return out


def _is_snakemake(cmd: str) -> bool:
    words = cmd.split()[:3]
    return any(Path(w).name.startswith("snakemake") for w in words) or \
        "-m snakemake" in cmd


def clear_stale_lock(cmd: list[str], env: dict, workdir: Path) -> bool:
    """Remove a lock no live Snakemake holds, and the dead run's job processes.

    Returns False when another Snakemake is working in ``workdir`` (it says so)."""
    locks = workdir / ".snakemake" / "locks"
    if "--unlock" in cmd or not locks.is_dir() or not any(locks.iterdir()):
        return True
    if not Path("/proc").is_dir():
        print("[run.py] .snakemake/locks holds a lock; if no Snakemake is running here, "
              "run: python3 run.py report --unlock", flush=True)
        return True
    procs, me = _processes(), os.getpid()
    here = str(workdir)
    live = [p for p, (_, c, cwd) in procs.items() if p != me and cwd == here and _is_snakemake(c)]
    if live:
        print(f"[run.py] another Snakemake (pid {live[0]}) is working in {here}; wait for "
              "it to finish, or stop it first", flush=True)
        return False
    _end_orphans(procs, here)
    print("[run.py] removing a stale Snakemake lock (no Snakemake is running here; a "
          "previous run was killed) and resuming", flush=True)
    subprocess.run([*cmd, "--unlock"], env=env, check=False, stdout=subprocess.DEVNULL)
    return True


def _end_orphans(procs: dict, here: str) -> None:
    """End job shells of a dead Snakemake run in ``here`` (Snakemake starts every shell
    job with ``set -euo pipefail``) and what they started, so nothing keeps writing."""
    orphans = {p for p, (_, c, cwd) in procs.items()
               if cwd == here and "set -euo pipefail" in c and "-m gaitval" in c}
    changed = True
    while changed:                                   # and their descendants
        new = {p for p, (pp, _, _) in procs.items() if pp in orphans} - orphans
        changed = bool(new)
        orphans |= new
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for p in orphans:
            try:
                os.kill(p, sig)
            except OSError:
                pass
        if orphans and sig == signal.SIGTERM:
            time.sleep(2)
    if orphans:
        print(f"[run.py] ended {len(orphans)} job process(es) left by the killed run",
              flush=True)


def ensure_pdflatex_on_ci() -> None:
    """On CI (``CI=true``, as root, with apt-get) install pdflatex from Debian's packages
    (texlive-latex-recommended, -extra; about 2 minutes), so the tests that compile every
    table as a page run instead of skipping (tests/test_latex_compile.py, issue 35).  On
    anybody else's machine nothing is installed: those tests skip with the reason."""
    import shutil
    if (os.environ.get("CI", "").lower() != "true" or shutil.which("pdflatex")
            or os.name == "nt" or os.geteuid() != 0 or not shutil.which("apt-get")):
        return
    print("[run.py] CI: installing pdflatex (texlive-latex-recommended, -extra) ...",
          flush=True)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    ok = subprocess.call(["apt-get", "update", "-qq"], env=env,
                         stdout=subprocess.DEVNULL) == 0 and subprocess.call(
        ["apt-get", "install", "-y", "-qq", "--no-install-recommends",
         "texlive-latex-recommended", "texlive-latex-extra"], env=env,
        stdout=subprocess.DEVNULL) == 0
    if not ok:
        print("[run.py] could not install pdflatex; the LaTeX compile tests will skip",
              flush=True)


#: The twin's free choices varied by ``run.py sensitivity`` (docs/simulator.md, "Free
#: choices of the twin"): one study per alternative, defined in config/config.yaml.
SENSITIVITY_STUDIES = ("mtst_sensor_beside", "mtst_attendant_left", "tug_sit_turn_right")


def sensitivity(rest: list[str], env: dict) -> int:
    """The default report, the same study under each alternative free choice, and the
    table of verdicts beside each other (reports/default/tables/sensitivity.*), then the
    default report's index again so it shows that table."""
    ensure_env("test")
    rest, logger = console_args(rest, env)
    for name in ("default", *SENSITIVITY_STUDIES):
        cmd = [str(BIN / "snakemake"), "--profile", "workflow/profiles/default", *logger,
               "--config", f'run=["{name}"]', *rest]
        print("[run.py] " + " ".join(cmd), flush=True)
        if not clear_stale_lock(cmd, env, _workdir(rest)):
            return 1
        rc = subprocess.call(cmd, env=env)
        if rc:
            return rc
    steps = [[str(PY), "-m", "gaitval", "sensitivity", "reports/default",
              *[f"reports/{s}" for s in SENSITIVITY_STUDIES],
              "--out", "reports/default/tables/sensitivity"],
             [str(PY), "-m", "gaitval", "report", "--reports-dir", "reports/default",
              "--studies", "default"]]
    for cmd in steps:
        print("[run.py] " + " ".join(cmd), flush=True)
        rc = subprocess.call(cmd, env=env)
        if rc:
            return rc
    print("[run.py] report: reports/default/index.html (section: sensitivity)", flush=True)
    return 0


def robustness(rest: list[str], env: dict) -> int:
    """The robustness ensemble (docs/robustness.md;
    ``gaitval robustness``): twins drawn from ``--ensemble FILE`` (default
    config/robustness.yaml), each twin's report built by the workflow as any study's
    (reports/robustness/twins/), the table reports/robustness/robustness.*, then the base
    study's report again so its verdicts show the shares.  Other arguments go to Snakemake
    (e.g. another profile)."""
    import json

    ensure_env("test")
    pick = []
    if "--ensemble" in rest:
        i = rest.index("--ensemble")
        pick, rest = ["--config", rest[i + 1]], rest[:i] + rest[i + 2:]
    rest, logger = console_args(rest, env)
    cmd = [str(PY), "-m", "gaitval", "robustness", "run", *pick, "--snakemake",
           "--profile", "workflow/profiles/default", *logger, *rest]
    print("[run.py] " + " ".join(cmd), flush=True)
    plain = [str(BIN / "snakemake"), "--profile", "workflow/profiles/default", *rest]
    if not clear_stale_lock(plain, env, _workdir(rest)):
        return 1
    rc = subprocess.call(cmd, env=env)
    if rc:
        return rc
    record = Path("reports/robustness/robustness.json")
    if {"-n", "--dry-run", "--dryrun"} & set(rest) or not record.is_file():
        return 0                                              # a dry run: no table
    base = json.loads(record.read_text(encoding="utf-8"))["base_study"]
    if not Path(f"reports/{base}/verdicts.csv").is_file():
        print(f"[run.py] reports/{base} is not built; its verdicts show the shares after "
              f"python3 run.py report --config 'run=[\"{base}\"]'", flush=True)
    else:
        cmd = [str(PY), "-m", "gaitval", "report", "--reports-dir", f"reports/{base}",
               "--studies", base]
        print("[run.py] " + " ".join(cmd), flush=True)
        rc = subprocess.call(cmd, env=env)
    print("[run.py] robustness table: reports/robustness/robustness.html", flush=True)
    return rc


def _has_logger_plugins() -> bool:
    """Whether the environment's Snakemake takes logger plugins (Snakemake 9; 8 has none,
    and then its own console is the one there is)."""
    return subprocess.call([str(PY), "-c", "import snakemake_interface_logger_plugins"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) == 0


def console_args(rest: list[str], env: dict) -> tuple[list[str], list[str]]:
    """Snakemake's arguments without ``-v``/``--verbose``, and the logger to add.

    By default Snakemake's console is gaitval's (``--logger gaitval``,
    ``snakemake_logger_plugin_gaitval``: one line per finished step, errors and refusals
    highlighted; Snakemake's full output in its log file).  ``-v``/``--verbose`` or
    ``GAITVAL_CONSOLE=raw`` give Snakemake's own console back.  Snakemake finds a logger
    plugin by its top-level package name, which an editable install hides, so the
    checkout goes on ``PYTHONPATH`` (``env``, changed in place)."""
    raw = {"-v", "--verbose"}
    if any(a in raw for a in rest) or os.environ.get("GAITVAL_CONSOLE", "") == "raw" \
            or any(a == "--logger" or a.startswith("--logger=") for a in rest) \
            or not _has_logger_plugins():
        return [a for a in rest if a not in raw], []
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", ""))
                                        if p)
    return rest, ["--logger", "gaitval"]


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in ("report", "test", "bench", "sensitivity", "robustness"):
        print(__doc__)
        return 2
    verb, rest = argv[0], argv[1:]
    accept_refusals = "--accept-refusals" in rest
    rest = [a for a in rest if a != "--accept-refusals"]
    os.chdir(ROOT)
    env = dict(os.environ, MPLBACKEND="Agg", PATH=f"{BIN}{os.pathsep}{os.environ['PATH']}")
    if verb == "sensitivity":
        return sensitivity(rest, env)
    if verb == "robustness":
        return robustness(rest, env)
    if verb == "report":
        ensure_env("test")
        rest, logger = console_args(rest, env)
        cmd = [str(BIN / "snakemake"), "--profile", "workflow/profiles/default", *logger,
               *rest]
        if not clear_stale_lock(cmd, env, _workdir(rest)):
            return 1
    elif verb == "test":
        ensure_env("test")
        ensure_pdflatex_on_ci()
        cmd = [str(PY), "-m", "pytest", *xdist_args(rest), *rest]
    else:
        ensure_env("test,bench")
        cmd = [str(PY), *rest]
    target = _workdir(rest) / "logs" / "run_target.json"
    if verb == "report" and target.is_file():
        target.unlink()                   # rewritten by the workflow as it reads its config
    print("[run.py] " + " ".join(cmd), flush=True)
    rc = subprocess.call(cmd, env=env)
    if verb == "report" and rc == 0:
        index = _report_index(rest)
        if index is not None and index.is_file():
            print(f"[run.py] report: {index}", flush=True)
        if not any(a in ("-n", "--dry-run", "--dryrun") for a in rest):
            rc = closing_summary(target, accept_refusals)
    return rc



def xdist_args(rest: list[str]) -> list[str]:
    """pytest-xdist's options ``test`` adds: one worker per core, each test file on one
    worker (a module's fixture, e.g. a workflow run, is built once), the longest files
    first, unless the arguments
    choose (``-n``, ``--numprocesses``, ``--dist``, ``-p no:xdist``) or ask for a debugger
    or a listing, which want one process."""
    own = ("-n", "--numprocesses", "--dist", "--pdb", "--trace", "--co", "--collect-only",
           "--setup-plan", "--setup-only", "no:xdist")
    if any(a in own or a.startswith(("-n", "--numprocesses=", "--dist=")) for a in rest):
        return []
    # files in the order of tests/conftest.py LONG_FIRST, not xdist's (most tests first)
    return ["-n", "auto", "--dist", "loadfile", "--no-loadscope-reorder"]

#: ``run.py report``'s exit code when the report was built but trials were refused.
EXIT_REFUSED = 3


def closing_summary(target: Path, accept_refusals: bool) -> int:
    """Say how many trials the report analysed and why the others were refused (from the
    report's ``analysed.json``); :data:`EXIT_REFUSED` when any was, unless accepted."""
    import json
    try:
        reports = Path(json.loads(target.read_text())["reports"])
        if not reports.is_absolute():
            reports = target.parent.parent / reports
        rec = json.loads((reports / "analysed.json").read_text())
    except (OSError, ValueError, KeyError, TypeError):
        return 0                               # no report was asked for (a single target)
    total = sum(int(v["trials"]) for v in rec.values())
    done = sum(int(v["analysed"]) for v in rec.values())
    refused = [(st, t, r) for st, v in rec.items() for t, r in v["refused"].items()]
    print(f"[run.py] analysed {done} of {total} trials"
          + (f"; {len(refused)} refused:" if refused else ""), flush=True)
    import textwrap
    for st, t, r in refused:             # wrapped: a reason names the file and the cause
        print(textwrap.fill(f"REFUSED {st}/{t} ({r['protocol']}): {r['reason']}", width=110,
                            initial_indent="[run.py]   ", subsequent_indent="[run.py]     "),
              flush=True)
    if refused and not accept_refusals:
        print(f"[run.py] exit code {EXIT_REFUSED}: the report leaves the refused trials out "
              "(its top box says so); fix them, or accept the refusals with "
              "`python3 run.py report --accept-refusals ...`", flush=True)
        return EXIT_REFUSED
    return 0


def _report_index(args: list[str]) -> Path | None:
    """reports/<run>/index.html of the run the arguments ask for (workflow/rules/common.smk
    names the folder after `run` joined by '+'); None when the arguments are not plain
    enough to tell (a --configfile, a custom reports_dir)."""
    import json
    import re
    if any(a.startswith("--configfile") for a in args):
        return None
    run = None
    for a in args:
        if a.startswith("reports_dir="):
            return None
        if a.startswith("run="):
            try:
                run = json.loads(a[4:])
            except ValueError:
                return None
    if run is None:
        m = re.search(r"^run:\s*\[([^\]]*)\]", (ROOT / "config" / "config.yaml").read_text(),
                      re.M)
        run = [w.strip().strip("'\"") for w in m.group(1).split(",")] if m else None
    if not run or not all(isinstance(r, str) for r in run):
        return None
    return _workdir(args) / "reports" / "+".join(run) / "index.html"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
