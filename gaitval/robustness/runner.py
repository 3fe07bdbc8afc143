"""Run the robustness ensemble: design the twins, build each twin's report with the
workflow (one Snakemake run per twin, ``run=[<twin>]``, so each twin is an ordinary study
and its jobs run wherever the given profile sends them), then the robustness table.

``gaitval robustness run [--config FILE] [--workdir DIR] [--snakemake ARGS...]``;
``python3 run.py robustness`` calls it and then rebuilds the base study's report so its
verdicts show the shares.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path


from gaitval.robustness.design import ROOT, load_config, read_design, write_ensemble

#: Snakemake's dry-run flags: the twins' jobs are listed, no table is made.
DRY_RUN = {"-n", "--dry-run", "--dryrun"}
#: Where the ensemble writes, relative to the working folder.
OUT = Path("reports") / "robustness"


def snakemake_cmd(conf: Path, twin: str, out: Path, extra: list[str]) -> list[str]:
    """The Snakemake command that builds one twin's report under ``out/twins``."""
    exe = Path(sys.executable).with_name("snakemake")
    return [str(exe), "--snakefile", str(ROOT / "Snakefile"), "--configfile", str(conf),
            "--config", f'run=["{twin}"]', f"reports_dir={out / 'twins'}", *extra]


def run_ensemble(config: str | Path | None = None, workdir: str | Path = ".",
                 extra: list[str] | None = None) -> int:
    """Design, every twin's report, the table; Snakemake's exit code on a failed twin."""
    from gaitval.robustness.summary import write_robustness

    cfg = load_config(config)
    work = Path(workdir).resolve()
    out = work / OUT
    design, conf = write_ensemble(cfg, out)
    extra = list(extra or [])
    if "--directory" not in extra and "-d" not in extra:
        extra = ["--directory", str(work), *extra]
    for twin in design.index:
        cmd = snakemake_cmd(conf, twin, out, extra)
        print("[robustness] " + " ".join(cmd), flush=True)
        rc = subprocess.call(cmd, cwd=work)
        if rc:
            return rc
    if DRY_RUN & set(extra):
        print("[robustness] dry run: no twin report, no table", flush=True)
        return 0
    for p in write_robustness(read_design(out),
                              out / "twins", cfg, out):
        print(p, flush=True)
    return 0


def robustness_step(step: str, config=None, out=None, reports_dir=None, workdir=".",
                    extra: list[str] | None = None) -> int:
    """``gaitval robustness design|table|run`` (the verb's handler, gaitval/cli/study.py).

    ``design --out DIR`` writes the twins' presets, ``DIR/design.csv`` and
    ``DIR/ensemble.yaml`` (the Snakemake config file declaring the twins as studies) and
    prints its path, the twins' names and the base study; ``run [--workdir DIR]
    [--snakemake ARGS...]`` does all three in DIR; ``table --out DIR --reports-dir TWINS`` writes
    ``DIR/robustness.*`` from each twin's ``TWINS/<twin>/verdicts.csv``."""
    from gaitval.errors import ConfigError

    if step == "run":
        return run_ensemble(config, workdir, list(extra or []))
    if out is None:
        raise ConfigError(f"gaitval robustness {step} needs --out")
    out = Path(out)
    cfg = load_config(config)
    if step == "design":
        table, conf = write_ensemble(cfg, out)
        print(conf)
        print(" ".join(table.index))
        print(cfg.get("base_study", "default"))
        return 0
    from gaitval.robustness.summary import write_robustness

    design = read_design(out)
    for p in write_robustness(design, reports_dir or out / "twins", cfg, out):
        print(p)
    return 0
