"""Compare two runs of the workflow byte for byte (issue 17: SLURM run against a local run).

    python tests/cluster/compare_runs.py LOCAL_ROOT SLURM_ROOT [--run tiny]

Each root holds results/ and reports/ (results_dir=ROOT/results reports_dir=ROOT/reports).
Compared, and required identical:
  * reports/<run>/tables/*   every table (.csv, .md, .tex)
  * results/**               every intermediate per-trial file (parquet, json, csv ...)
Listed but not required identical (they carry timestamps, absolute paths, the command
line or the host): reports/<run>/index.*, provenance/, figures/.
A .parquet file whose bytes differ is opened and explained: same columns and values with
only the schema metadata different (e.g. gaitval:mocap's `source`, the absolute path of the
C3D, which differs when the two runs have different working directories), or which
columns/values differ.  Exit status 0 when every table is byte-identical and every results
file is byte-identical or differs in such path metadata only (--strict: bytes only).
"""
from __future__ import annotations

import argparse
import filecmp
import sys
from pathlib import Path


def files_under(root: Path) -> set[str]:
    """Every file under ``root`` but Snakemake's own marker of a `directory()` output
    (``.snakemake_timestamp``: when the job ended)."""
    if not root.is_dir():
        return set()
    return {str(p.relative_to(root)) for p in root.rglob("*")
            if p.is_file() and p.name != ".snakemake_timestamp"}


def compare_tree(a: Path, b: Path) -> tuple[list[str], list[str], list[str], list[str]]:
    """(identical, differing, only in a, only in b) relative paths."""
    fa, fb = files_under(a), files_under(b)
    same, diff = [], []
    for rel in sorted(fa & fb):
        (same if filecmp.cmp(a / rel, b / rel, shallow=False) else diff).append(rel)
    return same, diff, sorted(fa - fb), sorted(fb - fa)


def explain_parquet(a: Path, b: Path, roots: tuple[str, str]) -> tuple[bool, str]:
    """(only path metadata differs, explanation) for two parquet files of unequal bytes."""
    import pyarrow.parquet as pq

    ta, tb = pq.read_table(a), pq.read_table(b)
    if ta.schema.names != tb.schema.names:
        only_a = [c for c in ta.schema.names if c not in tb.schema.names]
        only_b = [c for c in tb.schema.names if c not in ta.schema.names]
        return False, f"columns differ (only local {only_a}, only other {only_b})"
    if not ta.equals(tb):
        return False, "values differ"
    ma, mb = ta.schema.metadata or {}, tb.schema.metadata or {}
    keys = sorted(k.decode() for k in set(ma) | set(mb) if ma.get(k) != mb.get(k))
    # the metadata is the same once each run's root folder is blanked out
    same_wo_paths = all(
        (ma.get(k.encode()) or b"").decode().replace(roots[0], "<root>")
        == (mb.get(k.encode()) or b"").decode().replace(roots[1], "<root>") for k in keys)
    return same_wo_paths, ("same columns and values; schema metadata differs in "
                           + ", ".join(keys)
                           + (" only by the runs' root folders" if same_wo_paths else ""))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("local", type=Path)
    ap.add_argument("other", type=Path)
    ap.add_argument("--run", default="tiny", help="run name = reports/<run>/ (default tiny)")
    ap.add_argument("--strict", action="store_true",
                    help="results/ must be byte-identical too (no path-metadata allowance)")
    args = ap.parse_args(argv)
    roots = (str(args.local.resolve()), str(args.other.resolve()))

    ok = True
    required = [("reports/%s/tables" % args.run, True), ("results", True)]
    informative = [(f"reports/{args.run}/{d}", False) for d in ("provenance", "figures")]
    for sub, must in required + informative:
        same, diff, only_a, only_b = compare_tree(args.local / sub, args.other / sub)
        n = len(same) + len(diff) + len(only_a) + len(only_b)
        status = "IDENTICAL" if n and not (diff or only_a or only_b) else "DIFFERENT"
        if n == 0:
            status = "MISSING"
        path_only = []
        if sub == "results" and diff and not args.strict:
            for rel in diff:
                if rel.endswith(".parquet"):
                    ok_paths, why = explain_parquet(args.local / sub / rel,
                                                    args.other / sub / rel, roots)
                    print(f"    {rel}: {why}")
                    if ok_paths:
                        path_only.append(rel)
            if len(path_only) == len(diff) and not (only_a or only_b):
                status = "IDENTICAL except path metadata"
        print(f"{sub}: {len(same)}/{n} files byte-identical"
              + (f", {len(path_only)} more differ only in the runs' root folders in metadata"
                 if path_only else "")
              + f" -> {status}" + ("" if must else " (informative only)"))
        for label, items in (("differ", [d for d in diff if d not in path_only]),
                             ("only in local", only_a), ("only in other", only_b)):
            for rel in items[:20]:
                print(f"    {label}: {rel}")
            if len(items) > 20:
                print(f"    ... and {len(items) - 20} more {label}")
        if must and not status.startswith("IDENTICAL"):
            ok = False
    top_a = {p.name for p in (args.local / "reports" / args.run).glob("*") if p.is_file()}
    top_b = {p.name for p in (args.other / "reports" / args.run).glob("*") if p.is_file()}
    print(f"reports/{args.run}/ top-level files (index.*, not compared): "
          f"local {sorted(top_a)}, other {sorted(top_b)}")
    print("RESULT:", "tables byte-identical, results identical" if ok else "MISMATCH")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
