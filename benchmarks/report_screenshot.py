"""Screenshot the top of a gaitval report in headless Chromium (issue 14, scope 2).

Usage::

    python benchmarks/report_screenshot.py REPORTS_DIR [OUT.png] [--width 1400 --height 1800]

Rebuilds ``REPORTS_DIR/index.{md,html}`` from the tables already there
(:func:`gaitval.report.index.build_index`), then runs
``chromium --headless --screenshot=OUT.png --window-size=W,H file://.../index.html``.
Look at the PNG: the verdict table must be visible at the top, at 1400 px wide.
Chromium comes from Debian (``apt-get install -y chromium``); without it the script says so
and exits 2.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

from gaitval.report.index import build_index


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reports_dir", type=Path)
    ap.add_argument("out", type=Path, nargs="?", default=Path("report_top.png"))
    ap.add_argument("--width", type=int, default=1400)
    ap.add_argument("--height", type=int, default=1800)
    ap.add_argument("--studies", nargs="*", default=None)
    a = ap.parse_args(argv)
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        print("chromium not found: apt-get install -y chromium", file=sys.stderr)
        return 2
    # the report folder is named after its run (reports/<study>+<study>): re-rendering the
    # index without the studies would overwrite its "Studies:" line with "-"
    studies = a.studies if a.studies is not None else Path(a.reports_dir).name.split("+")
    _, html = build_index(a.reports_dir, study_names=studies)
    a.out.parent.mkdir(parents=True, exist_ok=True)
    subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    f"--screenshot={a.out.resolve()}",
                    f"--window-size={a.width},{a.height}", html.resolve().as_uri()],
                   check=True, capture_output=True, timeout=120)
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
