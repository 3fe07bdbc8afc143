"""Replay a finished run's jobs of some verbs in one process and print their CPU (issue 13).

Usage::

    .venv/bin/python benchmarks/replay_jobs.py RUN_FOLDER register [VERB ...] [--profile 30]

``RUN_FOLDER`` is a folder the end-to-end benchmark (or ``python3 run.py report``) built,
with its ``logs/forkserver.log``.  The folder is hard-linked into a temporary copy (outputs
are written atomically, so the originals are never touched), and every job of the given
verbs that the server's log lists runs again there, in this process, in the log's order,
as a warm worker runs it: ``gaitval.cli.main(args)``.  That isolates a stage's CPU from
Snakemake and the machine's other jobs, so two versions of the code can be compared in
alternation (``PYTHONPATH=<other checkout>``).  ``--profile N``: cProfile, N lines by
cumulative time.  ``--compare``: check each rewritten file against the run folder's.
``--keep DIR``: replay in ``DIR`` (new) and keep it, to compare the values.

The last line is exactly ``replay <verbs>: <n> jobs, <cpu> cpu-s``.
"""
from __future__ import annotations

import argparse
import contextlib
import cProfile
import filecmp
import io
import os
import pstats
import re
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path


def _link_copy(src: Path, dst: Path) -> None:
    """``src`` hard-linked into ``dst`` (copied where it cannot be linked: another disk)."""
    def link(a, b):
        try:
            os.link(a, b)
        except OSError:
            shutil.copy2(a, b)
    shutil.copytree(src, dst, copy_function=link, symlinks=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", type=Path)
    ap.add_argument("verbs", nargs="+")
    ap.add_argument("--profile", type=int, default=0)
    ap.add_argument("--compare", action="store_true")
    ap.add_argument("--keep", type=Path, default=None,
                    help="replay in this new folder and keep it (to compare values)")
    args = ap.parse_args()
    log = args.run / "logs" / "forkserver.log"
    if not log.is_file():
        sys.exit(f"{log}: no fork server log (a run with the fork server on is needed)")
    cmds = []
    for line in log.read_text().splitlines():
        m = re.match(r"job \S+: gaitval (.*)$", line)
        if m:
            a = shlex.split(m.group(1))
            if a and a[0] in args.verbs:
                cmds.append(a)
    if not cmds:
        sys.exit(f"no job of {args.verbs} in {log}")
    from gaitval.cli import main as gaitval_main
    import gaitval.forkserver as fs

    fs.preload()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep.resolve() if args.keep else Path(tmp) / "run"
        _link_copy(args.run.resolve(), work)
        os.chdir(work)
        prof = cProfile.Profile() if args.profile else None
        per: dict[str, float] = {}
        c0 = time.process_time()
        for a in cmds:
            c = time.process_time()
            if prof:
                prof.enable()
            with contextlib.redirect_stdout(io.StringIO()):
                rc = gaitval_main(list(a))
            if prof:
                prof.disable()
            if rc not in (0, None):
                sys.exit(f"job failed ({rc}): gaitval {shlex.join(a)}")
            per[a[0]] = per.get(a[0], 0.0) + time.process_time() - c
        total = time.process_time() - c0
        for verb, cpu in per.items():
            print(f"  {verb:24s} {cpu:7.2f} cpu-s")
        if args.compare:
            differ = []
            for dirpath, _, files in os.walk(work / "results"):
                for f in files:
                    p = Path(dirpath) / f
                    orig = args.run / p.relative_to(work)
                    if p.stat().st_ino != orig.stat().st_ino and not filecmp.cmp(p, orig, False):
                        differ.append(str(p.relative_to(work)))
            print(f"  rewritten files that differ from the run's: {len(differ)}",
                  *differ[:20], sep="\n    ")
        if prof:
            s = io.StringIO()
            pstats.Stats(prof, stream=s).sort_stats("cumulative").print_stats(args.profile)
            print(s.getvalue())
    print(f"replay {' '.join(args.verbs)}: {len(cmds)} jobs, {total:.2f} cpu-s")


if __name__ == "__main__":
    main()
