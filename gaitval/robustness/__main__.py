"""``python -m gaitval.robustness design|table|run``: the ensemble's twins, its table, or
both with every twin's report between them (:mod:`gaitval.robustness.runner`).

``design --out DIR`` writes the twins' presets, ``DIR/design.csv`` and ``DIR/ensemble.yaml``
(the Snakemake config file declaring the twins as studies) and prints its path, the twins' names and the base study;
``run [--workdir DIR] [-- SNAKEMAKE ARGS]`` does all three in DIR (default: here);
``table --out DIR --reports-dir TWINS`` writes ``DIR/robustness.*`` from each twin's
``TWINS/<twin>/verdicts.csv``.  ``--config`` names the ensemble's configuration
(default ``config/robustness.yaml``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


from gaitval.robustness.design import load_config, read_design, write_ensemble


def main(argv: list[str] | None = None) -> int:
    """The command line; a gaitval error ends it with its one-line message (exit 2)."""
    from gaitval.errors import GaitvalError

    try:
        return _main(argv)
    except GaitvalError as exc:
        print(f"gaitval.robustness: {exc}", file=sys.stderr)
        return 2


def _main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    argv = list(sys.argv[1:] if argv is None else argv)
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    argv = argv[:argv.index("--")] if "--" in argv else argv
    ap.add_argument("step", choices=["design", "table", "run"])
    ap.add_argument("--config", type=Path, default=None)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--reports-dir", type=Path, default=None)
    ap.add_argument("--workdir", type=Path, default=Path("."))
    a = ap.parse_args(argv)
    if a.step == "run":
        from gaitval.robustness.runner import run_ensemble

        return run_ensemble(a.config, a.workdir, extra)
    if a.out is None:
        ap.error(f"{a.step} needs --out")
    cfg = load_config(a.config)
    if a.step == "design":
        table, conf = write_ensemble(cfg, a.out)
        print(conf)
        print(" ".join(table.index))
        print(cfg.get("base_study", "default"))
        return 0
    from gaitval.robustness.summary import write_robustness

    design = read_design(a.out)
    for p in write_robustness(design, a.reports_dir or a.out / "twins", cfg, a.out):
        print(p)
    return 0


if __name__ == "__main__":                                    # pragma: no cover
    raise SystemExit(main())
