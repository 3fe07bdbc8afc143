"""Per-rule summary of the SLURM jobs of one Snakemake run, from its log and `sacct`.

    python tests/cluster/slurm_job_report.py SNAKEMAKE_LOG [--no-sacct]

The log's "Job N has been submitted with SLURM jobid M (log: .../rule_RULE/...)" lines
give the SLURM job ids and their rules.  With accounting (slurmdbd), `sacct` gives each
job's state, elapsed time and peak memory (MaxRSS over the job's steps: the batch script,
the job's own Snakemake and the rule's command); without it (sacct: "Slurm accounting
storage is disabled") the script falls back to `squeue --states=all`, which lists state
and elapsed time of jobs younger than MinJobAge but no memory.
Works on a real cluster too: the numbers to put in workflow/profiles/slurm/config.yaml.
"""
from __future__ import annotations

import argparse
import re
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

SUBMIT_RE = re.compile(r"submitted with SLURM jobid (\d+) \(log: .*/rule_([^/]+)/")


def submitted(log: Path) -> dict[str, str]:
    """SLURM job id -> rule."""
    return {m.group(1): m.group(2)
            for m in SUBMIT_RE.finditer(log.read_text(errors="replace"))}


def seconds(elapsed: str) -> float:
    """[D-]HH:MM:SS or MM:SS -> seconds."""
    days = 0
    if "-" in elapsed:
        d, elapsed = elapsed.split("-", 1)
        days = int(d)
    parts = [float(p) for p in elapsed.split(":")]
    while len(parts) < 3:
        parts.insert(0, 0.0)
    h, m, s = parts
    return days * 86400 + h * 3600 + m * 60 + s


def mb(rss: str) -> float:
    if not rss:
        return 0.0
    unit = rss[-1].upper()
    scale = {"K": 1 / 1024, "M": 1.0, "G": 1024.0, "T": 1024.0 ** 2}
    if unit in scale:
        return float(rss[:-1]) * scale[unit]
    return float(rss) / 1024 ** 2  # bytes


def sacct(ids: list[str]) -> dict[str, dict] | None:
    proc = subprocess.run(
        ["sacct", "--parsable2", "--noheader", "-j", ",".join(ids),
         "--format=JobIdRaw,State,Elapsed,MaxRSS"],
        capture_output=True, text=True)
    if proc.returncode != 0:
        print(f"sacct: {proc.stderr.strip()}", file=sys.stderr)
        return None
    jobs: dict[str, dict] = {}
    for line in proc.stdout.splitlines():
        jid, state, elapsed, rss = (line.split("|") + ["", "", "", ""])[:4]
        main = jid.split(".")[0]
        j = jobs.setdefault(main, {"state": "", "elapsed_s": 0.0, "rss_mb": 0.0})
        if "." not in jid:
            j["state"], j["elapsed_s"] = state, seconds(elapsed)
        j["rss_mb"] = max(j["rss_mb"], mb(rss))
    return jobs


def squeue(ids: list[str]) -> dict[str, dict]:
    proc = subprocess.run(["squeue", "--states=all", "--noheader", "-o", "%i|%T|%M"],
                          capture_output=True, text=True, check=True)
    jobs = {}
    for line in proc.stdout.splitlines():
        jid, state, elapsed = line.strip().split("|")
        if jid in ids:
            jobs[jid] = {"state": state, "elapsed_s": seconds(elapsed), "rss_mb": None}
    return jobs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", type=Path)
    ap.add_argument("--no-sacct", action="store_true", help="use squeue only")
    args = ap.parse_args(argv)
    rules = submitted(args.log)
    if not rules:
        sys.exit(f"no submitted SLURM jobs in {args.log}")
    ids = sorted(rules, key=int)
    jobs = None if args.no_sacct else sacct(ids)
    source = "sacct"
    if jobs is None:
        jobs, source = squeue(ids), "squeue --states=all"
    states = defaultdict(int)
    per_rule = defaultdict(list)
    for jid in ids:
        j = jobs.get(jid, {"state": "UNKNOWN", "elapsed_s": 0.0, "rss_mb": None})
        states[j["state"]] += 1
        per_rule[rules[jid]].append(j)
    print(f"{len(ids)} SLURM jobs submitted by Snakemake; seen by {source}: "
          + ", ".join(f"{n} {s}" for s, n in sorted(states.items())))
    print("\n| rule | jobs | max elapsed s | max MaxRSS MB |")
    print("|---|---:|---:|---:|")
    for rule in sorted(per_rule):
        js = per_rule[rule]
        el = max(j["elapsed_s"] for j in js)
        rss = [j["rss_mb"] for j in js if j["rss_mb"] is not None]
        print(f"| {rule} | {len(js)} | {el:.0f} | "
              + (f"{max(rss):.0f}" if rss else "n/a") + " |")
    return 0 if set(states) <= {"COMPLETED"} else 1


if __name__ == "__main__":
    sys.exit(main())
