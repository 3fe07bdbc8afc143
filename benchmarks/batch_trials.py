"""CPU seconds of a batch job's trials, rerun in one process from a finished run's logs.

Usage::

    .venv/bin/python benchmarks/batch_trials.py RUN_DIR LOG [LOG ...] [--limit N] [--repeat 3]

``LOG``: a batch job's log under ``RUN_DIR`` (e.g. ``logs/mtst_track/default/people.log``):
its ``$ gaitval VERB ...`` lines are the trials' commands, by hand.  The first ``--limit``
trials' commands of each log are run in this process (``gaitval.cli.main``, as the batch
pool does), every output redirected into a temporary folder, ``--repeat`` times; printed:
each repeat's CPU seconds (``time.process_time``; the first includes the imports) and a
SHA-256 digest of the outputs, so a code change can be checked for speed and for
byte-identical files at once (run it before and after, on the same machine).
"""
from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import os
import shlex
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def commands(log: Path, limit: int) -> list[list[str]]:
    out, trials = [], []
    for line in log.read_text(encoding="utf-8").splitlines():
        if line.startswith("== "):
            trials.append(line[3:].split(":")[0])
            if len(trials) > limit:
                break
        elif line.startswith("$ gaitval ") and len(trials) <= limit:
            out.append(shlex.split(line[2:])[1:])
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir")
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--limit", type=int, default=12)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args(argv)
    from gaitval.cli import main as gaitval_main

    run = Path(a.run_dir).resolve()
    cmds = [c for log in a.logs for c in commands(run / log, a.limit)]
    os.chdir(run)
    cpu = []
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(a.repeat):
            outs = []
            t0 = time.process_time()
            for i, argv in enumerate(cmds):
                argv = list(argv)
                if "--out" in argv:
                    k = argv.index("--out")
                    argv[k + 1] = str(Path(tmp) / f"{i:04d}-{Path(argv[k + 1]).name}")
                    outs.append(Path(argv[k + 1]))
                with contextlib.redirect_stdout(io.StringIO()):
                    rc = gaitval_main(argv)
                if rc:
                    sys.exit(f"gaitval {shlex.join(argv)} exited with {rc}")
            cpu.append(time.process_time() - t0)
            h = hashlib.sha256()
            for p in outs:
                files = sorted(p.rglob("*")) if p.is_dir() else [p]
                for f in files:
                    if f.is_file():
                        h.update(f.read_bytes())
            print(f"repeat {r + 1}: {len(cmds)} commands, {cpu[-1]:.2f} cpu-s, "
                  f"outputs sha256 {h.hexdigest()[:16]}")
    print(f"median {statistics.median(cpu):.2f} cpu-s; without the first "
          f"{statistics.median(cpu[1:]) if len(cpu) > 1 else float('nan'):.2f} cpu-s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
