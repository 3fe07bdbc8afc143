"""Build a report from nothing and print what it cost (the measure of issue 13).

Usage::

    .venv/bin/python benchmarks/report_end_to_end.py --study tiny            # ~1-3 min
    .venv/bin/python benchmarks/report_end_to_end.py --study default --repeat 3
    # the code of another checkout (e.g. a `git worktree` of an older commit):
    PYTHONPATH=/tmp/base .venv/bin/python benchmarks/report_end_to_end.py --root /tmp/base
    # keep the run's folder, then time a rerun with nothing changed in it:
    .venv/bin/python benchmarks/report_end_to_end.py --study default --workdir /tmp/e2e
    cd /tmp/e2e/run0 && time /path/to/.venv/bin/snakemake -s /path/to/Snakefile \
        --cores 2 --config 'run=["default"]' -n

Each repeat runs Snakemake from the checkout's Snakefile with the profile of ``python3 run.py
report`` (``--profile workflow/profiles/default --cores N``) in a fresh temp
dir (fresh data/, results/, reports/, logs/; the venv is not touched), so the simulation
is included.  Afterwards one job of each rule is rerun twice in a hard-linked copy of the
last run's folder (removed afterwards; the run's folder stays as Snakemake left it): once
with its modules' import recorded (``sys.modules`` at exit) and timed, and once as a
process that only imports those modules (``python -c 'import ...'``).  The second is the
job's start-up + import + exit cost; times the rule's job count, summed over the rules,
it is the share of the run's CPU that goes to interpreter start-up and imports.

With the fork server (the default for local runs, ``gaitval/forkserver.py``) the server's
imports are paid once per run and counted once; a job the workflow sent to it from
Snakemake's own thread (``via snakemake`` in the server's log) starts no process (its
~0.1 ms of dispatch is in Snakemake's own CPU); one that went through the small client
(``python -I -S gaitval/forkclient.py``, ``via client``) costs the client's start; one the
server did not run (before it was up, e.g. the simulation) costs the plain start-up.
``--no-fork-server`` runs the plain one-process-per-job shape for comparison.

Prints per repeat ``wall``, ``cpu`` (user + system of all child processes) and the job
count; then the per-rule table and the last line::

    report <study>: wall <median> s, cpu <median> s, <jobs> jobs, start-up+imports <pct> % of cpu
"""
from __future__ import annotations

import argparse
import os
import re
import resource
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# records the modules a job imported, then runs `python -m gaitval ...` as usual
_RECORD = ("import sys, atexit, runpy\n"
           "def _dump(p=sys.argv.pop(1)):\n"
           "    open(p, 'w').write('\\n'.join(m for m in list(sys.modules)))\n"
           "atexit.register(_dump)\n"
           "sys.argv[0] = 'gaitval'\n"
           "runpy.run_module('gaitval', run_name='__main__', alter_sys=True)\n")


# runs Snakemake in this process and prints its own CPU (not its jobs') at exit
_SNAKEMAKE_SELF = ("import atexit, os, runpy, sys\n"
                   "atexit.register(lambda: print('snakemake itself: cpu %.2f s' % "
                   "(os.times().user + os.times().system), file=sys.stderr))\n"
                   "sys.argv[0] = 'snakemake'\n"
                   "runpy.run_module('snakemake', run_name='__main__', alter_sys=True)\n")


def _forked_jobs(log: Path) -> dict[str, list[float]]:
    """verb -> [jobs, cpu s] of the jobs the fork server ran (its log: one line with each
    job's command when it starts, one with its exit, wall and CPU from wait4 when it ends)."""
    verb, out = {}, {}
    if not log.is_file():
        return out
    for line in log.read_text().splitlines():
        m = re.match(r"job ([\d.]+): gaitval (\S+)", line)
        if m:
            verb[m[1]] = m[2]
            continue
        m = re.match(r"job ([\d.]+): exit (-?\d+), wall ([\d.]+) s, cpu ([\d.]+) s", line)
        if m:
            acc = out.setdefault(verb.get(m[1], "?"), [0, 0.0])
            acc[0] += 1
            acc[1] += float(m[4])
    return out


def _cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run_snakemake(root: Path, work: Path, study: str, cores: int, fork_server: bool = True
                   ) -> tuple[float, float, str]:
    # the profile `python3 run.py report` uses (workflow/profiles/default), cores overridden
    cmd = [sys.executable, "-c", _SNAKEMAKE_SELF, "-s", str(root / "Snakefile"),
           "--profile", str(root / "workflow" / "profiles" / "default"),
           "--directory", str(work), "--cores", str(cores), "--config", f'run=["{study}"]']
    if not fork_server:
        cmd.append("fork_server=False")
    c0, t0 = _cpu_children(), time.perf_counter()
    p = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _cpu_children() - c0
    log = p.stdout + p.stderr
    if p.returncode:
        sys.exit(f"snakemake failed ({p.returncode}):\n{log[-4000:]}")
    return wall, cpu, log


def _job_stats(log: str) -> dict[str, int]:
    """rule -> jobs run, from the ``rule X:`` / ``checkpoint X:`` line Snakemake prints per
    job (its 'Job stats' table is printed before a checkpoint adds the per-trial jobs)."""
    counts: dict[str, int] = {}
    for line in log.splitlines():
        m = re.match(r"\s*(?:localrule|rule|localcheckpoint|checkpoint) (\w+):\s*$", line)
        if m:
            counts[m.group(1)] = counts.get(m.group(1), 0) + 1
    return counts


def _shell_commands(log: str) -> dict[str, str]:
    """rule -> the first `python -m gaitval ...` shell command Snakemake printed for it."""
    out, rule = {}, None
    for line in log.splitlines():
        m = re.match(r"\s*(?:localrule|rule|localcheckpoint|checkpoint) (\w+):\s*$", line)
        if m:
            rule = m.group(1)
            continue
        if rule and rule not in out and (" -m gaitval " in line or "forkclient.py" in line):
            out[rule] = line.strip()
    return out


def _job_argvs(cmd: str) -> list[list[str]] | None:
    """The argv of each gaitval step of a rule's shell command, in order: one, or several
    chained with ``&&`` (a track job's tracking and evaluation)."""
    out = []
    for part in cmd.split(" && "):
        argv = _job_argv(part)
        if argv is None:
            break
        out.append(argv)
    return out or None


def _job_argv(cmd: str) -> list[str] | None:
    """The argv after `-m gaitval` of a rule's shell command (up to the redirection)."""
    words = shlex.split(re.split(r" >>? ", cmd)[0])
    if any(w.endswith("forkclient.py") for w in words) and "--" in words:
        return words[words.index("--") + 1:]
    try:
        i = words.index("gaitval", words.index("-m"))
    except ValueError:
        return None
    return words[i + 1:]


def _cpu_of(argv: list[str], cwd: Path) -> float:
    c0 = _cpu_children()
    subprocess.run(argv, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   check=False)
    return _cpu_children() - c0


def _startup_of(rule_argv: list[str], work: Path, n: int = 3) -> tuple[float, float, int]:
    """(job cpu, start-up + imports + exit cpu, modules) of one job, medians of n."""
    mods_file = work / "_modules.txt"
    job = statistics.median(
        _cpu_of([sys.executable, "-c", _RECORD, str(mods_file), *rule_argv], work)
        for _ in range(n))
    mods = [m for m in mods_file.read_text().split("\n")
            if m and m != "__main__" and not m.startswith("_frozen")]
    imp = ("import importlib\n"
           f"for m in {mods!r}:\n"
           "    try: importlib.import_module(m)\n"
           "    except Exception: pass\n")
    start = statistics.median(_cpu_of([sys.executable, "-c", imp], work) for _ in range(n))
    return job, start, len(mods)


def _print_breakdown(log: str, server_log: Path, cpu: float) -> None:
    """Where the run's CPU went: Snakemake itself, each verb's forked jobs, the rest."""
    m = re.search(r"snakemake itself: cpu ([\d.]+) s", log)
    own = float(m[1]) if m else float("nan")
    forked = _forked_jobs(server_log)
    jobs_cpu = sum(c for _n, c in forked.values())
    print(f"  snakemake itself {own:.1f} s; forked jobs {jobs_cpu:.1f} s; the rest (fork "
          f"server imports, job shells and clients, plain jobs) {cpu - own - jobs_cpu:.1f} s")
    for verb, (n, c) in sorted(forked.items(), key=lambda kv: -kv[1][1]):
        print(f"    {verb:26s} {n:5d} jobs {c:8.1f} cpu-s ({c / n:.2f} per job)")


def _linked_copy(src: Path, dst: Path) -> Path:
    """``src`` copied to ``dst`` with hard links (same file system; no data copied)."""
    shutil.copytree(src, dst, copy_function=os.link, symlinks=True,
                    ignore=shutil.ignore_patterns(".snakemake"))
    return dst


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", default="tiny", choices=["tiny", "default"])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--root", type=Path, default=ROOT,
                    help="checkout whose Snakefile runs (default: this one)")
    ap.add_argument("--keep", type=Path, default=None,
                    help="copy the last run's results/ here (to compare outputs)")
    ap.add_argument("--workdir", type=Path, default=None,
                    help="run in this new folder and keep it (data/, results/, reports/, "
                         "logs/: e.g. to time a rerun with nothing changed afterwards)")
    ap.add_argument("--no-fork-server", action="store_true",
                    help="one plain Python process per job (fork_server=False)")
    ap.add_argument("--no-startup", action="store_true",
                    help="skip the per-rule start-up measurement")
    args = ap.parse_args()
    walls, cpus, jobs = [], [], 0
    if args.workdir is not None:
        args.workdir.mkdir(parents=True)               # refuses an existing folder
    with tempfile.TemporaryDirectory(prefix="gaitval-e2e-") as tmp:
        for r in range(args.repeat):
            base = args.workdir.resolve() if args.workdir is not None else Path(tmp)
            work = base / f"run{r}"
            work.mkdir()
            wall, cpu, log = _run_snakemake(args.root.resolve(), work, args.study, args.cores,
                                            fork_server=not args.no_fork_server)
            counts = _job_stats(log)
            jobs = sum(counts.values())
            walls.append(wall)
            cpus.append(cpu)
            print(f"run {r + 1}: wall {wall:.1f} s, cpu {cpu:.1f} s, {jobs} jobs", flush=True)
            _print_breakdown(log, work / "logs" / "forkserver.log", cpu)
        if args.keep:
            shutil.copytree(work / "results", args.keep, dirs_exist_ok=True)
        share = float("nan")
        if not args.no_startup:
            # the jobs below rewrite their outputs (the simulation its data/): run them in
            # a hard-linked copy of the last run, so the run's own folder keeps the state
            # Snakemake left (a rerun in it has nothing to do); gaitval writes atomically
            # (a new file replaces the link), so the original files are never touched
            work = _linked_copy(work, base / "_startup")
            cmds = _shell_commands(log)
            forked = "forkclient.py" in log
            total_start = 0.0
            if forked:
                # the client itself, started as the rules start it, leaving at once (usage)
                client = statistics.median(_cpu_of(
                    [sys.executable, "-I", "-S", str(args.root / "gaitval" / "forkclient.py")],
                    work) for _ in range(5))
                server = statistics.median(_cpu_of(
                    [sys.executable, "-c", "from gaitval.forkserver import preload; preload()"],
                    work) for _ in range(3))
                total_start += server
                print(f"fork server: imports once {server:.2f} cpu-s; per job the client "
                      f"{client:.3f} cpu-s (instead of the plain start-up column)")
            via = _server_jobs(work / "logs" / "forkserver.log")
            ways = {"snakemake": 0, "client": 0, "plain": 0}
            print(f"{'rule':28s} {'jobs':>5s} {'job cpu':>8s} {'start-up':>9s} {'modules':>8s}")
            for rule, n in sorted(counts.items()):
                argvs = _job_argvs(cmds[rule]) if rule in cmds else None
                if argvs is None:
                    print(f"{rule:28s} {n:5d}  (no gaitval shell command: runs in Snakemake)")
                    continue
                for i, argv in enumerate(argvs):   # a chained job: a row per gaitval step
                    job, start, nmod = _startup_of(argv, work)
                    seen = via.get(argv[0], {})
                    direct = min(n, seen.get("snakemake", 0))
                    through = min(n - direct, seen.get("client", 0))
                    ways["snakemake"] += direct
                    ways["client"] += through
                    ways["plain"] += n - direct - through
                    total_start += through * (client if forked else start) \
                        + (n - direct - through) * start
                    label = rule if i == 0 else f"  then {argv[0]}"
                    print(f"{label:28s} {n:5d} {job:8.2f} {start:9.2f} {nmod:8d}", flush=True)
            print(f"gaitval steps sent to the fork server from Snakemake's thread: "
                  f"{ways['snakemake']}, through the client: {ways['client']}, plain "
                  f"processes: {ways['plain']}")
            share = 100 * total_start / statistics.median(cpus)
            shutil.rmtree(work, ignore_errors=True)
    print(f"report {args.study}: wall {statistics.median(walls):.1f} s, "
          f"cpu {statistics.median(cpus):.1f} s, {jobs} jobs, "
          f"start-up+imports {share:.0f} % of cpu")


def _server_jobs(path: Path) -> dict:
    """{verb: {"snakemake": n, "client": n}} of the jobs the fork server's log lists (how
    each reached it: the end line's ``via``; older logs without it: the client)."""
    out: dict = {}
    verbs: dict = {}
    if not path.is_file():
        return out
    for line in path.read_text().splitlines():
        m = re.match(r"job (\S+): gaitval (\S+)", line)
        if m:
            verbs[m.group(1)] = m.group(2)
            continue
        m = re.match(r"job (\S+): exit .*?(?:, via (\S+))?$", line)
        if m and m.group(1) in verbs:
            way = "snakemake" if m.group(2) == "snakemake" else "client"
            d = out.setdefault(verbs.pop(m.group(1)), {})
            d[way] = d.get(way, 0) + 1
    return out


if __name__ == "__main__":
    main()
