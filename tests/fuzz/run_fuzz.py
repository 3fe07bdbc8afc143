#!/usr/bin/env python3
"""Run the fuzz harness on many mutants and print the outcome counts per file type.

    .venv/bin/python tests/fuzz/run_fuzz.py                 # 10,000 mutants, 1 process
    nice -n 10 .venv/bin/python tests/fuzz/run_fuzz.py -j 2 --seed 1
    .venv/bin/python tests/fuzz/run_fuzz.py -n 300 --kinds c3d bag
    .venv/bin/python tests/fuzz/run_fuzz.py --timeout 20 --mem-gib 3   # the defaults

Mutants are made in a temporary folder (never in the repository) from the real files in
``../shared/realdata/`` and small generated logs, sheets and annotations
(``fuzz_mutators``); each is read in a child process with a time-out and rlimits
(``fuzz_harness``).  Every failure (crash, hang, foreign exception, error that does not
name the file, a load that is silently short or gives a non-finite key number) is listed
with its mutation so it can be reproduced with --kinds/--only; loads with warnings are
counted as ``warned``.
Exit status 1 when there is any failure.
"""
from __future__ import annotations

import argparse
import itertools
import multiprocessing
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_harness as H  # noqa: E402

#: share of the mutants per kind (bags are slow to read: ~1 s each)
SHARE = {"c3d": 0.25, "bag": 0.05, "scanlog": 0.18, "ultrasonic": 0.18,
         "annotations": 0.17, "sheet": 0.17}


def tasks(n: int, seed: int, kinds: list[str], work: str) -> list[tuple]:
    share = {k: SHARE[k] for k in kinds}
    total = sum(share.values())
    per_kind = [[(k, seed, i, work) for i in range(round(n * share[k] / total))]
                for k in kinds]
    out = []                                   # interleaved: every kind early in the run
    for row in itertools.zip_longest(*per_kind):
        out += [t for t in row if t is not None]
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=10_000, help="number of mutants (all kinds)")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kinds", nargs="+", default=list(H.KINDS), choices=H.KINDS)
    ap.add_argument("--only", type=int, nargs="*", help="just these mutant indices")
    ap.add_argument("--timeout", type=float, default=20.0,
                    help="seconds a mutant's child may take (wall clock; CPU limit too)")
    ap.add_argument("--mem-gib", type=float, default=3.0,
                    help="address-space limit of a mutant's child, GiB")
    a = ap.parse_args(argv)
    H.LIMITS.update(timeout_s=a.timeout, memory_bytes=int(a.mem_gib * 2 ** 30))
    t0 = time.time()
    with tempfile.TemporaryDirectory(prefix="gaitval-fuzz-") as work:
        todo = tasks(a.n, a.seed, a.kinds, work)
        if a.only is not None:
            todo = [t for t in todo if t[2] in a.only]
        ctx = multiprocessing.get_context("fork")
        H.warm_up()                                   # before the pool forks its workers
        with ctx.Pool(a.jobs) as pool:
            results = []
            for k, r in enumerate(pool.imap_unordered(H.fuzz_one, todo, chunksize=4)):
                results.append(r)
                if r["outcome"] in H.FAILURES or r["detail"].startswith("contained"):
                    tag = "FAIL" if r["outcome"] in H.FAILURES else "note"
                    print(f"{tag} {r['outcome']:8} {r['kind']}#{r['index']} {r['what']}: "
                          f"{r['detail']}", flush=True)
                if (k + 1) % 500 == 0:
                    print(f"... {k + 1}/{len(todo)} mutants, {time.time() - t0:.0f} s\n"
                          + H.format_table(H.summarise(results)), file=sys.stderr, flush=True)
    table = H.summarise(results)
    print(f"\n{len(results)} mutants (seed {a.seed}, {a.timeout:g} s and {a.mem_gib:g} GiB "
          f"per mutant) in {time.time() - t0:.0f} s; 'contained' = native crash/stall caught "
          "by gaitval's own child process")
    print(H.format_table(table))
    return int(any(row[f] for row in table.values() for f in H.FAILURES))


if __name__ == "__main__":
    sys.exit(main())
