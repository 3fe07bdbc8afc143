"""How much core time a run's batch jobs leave idle at their ends, from their trials' CPU
times (issue 38: the stage barriers).

Usage::

    .venv/bin/python benchmarks/batch_tails.py --directory <a finished run folder>

A batch job (``gaitval.jobs.batch``) holds its ``P`` processes until its last trial ends;
while that trial runs alone, the other processes' cores wait for the next job.  On a
shared machine the logs' wall times say little, so this models each job from the CPU time
of each trial (``-- 0.123 s cpu`` in ``logs/<rule>/...``): its trials handed to ``P``
workers longest first (what ``by_size`` approximates with the trials' bytes), the job
lasts as long as its busiest worker (the makespan), and ``P * makespan - sum(cpu)`` core
seconds are idle.  A job of one process (a table) leaves ``cores - 1`` cores idle for its
whole length unless Snakemake runs another one-process job beside it.  Prints per rule the
jobs, trials, CPU, the modelled makespan and idle core seconds, and the totals.
"""
from __future__ import annotations

import argparse
import heapq
import re
from pathlib import Path

HEAD = re.compile(r"(\d+) task\(s\) in (\d+) process\(es\), ([\d.]+) s wall, ([\d.]+) s cpu")
TASK_CPU = re.compile(r"^-- ([\d.]+) s cpu$", re.M)


def makespan(cpus: list[float], workers: int) -> float:
    """The longest worker's load when tasks go, longest first, to the least loaded."""
    load = [0.0] * max(1, workers)
    for c in sorted(cpus, reverse=True):
        heapq.heapreplace(load, load[0] + c)
    return max(load)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--directory", type=Path, required=True)
    ap.add_argument("--cores", type=int, default=2)
    args = ap.parse_args()
    rows: dict[str, list[float]] = {}
    for p in sorted((args.directory / "logs").rglob("*.log")):
        text = p.read_text(errors="replace")
        m = HEAD.match(text)
        cpus = [float(x) for x in TASK_CPU.findall(text)]
        if not m or not cpus:
            continue
        procs = int(m[2])
        span = makespan(cpus, procs)
        idle = procs * span - sum(cpus) + (args.cores - procs) * span
        rule = p.relative_to(args.directory / "logs").parts[0].removesuffix(".log")
        acc = rows.setdefault(rule, [0, 0, 0.0, 0.0, 0.0])
        acc[0] += 1
        acc[1] += len(cpus)
        acc[2] += sum(cpus)
        acc[3] += span
        acc[4] += idle
    print(f"{'rule':24s} {'jobs':>4s} {'trials':>6s} {'cpu s':>7s} {'makespan s':>10s} "
          f"{'idle core-s':>11s}")
    total = [0, 0, 0.0, 0.0, 0.0]
    for rule, acc in sorted(rows.items(), key=lambda kv: -kv[1][4]):
        print(f"{rule:24s} {acc[0]:4d} {acc[1]:6d} {acc[2]:7.2f} {acc[3]:10.2f} {acc[4]:11.2f}")
        total = [a + b for a, b in zip(total, acc)]
    print(f"{'total':24s} {total[0]:4d} {total[1]:6d} {total[2]:7.2f} {total[3]:10.2f} "
          f"{total[4]:11.2f}")
    print(f"(idle core-s of {args.cores} cores; a one-process job's idle core is counted "
          "as if nothing ran beside it)")


if __name__ == "__main__":
    main()
