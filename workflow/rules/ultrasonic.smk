# Ultrasonic foot tracking (seed 003): noise identification from the pendulum trials
# (Table 1), UKF track per treadmill trial, gait parameters, Tables 2-8, C1 and figures.
# Like every paper table, these pool the studies in `run`; the pendulum noise
# identification is shared by them (run studies with different hardware separately).


rule ultrasonic_noise:
    input:
        ingest=lambda w: [
            f"{RESULTS}/{s}/ingest/{t}/sensor.parquet" for s, t in pendulum_trials()
        ],
        # the study view (no method's definition): a tracker parameter changed elsewhere
        # does not rerun the noise identification and every ultrasonic track after it
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/ultrasonic/{STUDY_VIEW}.json",
    output:
        noise=f"{RESULTS}/ultrasonic_noise.json",
        table=report(
            f"{REPORTS}/tables/ultrasonic_table1.csv",
            caption="../report/ultrasonic.rst",
            category="Ultrasonic",
        ),
    priority: 100  # critical path first (PRIORITIES in common.smk)
    params:
        gv=GV,
        dirs=lambda w, input: [str(Path(p).parent) for p in input.ingest],
        trials=lambda w: [t for _, t in pendulum_trials()],
        stem=lambda w, output: output.table[: -len(".csv")],
        reports=parent_of("table", up=1),
        # Table 1's provenance: the config hash of the run that made it.  A function of
        # `input`, so Snakemake does not rerun the job when only the hash changed (its
        # "derived" params are not compared); the config it reads is its input above.
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/ultrasonic_noise.log",
    shell:
        "{params.gv} ultrasonic-noise --ingest {params.dirs:q} --trials {params.trials:q}"
        " --config {input.config:q} --out {output.noise:q} --table-stem {params.stem:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule ultrasonic_track:
    # the UKF track and then its gait parameters: two gaitval steps in one job (rule track)
    input:
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        mocap=f"{RESULTS}/{{study}}/ingest/{{trial}}/mocap.parquet",
        config=config_view_file,
        noise=f"{RESULTS}/ultrasonic_noise.json",
        sheet=lambda w: sheet_path(w.study),
    output:
        track=f"{RESULTS}/{{study}}/ultrasonic/track/{{trial}}.parquet",
        gait=f"{RESULTS}/{{study}}/ultrasonic/gait/{{trial}}.parquet",
    priority: 50  # critical path first (PRIORITIES in common.smk)
    params:
        gv=GV,
        ingest=lambda w, input: str(Path(input.sensor).parent),
        subjects=lambda w: subjects_path(w.study),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/ultrasonic_track/{study}/{trial}.log",
    shell:
        "{params.gv} ultrasonic-track --ingest {params.ingest:q} --trial {wildcards.trial:q}"
        " --config {input.config:q} --noise {input.noise:q} --out {output.track:q}"
        " > {log:q} 2>&1"
        " && {params.gv} gait-parameters --track {output.track:q} --ingest {params.ingest:q}"
        " --sheet {input.sheet:q} --subjects {params.subjects:q} --trial {wildcards.trial:q}"
        " --config {input.config:q} --out {output.gait:q} >> {log:q} 2>&1"
        " || (cat {log:q} >&2; exit 1)"


rule ultrasonic_tables:
    input:
        gait=lambda w: [
            f"{RESULTS}/{s}/ultrasonic/gait/{t}.parquet" for s, t in treadmill_trials()
        ],
        # ultrasonic.tables: the strides the tables use (the study view, as the noise rule)
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/ultrasonic/{STUDY_VIEW}.json",
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
        gv=GV,
        tables=parent_of("t2"),
        figures=parent_of("fig"),
        reports=parent_of("t2", up=1),
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/ultrasonic_tables.log",
    shell:
        "{params.gv} ultrasonic-tables {input.gait:q} --tables-dir {params.tables:q}"
        " --figures-dir {params.figures:q} --reports-dir {params.reports:q}"
        " --config {input.config:q} --config-hash {params.chash:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


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
