"""Time a rerun of a finished report, and list what one method's parameter reruns (issue 13).

Usage::

    # a finished run folder, e.g. one kept by the end-to-end benchmark:
    .venv/bin/python benchmarks/report_end_to_end.py --study default --workdir /tmp/e2e
    .venv/bin/python benchmarks/report_rerun.py --directory /tmp/e2e/run0 --repeat 3

Runs the README's command, ``python3 run.py report --directory DIR``, once to settle the
folder (a folder built by another command gets its ``report_config`` record rewritten:
the rebuild command it names differs), then ``--repeat`` times more, each of which must
find nothing to do; prints their wall and CPU times.  Then plans (``-n``) the rerun after a
new value of one tracker method's parameter (``tracking.overrides.<method>``, default
``tug_m3``'s ``occlusion__max_n``) and prints Snakemake's job counts per rule; the jobs it
may plan are that method's ``track`` jobs, one per study, each tracking and evaluating
every TUG trial (the method and its reading variant, e.g. ``tug_m3_stance_first``), the
config views and records, the TUG tables and the report.  Exits 1 when a rerun did work or the plan holds another rule or method.

Last line: ``rerun <folder>: nothing changed <median> s wall (bar 5 s); one method's
parameter: <n> jobs, only its own: yes|no``.
"""
from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

from report_end_to_end import _cpu_children        # this folder's sibling script

ROOT = Path(__file__).resolve().parents[1]
#: What a new value of one TUG method's parameter may rerun.
ALLOWED = {"track", "config_view", "study_config", "report_config",
           "tug_tables", "report", "all"}


def _report(directory: Path, *extra: str) -> tuple[float, float, str]:
    """(wall s, cpu s, output) of ``python3 run.py report --directory DIR [extra]``."""
    c0, t0 = _cpu_children(), time.perf_counter()
    p = subprocess.run([sys.executable, str(ROOT / "run.py"), "report", "--directory",
                        str(directory), *extra], capture_output=True, text=True, check=False)
    wall, cpu = time.perf_counter() - t0, _cpu_children() - c0
    out = p.stdout + p.stderr
    if p.returncode != 0:
        sys.exit(f"run.py report failed (exit {p.returncode}):\n{out[-3000:]}")
    return wall, cpu, out


def _job_counts(out: str) -> dict[str, int]:
    """Snakemake's first "Job stats" table: rule -> planned jobs."""
    counts, inside = {}, False
    for line in out.splitlines():
        if line.startswith("Job stats"):
            if counts:
                break
            inside = True
            continue
        m = re.match(r"(\w+)\s+(\d+)$", line.strip())
        if inside and m and m.group(1) != "total":
            counts[m.group(1)] = int(m.group(2))
        elif inside and line.strip().startswith("total"):
            break
    return counts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--directory", type=Path, required=True,
                    help="a run folder in which the report was built")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--method", default="tug_m3")
    ap.add_argument("--param", default="occlusion__max_n")
    ap.add_argument("--value", default="7")
    args = ap.parse_args()
    d = args.directory.resolve()
    wall, cpu, out = _report(d)
    print(f"settling run: {wall:.2f} s wall, {cpu:.2f} cpu-s", flush=True)
    walls, ok = [], True
    for i in range(args.repeat):
        wall, cpu, out = _report(d)
        idle = "Nothing to be done" in out
        ok &= idle
        walls.append(wall)
        print(f"rerun {i + 1}: {wall:.2f} s wall, {cpu:.2f} cpu-s"
              f"{'' if idle else '  -- DID WORK'}", flush=True)
    override = json.dumps({"overrides": {args.method: {args.param: json.loads(args.value)}}})
    _, _, out = _report(d, "-n", "--config", f"tracking={override}")
    counts = _job_counts(out)
    for rule, n in counts.items():
        print(f"    {rule:16s} {n:5d}")
    # the methods whose tracks and evaluations are planned (output folder names)
    methods = sorted(set(re.findall(r"^\s+output: \S+?/(?:track|evaluate)/([^/\s,]+)", out,
                                    flags=re.M)))
    print(f"    methods rerun: {', '.join(methods) or 'none'}")
    own = (bool(counts) and set(counts) <= ALLOWED and bool(methods)
           and all(m == args.method or m.startswith(args.method + "_") for m in methods))
    print(f"rerun {d.name}: nothing changed {statistics.median(walls):.2f} s wall (bar 5 s); "
          f"one method's parameter: {sum(counts.values())} jobs, only its own: "
          f"{'yes' if own else 'no'}")
    if not (ok and own):
        sys.exit(1)


if __name__ == "__main__":
    main()
