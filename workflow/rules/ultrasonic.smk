# Ultrasonic foot tracking (seed 003): noise identification from the pendulum trials
# (Table 1), UKF track per treadmill trial, gait parameters, Tables 2-8, C1 and figures.
# Like every paper table, these pool the studies in `run`; the pendulum noise
# identification is shared by them (run studies with different hardware separately).
# Its result is the run's (results/runs/<run-name>/): another run (run=["tiny"]) has its
# own, so switching runs reruns neither's ultrasonic jobs.
NOISE = f"{RESULTS}/runs/{RUN_NAME}/ultrasonic_noise.json"


rule ultrasonic_noise:
    input:
        ingest=lambda w: sorted({f"{RESULTS}/{s}/ingest" for s, _ in pendulum_trials()}),
        # the study view (no method's definition): a tracker parameter changed elsewhere
        # does not rerun the noise identification and every ultrasonic track after it
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/ultrasonic/{STUDY_VIEW}.json",
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        noise=NOISE,
        table=report(
            f"{REPORTS}/tables/ultrasonic_table1.csv",
            caption="../report/ultrasonic.rst",
            category="Ultrasonic",
        ),
    priority: 100  # the ultrasonic tracks wait for it
    params:
        dirs=lambda w: [f"{RESULTS}/{s}/ingest/{t}" for s, t in pendulum_trials()],
        trials=lambda w: [t for _, t in pendulum_trials()],
        stem=lambda w, output: output.table[: -len(".csv")],
        reports=parent_of("table", up=1),
        # Table 1's provenance: the config hash of the run that made it.  A function of
        # `input`, so Snakemake does not rerun the job when only the hash changed (its
        # "derived" params are not compared); the config it reads is its input above.
        chash=config_hash_when_run,
    log:
        f"logs/ultrasonic_noise/{RUN_NAME}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval ultrasonic-noise --ingest {params.dirs:q} --trials {params.trials:q}"
        " --config {input.config:q} --out {output.noise:q} --table-stem {params.stem:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q} > {log:q} 2>&1"


rule ultrasonic_track:
    # one job per study: each treadmill trial's UKF track, then its gait parameters (two
    # verbs of one task; HOW JOBS RUN in common.smk)
    input:
        ingest=f"{RESULTS}/{{study}}/ingest",
        config=f"{RESULTS}/{{study}}/config_views/ultrasonic/{STUDY_VIEW}.json",
        noise=NOISE,
        sheet=lambda w: sheet_path(w.study),
    output:
        directory(f"{RESULTS}/{{study}}/ultrasonic"),
    threads: BATCH_THREADS
    priority: 50  # the ultrasonic tables, the longest table job, wait for it
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["treadmill"]),
        sizes=lambda w, input: trial_sizes(w.study, trial_ids(w.study, ["treadmill"])),
    log:
        "logs/ultrasonic_track/{study}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval ultrasonic-trials --trials {params.trials:q} --sizes {params.sizes:q}"
        " --ingest {input.ingest:q} --noise {input.noise:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --out {output:q} --threads {threads:q} --log {log:q}"


rule ultrasonic_tables:
    input:
        tracks=lambda w: sorted({f"{RESULTS}/{s}/ultrasonic" for s, _ in treadmill_trials()}),
        # ultrasonic.tables: the strides the tables use (the study view, as the noise rule)
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/ultrasonic/{STUDY_VIEW}.json",
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        t2=report(
            f"{REPORTS}/tables/ultrasonic_table2.csv",
            caption="../report/ultrasonic.rst",
            category="Ultrasonic",
        ),
        tC1=f"{REPORTS}/tables/ultrasonic_tableC1.csv",
        fig=report(
            f"{REPORTS}/figures/ultrasonic_fig5.png",
            caption="../report/ultrasonic.rst",
            category="Ultrasonic",
        ),
    params:
        gait=lambda w: [f"{RESULTS}/{s}/ultrasonic/gait/{t}.parquet"
                        for s, t in treadmill_trials()],
        tables=parent_of("t2"),
        figures=parent_of("fig"),
        reports=parent_of("t2", up=1),
        chash=config_hash_when_run,
    priority: -5  # the longest table job: the first of the tables (PRIORITIES, common.smk)
    log:
        "logs/ultrasonic_tables.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval ultrasonic-tables {params.gait:q} --tables-dir {params.tables:q}"
        " --figures-dir {params.figures:q} --reports-dir {params.reports:q}"
        " --config {input.config:q} --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/ultrasonic_table1.csv"]
    if trial_ids(study, ["pendulum"])
    else []
)
REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/ultrasonic_table2.csv"]
    if trial_ids(study, ["treadmill"])
    else []
)
