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
    log:
        "logs/ingest/{study}.log",
    run:
        run_trials(
            [(t, [verb("ingest", "--sheet", input.sheet, "--subjects", params.subjects,
                       "--trial", t, "--out", f"{output[0]}/{t}")])
             for t in params.trials],
            threads, log[0], outdirs=output,
            sizes=[trial_bytes(wildcards.study, t) for t in params.trials],
        )


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
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    log:
        "logs/ingest_summary/{study}.log",
    run:
        run_verb_job(
            verb("ingest-summary", [f"{input[0]}/{t}/ingest.json" for t in params.trials],
                 "--study", wildcards.study, "--out-stem", params.stem,
                 "--reports-dir", params.reports, "--config-hash", params.chash),
            log[0],
        )


# Ingest reads mocap: a study whose trials all have annotations only has no ingest table.
REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/study_ingest_{study}.csv"] if mocap_trial_ids(study) else []
    )
)
