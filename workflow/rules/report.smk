# Gather every table and figure of the studies in `run` into reports/<run-name>/index.{md,html}
# with the verdict table (verdicts.*) on top, and, once per report, what a reviewer needs
# to rerun it (provenance/: resolved config, sha256 of every input file, exact package
# versions, git commit, the rebuild command; gaitval.report.provenance).
from gaitval.report.provenance import (config_hash, rebuild_command, study_input_files,
                                       write_workflow_record)


localrules:
    report_config,


rule report_config:
    input:
        lambda w: sorted(
            {f for s in config["run"]
             for f in study_input_files(sheet_path(s), subjects_path(s), trials(s))}
            | {str(Path(f).resolve()) for s in config["run"] for f in external_input_files(s)}
            | {str(Path(f).resolve()) for f in workflow.configfiles if Path(f).is_file()}
            | {str(PRESETS / f"{study_cfg(s)['simulate']['preset']}.yaml")
               for s in config["run"] if is_simulated(s)}
            | ({config["peer_results"]} if config.get("peer_results")
               and Path(config["peer_results"]).is_file() else set())
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
            list(getattr(workflow.config_settings, "configfiles", None) or ()),
            dict(getattr(workflow.config_settings, "config", None) or {}),
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
    params:
        reports=parent_of("md"),
        studies=list(config["run"]),
    log:
        f"logs/report/{RUN_NAME}.log",
    run:
        # no index over a partial report: every item a step's provenance lists is there,
        # no file of the report is left unfinished by an interrupted job (jobs/resume.py)
        from gaitval.jobs.resume import refuse_unfinished

        refuse_unfinished(params.reports, own_outputs=list(output))
        run_verb_job(verb("report", "--reports-dir", params.reports, "--studies",
                          params.studies), log[0])
