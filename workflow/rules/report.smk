# Gather every table and figure of the studies in `run` into reports/index.{md,html}, with
# the verdict table (reports/verdicts.*) on top.


rule report:
    input:
        report_items,
    output:
        md=report(f"{REPORTS}/index.md", caption="../report/index.rst", category="Report"),
        html=f"{REPORTS}/index.html",
        verdicts=multiext(f"{REPORTS}/verdicts", ".csv", ".md", ".tex"),
    params:
        gv=GV,
        reports=parent_of("md"),
        studies=list(config["run"]),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/report.log",
    shell:
        "{params.gv} report --reports-dir {params.reports:q} --studies {params.studies:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"
