# Raw trial files -> tidy per-trial files, and a per-study summary.  One job per study:
# every trial with mocap ingested into results/<study>/ingest/<trial>/ (HOW JOBS RUN in
# common.smk).


rule ingest:
    input:
        sheet=lambda w: sheet_path(w.study),
        raw=lambda w: study_raw_files(w.study),   # editing a trial's file reruns the study's
    output:
        directory(f"{RESULTS}/{{study}}/ingest"),
    threads: BATCH_THREADS
    priority: 20  # everything reads it
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: mocap_trial_ids(w.study),
        sizes=lambda w, input: trial_sizes(w.study, mocap_trial_ids(w.study)),
    log:
        "logs/ingest/{study}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval ingest-trials --trials {params.trials:q} --sizes {params.sizes:q}"
        " --sheet {input.sheet:q} --subjects {params.subjects:q}"
        " --out {output:q} --threads {threads:q} --log {log:q}"


rule ingest_summary:
    input:
        f"{RESULTS}/{{study}}/ingest",
        sheet=lambda w: sheet_path(w.study),  # the params list its trials
    output:
        csv=report(
            f"{REPORTS}/tables/study_ingest_{{study}}.csv",
            caption="../report/ingest.rst",
            category="Study",
        ),
        md=f"{REPORTS}/tables/study_ingest_{{study}}.md",
        tex=f"{REPORTS}/tables/study_ingest_{{study}}.tex",
    params:
        trials=lambda w: mocap_trial_ids(w.study),
        summaries=lambda w, input: [f"{input[0]}/{t}/ingest.json"
                                    for t in mocap_trial_ids(w.study)],
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    log:
        "logs/ingest_summary/{study}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval ingest-summary {params.summaries:q} --study {wildcards.study:q}"
        " --out-stem {params.stem:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1"


# Ingest reads mocap: a study whose trials all have annotations only has no ingest table.
REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/study_ingest_{study}.csv"] if mocap_trial_ids(study) else []
    )
)
