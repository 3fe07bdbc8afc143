# Raw trial files -> tidy per-trial files (one job per trial), and a per-study summary.


rule ingest:
    input:
        unpack(ingest_inputs),
    output:
        mocap=f"{RESULTS}/{{study}}/ingest/{{trial}}/mocap.parquet",
        events=f"{RESULTS}/{{study}}/ingest/{{trial}}/events.csv",
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        annotations=f"{RESULTS}/{{study}}/ingest/{{trial}}/annotations.csv",
        summary=f"{RESULTS}/{{study}}/ingest/{{trial}}/ingest.json",
    priority: 20  # critical path first (PRIORITIES in common.smk)
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        out=parent_of("mocap"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/ingest/{study}/{trial}.log",
    shell:
        "{params.gv} ingest --sheet {input.sheet:q} --subjects {params.subjects:q}"
        " --trial {wildcards.trial:q} --out {params.out:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule ingest_summary:
    input:
        lambda w: expand(
            f"{RESULTS}/{{study}}/ingest/{{trial}}/ingest.json",
            study=w.study,
            trial=mocap_trial_ids(w.study),
        ),
    output:
        csv=report(
            f"{REPORTS}/tables/study_ingest_{{study}}.csv",
            caption="../report/ingest.rst",
            category="Study",
        ),
        md=f"{REPORTS}/tables/study_ingest_{{study}}.md",
        tex=f"{REPORTS}/tables/study_ingest_{{study}}.tex",
    params:
        gv=GV,
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/ingest_summary/{study}.log",
    shell:
        "{params.gv} ingest-summary {input:q} --study {wildcards.study:q} --out-stem {params.stem:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


# Ingest reads mocap: a study whose trials all have annotations only has no ingest table.
REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/study_ingest_{study}.csv"] if mocap_trial_ids(study) else []
    )
)
