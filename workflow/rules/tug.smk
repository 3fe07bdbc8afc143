# TUG leg tracking (seed 000): one job per (trial, method) that tracks and evaluates
# against the registered ground truth, then Tables 2-5 and the figures.  The methods run are
# tug_runs() (common.smk): tug.methods and their reading variants (tug.phase_readings).


rule track:
    # the tracking and then its evaluation against the registered ground truth: two gaitval
    # steps in one job (one job fewer per (trial, method) for Snakemake to schedule and
    # record, issue 13); on a cluster the same two commands run in one job's shell
    input:
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        gt=f"{RESULTS}/{{study}}/register/{{trial}}/groundtruth.parquet",
        reg=f"{RESULTS}/{{study}}/register/{{trial}}/registration.json",
        config=config_view_file,
        sheet=lambda w: sheet_path(w.study),
    output:
        track=f"{RESULTS}/{{study}}/track/{{method}}/{{trial}}.parquet",
        summary=f"{RESULTS}/{{study}}/evaluate/{{method}}/{{trial}}/summary.parquet",
        frames=f"{RESULTS}/{{study}}/evaluate/{{method}}/{{trial}}/frames.parquet",
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        out=parent_of("summary"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} track --sensor {input.sensor:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {output.track:q} > {log:q} 2>&1"
        " && {params.gv} evaluate-tug --track {output.track:q} --groundtruth {input.gt:q}"
        " --registration {input.reg:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {params.out:q} >> {log:q} 2>&1"
        " || (cat {log:q} >&2; exit 1)"


# An external method (tracking.external, issue 37): the other tracker's file of the trial,
# converted to gaitval's track (sensor clock and frame, with the trial's registration), then
# the same evaluation as above.
ruleorder: track_external > track


rule track_external:
    input:
        tracks=external_tracks_file,
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        gt=f"{RESULTS}/{{study}}/register/{{trial}}/groundtruth.parquet",
        reg=f"{RESULTS}/{{study}}/register/{{trial}}/registration.json",
        config=config_view_file,
    output:
        track=f"{RESULTS}/{{study}}/track/{{method}}/{{trial}}.parquet",
        summary=f"{RESULTS}/{{study}}/evaluate/{{method}}/{{trial}}/summary.parquet",
        frames=f"{RESULTS}/{{study}}/evaluate/{{method}}/{{trial}}/frames.parquet",
    wildcard_constraints:
        method="|".join(re.escape(m) for m in external_methods("tug")) or "(?!x)x",
    params:
        gv=GV,
        out=parent_of("summary"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} import-tracks --tracks {input.tracks:q} --sensor {input.sensor:q}"
        " --registration {input.reg:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {output.track:q} > {log:q} 2>&1"
        " && {params.gv} evaluate-tug --track {output.track:q} --groundtruth {input.gt:q}"
        " --registration {input.reg:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {params.out:q} >> {log:q} 2>&1"
        " || (cat {log:q} >&2; exit 1)"


rule tug_tables:
    input:
        evals=lambda w: [
            f"{RESULTS}/{study}/evaluate/{method}/{trial}/summary.parquet"
            for study in config["run"]
            for method in tug_runs()
            for trial in trial_ids(study, ["tug"])
        ],
        configs=study_views(tug_runs(), "tug"),  # Table 2: each study's method definitions
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
        gv=GV,
        dirs=lambda w, input: [str(Path(p).parent) for p in input.evals],
        methods=tug_runs(),
        tables=parent_of("t4"),
        figures=parent_of("fig"),
        reports=parent_of("t4", up=1),
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/tug_tables.log",
    shell:
        "{params.gv} tug-tables {params.dirs:q} --methods {params.methods:q}"
        " --tables-dir {params.tables:q} --figures-dir {params.figures:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q}"
        " --configs {input.configs:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/tug_table4.csv"] if trial_ids(study, ["tug"]) else []
)
