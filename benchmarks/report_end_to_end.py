"""Build a report from nothing and print what it cost (issues 13 and 38).

Usage::

    .venv/bin/python benchmarks/report_end_to_end.py --study tiny            # ~1 min
    .venv/bin/python benchmarks/report_end_to_end.py --study default --repeat 3
    # keep the run folders, e.g. to time a rerun with nothing changed afterwards
    # (benchmarks/report_rerun.py):
    .venv/bin/python benchmarks/report_end_to_end.py --study default --workdir /tmp/e2e

Each repeat runs Snakemake from the checkout's Snakefile with the profile of ``python3 run.py
report`` (``--profile workflow/profiles/default --cores N``) in a fresh folder (fresh
data/, results/, reports/, logs/; the venv is not touched), so the simulation is included.
To compare with another checkout, run *its* copy of this script with *its* venv, in
alternation with this one, on the same machine (docs/speed.md, "Measuring").

Prints per repeat ``wall``, ``cpu`` (user + system of Snakemake and every process it
started, the process pools' forkserver and workers included) and the job count,
Snakemake's own CPU, and per rule the jobs' wall time and their tasks' CPU (from the
batch jobs' logs, ``logs/<rule>/...``: "N task(s) in P process(es), W s wall, C s cpu");
then::

    report <study>: wall <median> s, cpu <median> s, <jobs> jobs
"""
from __future__ import annotations

import argparse
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# runs Snakemake in this process and prints at exit its own CPU (not its jobs') and that
# of the process pools' forkserver (a child of Snakemake that is never waited for, so
# its CPU, and its reaped workers', is not in getrusage(RUSAGE_CHILDREN)): its
# /proc/PID/stat utime + stime + cutime + cstime
_SNAKEMAKE_SELF = ("import atexit, os, runpy, sys\n"
                   "def _forkservers():\n"
                   "    tick, cpu = os.sysconf('SC_CLK_TCK'), 0.0\n"
                   "    for d in os.listdir('/proc'):\n"
                   "        try:\n"
                   "            if not d.isdigit(): continue\n"
                   "            cmd = open(f'/proc/{d}/cmdline', 'rb').read()\n"
                   "            st = open(f'/proc/{d}/stat').read().rsplit(')', 1)[1].split()\n"
                   "            if int(st[1]) == os.getpid() and b'forkserver' in cmd:\n"
                   "                cpu += sum(int(x) for x in st[11:15]) / tick\n"
                   "        except (OSError, ValueError):\n"
                   "            pass\n"
                   "    return cpu\n"
                   "atexit.register(lambda: print('snakemake itself: cpu %.2f s; forkserver: '\n"
                   "    'cpu %.2f s' % (os.times().user + os.times().system, _forkservers()),\n"
                   "    file=sys.stderr))\n"
                   "sys.argv[0] = 'snakemake'\n"
                   "runpy.run_module('snakemake', run_name='__main__', alter_sys=True)\n")


def _cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run_snakemake(root: Path, work: Path, study: str, cores: int,
                   config: tuple[str, ...] = ()) -> tuple[float, float, str]:
    # the profile `python3 run.py report` uses (workflow/profiles/default), cores overridden
    cmd = [sys.executable, "-c", _SNAKEMAKE_SELF, "-s", str(root / "Snakefile"),
           "--profile", str(root / "workflow" / "profiles" / "default"),
           "--directory", str(work), "--cores", str(cores), "--config", f'run=["{study}"]',
           *config]
    c0, t0 = _cpu_children(), time.perf_counter()
    p = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _cpu_children() - c0
    log = p.stdout + p.stderr
    if p.returncode:
        sys.exit(f"snakemake failed ({p.returncode}):\n{log[-4000:]}")
    return wall, cpu, log


def _job_stats(log: str) -> dict[str, int]:
    """rule -> jobs run, from the ``rule X:`` / ``checkpoint X:`` line Snakemake prints per
    job (its 'Job stats' table is printed before a checkpoint adds the later jobs)."""
    counts: dict[str, int] = {}
    for line in log.splitlines():
        m = re.match(r"\s*(?:localrule|rule|localcheckpoint|checkpoint) (\w+):\s*$", line)
        if m:
            counts[m.group(1)] = counts.get(m.group(1), 0) + 1
    return counts


def _batch_walls(logs: Path) -> dict[str, tuple[int, int, float, float]]:
    """rule (the log's folder) -> (jobs, tasks, wall s, tasks' cpu s) of the batch jobs'
    logs."""
    out: dict[str, list] = {}
    for p in sorted(logs.rglob("*.log")):
        first = p.read_text(errors="replace").split("\n", 1)[0]
        m = re.match(r"(\d+) task\(s\) in \d+ process\(es\), ([\d.]+) s wall, "
                     r"([\d.]+) s cpu", first)
        if m:
            rule = p.relative_to(logs).parts[0].removesuffix(".log")
            acc = out.setdefault(rule, [0, 0, 0.0, 0.0])
            acc[0] += 1
            acc[1] += int(m[1])
            acc[2] += float(m[2])
            acc[3] += float(m[3])
    return {k: tuple(v) for k, v in out.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", default="tiny", choices=["tiny", "default"])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--workdir", type=Path, default=None,
                    help="run in this new folder and keep it (run0/, run1/, ...)")
    ap.add_argument("--config", nargs="*", default=(), metavar="KEY=VALUE",
                    help="more Snakemake --config items, e.g. 'rollator={methods: []}' to "
                         "leave out a row that an older checkout does not have")
    args = ap.parse_args()
    walls, cpus, jobs = [], [], 0
    if args.workdir is not None:
        args.workdir.mkdir(parents=True)               # refuses an existing folder
    with tempfile.TemporaryDirectory(prefix="gaitval-e2e-") as tmp:
        base = args.workdir.resolve() if args.workdir is not None else Path(tmp)
        for r in range(args.repeat):
            work = base / f"run{r}"
            work.mkdir()
            wall, cpu, log = _run_snakemake(ROOT, work, args.study, args.cores,
                                             tuple(args.config))
            jobs = sum(_job_stats(log).values())
            m = re.search(r"snakemake itself: cpu ([\d.]+) s; forkserver: cpu ([\d.]+) s", log)
            own, pool = (float(m[1]), float(m[2])) if m else (float("nan"), 0.0)
            cpu += pool
            walls.append(wall)
            cpus.append(cpu)
            print(f"run {r + 1}: wall {wall:.1f} s, cpu {cpu:.1f} s, {jobs} jobs; "
                  f"snakemake itself {own:.1f} cpu-s, the pools (forkserver, its imports "
                  f"and workers) {pool:.1f} cpu-s", flush=True)
            for rule, (n, tasks, w, c) in sorted(_batch_walls(work / "logs").items(),
                                                 key=lambda kv: -kv[1][3]):
                print(f"    {rule:24s} {n:4d} jobs {tasks:5d} tasks {w:7.1f} s wall "
                      f"{c:7.1f} s cpu")
    print(f"report {args.study}: wall {statistics.median(walls):.1f} s, "
          f"cpu {statistics.median(cpus):.1f} s, {jobs} jobs")


if __name__ == "__main__":
    main()
