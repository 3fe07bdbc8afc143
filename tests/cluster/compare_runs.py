"""Compare two runs of the workflow byte for byte (issue 17: SLURM run against a local run).

    python tests/cluster/compare_runs.py LOCAL_ROOT SLURM_ROOT [--run tiny]

Each root holds results/ and reports/ (results_dir=ROOT/results reports_dir=ROOT/reports).
Compared, and required identical:
  * reports/<run>/tables/*   every table (.csv, .md, .tex)
  * results/**               every intermediate per-trial file (parquet, json, csv ...)
Listed but not required identical (they carry timestamps, absolute paths, the command
line or the host): reports/<run>/index.*, provenance/, figures/.
Exit status 0 when every required file exists on both sides with the same bytes.
"""
from __future__ import annotations

import argparse
import filecmp
import sys
from pathlib import Path


def files_under(root: Path) -> set[str]:
    if not root.is_dir():
        return set()
    return {str(p.relative_to(root)) for p in root.rglob("*") if p.is_file()}


def compare_tree(a: Path, b: Path) -> tuple[list[str], list[str], list[str], list[str]]:
    """(identical, differing, only in a, only in b) relative paths."""
    fa, fb = files_under(a), files_under(b)
    same, diff = [], []
    for rel in sorted(fa & fb):
        (same if filecmp.cmp(a / rel, b / rel, shallow=False) else diff).append(rel)
    return same, diff, sorted(fa - fb), sorted(fb - fa)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("local", type=Path)
    ap.add_argument("other", type=Path)
    ap.add_argument("--run", default="tiny", help="run name = reports/<run>/ (default tiny)")
    args = ap.parse_args(argv)

    ok = True
    required = [("reports/%s/tables" % args.run, True), ("results", True)]
    informative = [(f"reports/{args.run}/{d}", False) for d in ("provenance", "figures")]
    for sub, must in required + informative:
        same, diff, only_a, only_b = compare_tree(args.local / sub, args.other / sub)
        n = len(same) + len(diff) + len(only_a) + len(only_b)
        status = "IDENTICAL" if n and not (diff or only_a or only_b) else "DIFFERENT"
        if n == 0:
            status = "MISSING"
        print(f"{sub}: {len(same)}/{n} files byte-identical -> {status}"
              + ("" if must else " (informative only)"))
        for label, items in (("differ", diff), ("only in local", only_a),
                             ("only in other", only_b)):
            for rel in items[:20]:
                print(f"    {label}: {rel}")
            if len(items) > 20:
                print(f"    ... and {len(items) - 20} more {label}")
        if must and status != "IDENTICAL":
            ok = False
    top_a = {p.name for p in (args.local / "reports" / args.run).glob("*") if p.is_file()}
    top_b = {p.name for p in (args.other / "reports" / args.run).glob("*") if p.is_file()}
    print(f"reports/{args.run}/ top-level files (index.*, not compared): "
          f"local {sorted(top_a)}, other {sorted(top_b)}")
    print("RESULT:", "tables and results byte-identical" if ok else "MISMATCH")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
