# TUG leg tracking (seed 000): one job per (study, method) that tracks and evaluates each
# trial against its registered ground truth, then Tables 2-5 and the figures.  The methods run are
# tug_runs() (common.smk): tug.methods and their reading variants (tug.phase_readings).


rule track:
    # one job per (study, method): each TUG trial tracked, then evaluated against its
    # registered ground truth (two verbs of one task; HOW JOBS RUN in common.smk)
    input:
        ingest=f"{RESULTS}/{{study}}/ingest",
        register=f"{RESULTS}/{{study}}/register/tug",
        config=f"{RESULTS}/{{study}}/config_views/tug/{{method}}.json",
        sheet=lambda w: sheet_path(w.study),
        # the trials' observations, when another method shares this one's detector
        detections=detections_dir("tug"),
    output:
        track=directory(f"{RESULTS}/{{study}}/track/{{method}}"),
        evaluate=directory(f"{RESULTS}/{{study}}/evaluate/{{method}}"),
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["tug"]),
        sizes=lambda w, input: trial_sizes(w.study, trial_ids(w.study, ["tug"])),
        detections=first_or_empty("detections"),
    log:
        "logs/track/{study}/{method}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval track-trials --trials {params.trials:q} --sizes {params.sizes:q}"
        " --ingest {input.ingest:q} --register {input.register:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --method {wildcards.method:q} --detections={params.detections:q}"
        " --out {output.track:q} {output.evaluate:q} --threads {threads:q} --log {log:q}"


# An external method (tracking.external, issue 37): the other tracker's file of each trial,
# converted to gaitval's track (sensor clock and frame, with the trial's registration), then
# the same evaluation as above.
ruleorder: track_external > track


rule track_external:
    input:
        tracks=lambda w: [external_tracks_file(trial_wildcards(w.study, t, w.method))
                          for t in trial_ids(w.study, ["tug"])],
        ingest=f"{RESULTS}/{{study}}/ingest",
        register=f"{RESULTS}/{{study}}/register/tug",
        config=f"{RESULTS}/{{study}}/config_views/tug/{{method}}.json",
        sheet=lambda w: sheet_path(w.study),  # the params list its trials
    output:
        track=directory(f"{RESULTS}/{{study}}/track/{{method}}"),
        evaluate=directory(f"{RESULTS}/{{study}}/evaluate/{{method}}"),
    wildcard_constraints:
        method="|".join(re.escape(m) for m in external_methods("tug")) or "(?!x)x",
    threads: BATCH_THREADS
    params:
        trials=lambda w: trial_ids(w.study, ["tug"]),
    log:
        "logs/track/{study}/{method}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval import-tracks-trials --trials {params.trials:q} --files {input.tracks:q}"
        " --ingest {input.ingest:q} --register {input.register:q}"
        " --config {input.config:q} --method {wildcards.method:q}"
        " --out {output.track:q} {output.evaluate:q} --threads {threads:q} --log {log:q}"


rule tug_tables:
    input:
        evals=lambda w: [f"{RESULTS}/{study}/evaluate/{method}"
                         for study in config["run"] if trial_ids(study, ["tug"])
                         for method in tug_runs()],
        configs=study_views(tug_runs(), "tug"),  # Table 2: each study's method definitions
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        t4=report(
            f"{REPORTS}/tables/tug_table4.csv",
            caption="../report/tug.rst",
            category="TUG",
        ),
        t2=f"{REPORTS}/tables/tug_table2.csv",
        t3=f"{REPORTS}/tables/tug_table3.csv",
        t5=f"{REPORTS}/tables/tug_table5.csv",
        failures=f"{REPORTS}/tables/tug_failures.csv",
        fig=report(
            f"{REPORTS}/figures/tug_trajectories.png",
            caption="../report/tug.rst",
            category="TUG",
        ),
    params:
        dirs=lambda w: [f"{RESULTS}/{study}/evaluate/{method}/{trial}"
                        for study in config["run"]
                        for method in tug_runs()
                        for trial in trial_ids(study, ["tug"])],
        methods=tug_runs(),
        tables=parent_of("t4"),
        figures=parent_of("fig"),
        reports=parent_of("t4", up=1),
        chash=config_hash_when_run,
    priority: -10  # after every track job, beside the other tables (PRIORITIES in common.smk)
    log:
        "logs/tug_tables.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval tug-tables {params.dirs:q} --methods {params.methods:q}"
        " --tables-dir {params.tables:q} --figures-dir {params.figures:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q}"
        " --configs {input.configs:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/tug_table4.csv"] if trial_ids(study, ["tug"]) else []
)
