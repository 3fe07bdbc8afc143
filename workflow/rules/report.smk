# Gather every table and figure of the studies in `run` into reports/<run-name>/index.{md,html}
# with the verdict table (verdicts.*) on top, and, once per report, what a reviewer needs
# to rerun it (provenance/: resolved config, sha256 of every input file, exact package
# versions, git commit, the rebuild command; gaitval.report.provenance).
import json

from gaitval.io.atomic import write_text
from gaitval.report.provenance import (config_hash, rebuild_command, study_input_files,
                                       write_workflow_record)


localrules:
    report_config,


# Where this run's report goes, for `run.py report` to read the report's analysed.json
# after Snakemake ends (its closing summary of refused trials and its exit code).
write_text("logs/run_target.json", json.dumps({"reports": REPORTS, "run": list(config["run"])}) + "\n")


rule report_config:
    input:
        lambda w: sorted(
            {f for s in config["run"]
             for f in study_input_files(sheet_path(s), subjects_path(s), trials(s))}
            | {str(Path(f).resolve()) for s in config["run"] for f in external_input_files(s)}
            | {str(Path(f).resolve()) for f in workflow.configfiles if Path(f).is_file()}
            | {str(PRESETS / f"{study_cfg(s)['simulate']['preset']}.yaml")
               for s in config["run"] if is_simulated(s)}
            | ({PEER_EXAMPLE} if PEER_EXAMPLE else set())
            | {str(Path(e["path"]).resolve()) for e in AGREEMENT_FILES.values()}
        ),
    output:
        config=f"{REPORTS}/provenance/config.yaml",
        inputs=f"{REPORTS}/provenance/inputs.txt",
        rebuild=f"{REPORTS}/provenance/rebuild.json",
    log:
        f"logs/report_config/{RUN_NAME}.log",
    params:
        # the whole resolved config (paths and `run` too), so any change rewrites it
        chash=config_hash(config),
        command=rebuild_command(
            _cli_configfiles(),
            _cli_config(),
            Path.cwd(),
        ),
    run:
        write_workflow_record(config, input, output, log[0], **params)


rule report:
    input:
        report_items,
        rules.report_config.output,
        study_configs,  # results/<study>/config.json, for running a step by hand (docs/formats.md)
    output:
        md=report(f"{REPORTS}/index.md", caption="../report/index.rst", category="Report"),
        html=f"{REPORTS}/index.html",
        verdicts=multiext(f"{REPORTS}/verdicts", ".csv", ".md", ".tex"),
        analysed=f"{REPORTS}/analysed.json",
    params:
        reports=parent_of("md"),
        studies=list(config["run"]),
    log:
        f"logs/report/{RUN_NAME}.log",
    # no index over a partial report (--complete): every item a step's provenance lists
    # is there, no file of the report is left unfinished by an interrupted job
    # (gaitval/jobs/resume.py)
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval report --reports-dir {params.reports:q} --studies {params.studies:q}"
        " --complete {output:q} > {log:q} 2>&1"


include: "report_common.smk"


rule tug_paper_figures:
    input:
        lambda w: paper_figure_inputs("tug"),
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["tug"]],
    params:
        study=lambda w: paper_figure_study("tug"),
        config=lambda w, input: [f for f in input if str(f).endswith(".json")],
        chash=config_hash_when_run,
        args=paper_figures_args("tug"),
    priority: -10  # after the track jobs, beside the tables (PRIORITIES in common.smk)
    log:
        "logs/paper_figures/tug.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval paper-figures {params.args:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["tug"]]
    if study == paper_figure_study("tug") else []
)


rule mtst_paper_figures:
    input:
        lambda w: paper_figure_inputs("mtst"),
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["mtst"]],
    params:
        study=lambda w: paper_figure_study("mtst"),
        config=lambda w, input: [f for f in input if str(f).endswith(".json")],
        chash=config_hash_when_run,
        args=paper_figures_args("mtst"),
    priority: -10  # after the track jobs, beside the tables (PRIORITIES in common.smk)
    log:
        "logs/paper_figures/mtst.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval paper-figures {params.args:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["mtst"]]
    if study == paper_figure_study("mtst") else []
)


rule rollator_paper_figures:
    input:
        lambda w: paper_figure_inputs("rollator"),
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["rollator"]],
    params:
        study=lambda w: paper_figure_study("rollator"),
        config=lambda w, input: [f for f in input if str(f).endswith(".json")],
        chash=config_hash_when_run,
        args=paper_figures_args("rollator"),
    priority: -10  # after the track jobs, beside the tables (PRIORITIES in common.smk)
    log:
        "logs/paper_figures/rollator.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval paper-figures {params.args:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["rollator"]]
    if study == paper_figure_study("rollator") else []
)


rule ultrasonic_paper_figures:
    input:
        lambda w: paper_figure_inputs("ultrasonic"),
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["ultrasonic"]],
    params:
        study=lambda w: paper_figure_study("ultrasonic"),
        config=lambda w, input: [f for f in input if str(f).endswith(".json")],
        chash=config_hash_when_run,
        args=paper_figures_args("ultrasonic"),
    priority: -10  # after the track jobs, beside the tables (PRIORITIES in common.smk)
    log:
        "logs/paper_figures/ultrasonic.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval paper-figures {params.args:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/figures/{stem}.png" for stem in PAPER_FIGURES["ultrasonic"]]
    if study == paper_figure_study("ultrasonic") else []
)
