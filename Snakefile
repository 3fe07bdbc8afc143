# gaitval workflow.  The rules live in workflow/rules/*.smk; see docs/architecture.md and
# README.md.  Run:  snakemake --profile workflow/profiles/default
from pathlib import Path

from snakemake.utils import min_version

min_version("8.0")


# Relative to the Snakefile, so `snakemake --directory ELSEWHERE` still finds it.
configfile: Path(workflow.basedir) / "config" / "config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/ingest.smk"
include: "workflow/rules/register.smk"
include: "workflow/rules/detect.smk"
include: "workflow/rules/tug.smk"
include: "workflow/rules/mtst.smk"
include: "workflow/rules/ultrasonic.smk"
include: "workflow/rules/peer.smk"
include: "workflow/rules/rollator.smk"
include: "workflow/rules/external.smk"
include: "workflow/rules/legbench.smk"
include: "workflow/rules/report.smk"


rule all:
    input:
        f"{REPORTS}/index.md",
        f"{REPORTS}/index.html",
    default_target: True
