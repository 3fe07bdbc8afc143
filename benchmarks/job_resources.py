"""Peak memory and run time of every rule's steps -- the numbers behind the per-rule
`set-resources` of workflow/profiles/slurm/config.yaml (issues 17, 38).

    # 1. a finished run (its batch jobs' logs hold each trial's command, "$ gaitval ...")
    .venv/bin/snakemake -s Snakefile --directory /tmp/jr/work --profile workflow/profiles/default \
        --config 'run=["tiny"]' results_dir=/tmp/jr/results reports_dir=/tmp/jr/reports
    # 2. rerun its steps one at a time under /usr/bin/time in a scratch copy
    .venv/bin/python benchmarks/job_resources.py --root /tmp/jr --scratch /tmp/jr-measure \
        [--per-rule 3]

Each trial's commands (its verbs, one after the other, as its task ran them) are taken from
the batch jobs' logs (``<root>/work/logs/<rule>/...``), the run's root folder is copied to
--scratch and the commands run there as `python -m gaitval VERB ...`, one trial at a time
(so the peaks are not disturbed by the neighbours, apart from the machine's load), under
`/usr/bin/time` (peak RSS = the largest process, wall and CPU seconds).

On a SLURM job a batch rule's trials run in a process pool of the job's threads, under
two Snakemake processes (the batch script's `python -m snakemake --executor
slurm-jobstep` and the one it starts with srun; each parses the whole workflow again) and
the pool's forkserver (gaitval imported, ~450 MB): the suggested mem_mb is (forkserver +
threads x step peak + 2 x Snakemake peak) x 1.5, rounded up to 100 MB; runtime (minutes)
is 3x the trials' summed wall / threads + 2 minutes, rounded up, at least 5.
"""
from __future__ import annotations

import argparse
import math
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FORKSERVER_MB = 450        # the pool's forkserver with gaitval imported (its RSS)
THREADS = 2                # the profile's set-threads


def trial_commands(logs: Path) -> list[tuple[str, str]]:
    """(rule, the trial's commands joined with &&) of every task in the batch jobs' logs
    under ``logs`` (``== <trial>`` then its ``$ gaitval ...`` lines)."""
    jobs = []
    for p in sorted(logs.rglob("*.log")):
        lines = p.read_text(errors="replace").splitlines()
        if not lines or " task(s) in " not in lines[0]:
            continue
        rule = p.relative_to(logs).parts[0].removesuffix(".log")
        cmds: list[str] = []
        for line in lines[1:] + ["== end"]:
            if line.startswith("== ") and cmds:
                jobs.append((rule, " && ".join(cmds)))
                cmds = []
            elif line.startswith("$ gaitval "):
                cmds.append(line[2:])
    return jobs


def plain(cmd: str, python: str) -> str:
    """The commands as a shell runs them: `python -m gaitval VERB ...`."""
    return cmd.replace("gaitval ", f"{python} -m gaitval ", 1).replace(
        " && gaitval ", f" && {python} -m gaitval ")


def timed(cmd: str, cwd: Path) -> dict:
    with tempfile.NamedTemporaryFile("r", suffix=".time") as out:
        t0 = time.monotonic()
        proc = subprocess.run(
            ["/usr/bin/time", "-f", "%M %e %U %S", "-o", out.name,
             "bash", "-c", "set -euo pipefail; " + cmd],
            cwd=cwd, capture_output=True, text=True)
        wall = time.monotonic() - t0
        fields = out.read().split()[-4:]
    rss_kb, _, user, sys_ = (float(x) for x in fields)
    return {"rc": proc.returncode, "rss_mb": rss_kb / 1024, "wall_s": wall,
            "cpu_s": user + sys_, "stderr": proc.stderr[-500:]}


def snakemake_overhead(root: Path, run: str) -> dict:
    """Peak RSS/time of `snakemake -n` of the workflow: what each SLURM job step adds
    (the job parses the Snakefile and imports gaitval before it runs the command)."""
    cmd = (f"{REPO / '.venv/bin/snakemake'} -s {REPO / 'Snakefile'} --directory {root / 'work'}"
           f" -n --config 'run=[\"{run}\"]' results_dir={root / 'results'}"
           f" reports_dir={root / 'reports'} --quiet all")
    return timed(cmd, root / "work")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, required=True,
                    help="the run's root: work/ (its --directory), results/, reports/")
    ap.add_argument("--scratch", type=Path, required=True, help="copy of --root to run in")
    ap.add_argument("--per-rule", type=int, default=0, help="jobs per rule (0 = all)")
    ap.add_argument("--match", default=None,
                    help="only commands matching this regex (e.g. the largest trials)")
    ap.add_argument("--run", default="tiny", help="run name (for --snakemake-overhead)")
    ap.add_argument("--python", default=str(REPO / ".venv/bin/python"))
    args = ap.parse_args(argv)

    jobs = trial_commands(args.root / "work" / "logs")
    if not jobs:
        sys.exit(f"no batch job logs with commands under {args.root / 'work' / 'logs'}")
    if args.scratch.exists():
        shutil.rmtree(args.scratch)
    shutil.copytree(args.root, args.scratch, symlinks=True)
    src, dst = str(args.root.resolve()), str(args.scratch.resolve())

    seen = defaultdict(int)
    per_rule = defaultdict(list)
    for rule, cmd in jobs:
        if args.match and not re.search(args.match, cmd):
            continue
        if args.per_rule and seen[rule] >= args.per_rule:
            continue
        seen[rule] += 1
        r = timed(plain(cmd, args.python).replace(src, dst), args.scratch / "work")
        if r["rc"] != 0:
            print(f"FAILED {rule}: {r['stderr']}", file=sys.stderr)
            continue
        per_rule[rule].append(r)
        print(f"  {rule:24s} {r['rss_mb']:7.0f} MB {r['wall_s']:6.1f} s wall "
              f"{r['cpu_s']:6.1f} CPU-s", file=sys.stderr, flush=True)

    sm = snakemake_overhead(args.scratch, args.run)
    print(f"\nSnakemake job-step process (snakemake -n of the run, rc={sm['rc']}): "
          f"{sm['rss_mb']:.0f} MB peak RSS, {sm['wall_s']:.1f} s wall")
    print("\n| rule | trials | peak RSS MB | wall s (sum) | CPU s (sum) | suggested mem_mb | runtime min |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for rule in sorted(per_rule):
        rs = per_rule[rule]
        rss = max(r["rss_mb"] for r in rs)
        wall = sum(r["wall_s"] for r in rs)
        cpu = sum(r["cpu_s"] for r in rs)
        mem = int(math.ceil((FORKSERVER_MB + THREADS * rss + 2 * sm["rss_mb"]) * 1.5
                            / 100.0) * 100)
        runtime = max(5, int(math.ceil(3 * wall / THREADS / 60.0 + 2)))
        print(f"| {rule} | {len(rs)} | {rss:.0f} | {wall:.1f} | {cpu:.1f} | {mem} | {runtime} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
