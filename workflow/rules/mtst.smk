# Multi-target stepping task (seed 001): one job per (study, method) that tracks and
# evaluates each trial, then Tables 1, 3, 4 and the trial figure.  A trial without mocap (annotations
# only) is tracked from its raw scan log; its pose comes from mtst.poles_m and its clock
# from the trial sheet (gaitval.pipeline.mtst).
include: "mtst_common.smk"


rule mtst_track:
    # one job per (study, method): each MTST trial tracked, then evaluated (two verbs of one
    # task; HOW JOBS RUN in common.smk)
    input:
        unpack(mtst_batch_inputs),
    output:
        track=directory(f"{RESULTS}/{{study}}/mtst_track/{{method}}"),
        evaluate=directory(f"{RESULTS}/{{study}}/mtst_eval/{{method}}"),
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["mtst"]),
        sensors=mtst_sensors,
        mocap=lambda w: [t for t in trial_ids(w.study, ["mtst"]) if has_mocap(w.study, t)],
        sizes=lambda w, input: [size_of(s) for s in mtst_sensors(w)],
        detections=first_or_empty("detections"),
        register=lambda w: register_dir(w.study, "mtst"),
    log:
        "logs/mtst_track/{study}/{method}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval mtst-trials --trials {params.trials:q} --sensors {params.sensors:q}"
        " --mocap-trials {params.mocap:q} --sizes {params.sizes:q}"
        " --register {params.register:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --method {wildcards.method:q} --detections={params.detections:q}"
        " --out {output.track:q} {output.evaluate:q} --threads {threads:q} --log {log:q}"


# An external method (tracking.external, issue 37): the other tracker's file of each trial,
# converted to gaitval's track (sensor clock and frame; a trial with mocap: with its
# registration), then the same evaluation as above.
ruleorder: mtst_track_external > mtst_track


rule mtst_track_external:
    input:
        unpack(mtst_batch_inputs),
        tracks=lambda w: [external_tracks_file(trial_wildcards(w.study, t, w.method))
                          for t in trial_ids(w.study, ["mtst"])],
    output:
        track=directory(f"{RESULTS}/{{study}}/mtst_track/{{method}}"),
        evaluate=directory(f"{RESULTS}/{{study}}/mtst_eval/{{method}}"),
    wildcard_constraints:
        method="|".join(re.escape(m) for m in external_methods("mtst")) or "(?!x)x",
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["mtst"]),
        sensors=mtst_sensors,
        mocap=lambda w: [t for t in trial_ids(w.study, ["mtst"]) if has_mocap(w.study, t)],
        register=lambda w: register_dir(w.study, "mtst"),
    log:
        "logs/mtst_track/{study}/{method}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval mtst-trials --trials {params.trials:q} --files {input.tracks:q}"
        " --sensors {params.sensors:q} --mocap-trials {params.mocap:q}"
        " --register {params.register:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --method {wildcards.method:q}"
        " --out {output.track:q} {output.evaluate:q} --threads {threads:q} --log {log:q}"


rule mtst_tables:
    input:
        evals=lambda w: [f"{RESULTS}/{study}/mtst_eval/{method}"
                         for study in config["run"] if trial_ids(study, ["mtst"])
                         for method in mtst_methods() + external_methods("mtst")],
        configs=study_views([STUDY_VIEW], "mtst"),  # the mtst: section
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        t3=report(
            f"{REPORTS}/tables/mtst_table3.csv",
            caption="../report/mtst.rst",
            category="MTST",
        ),
        t1=f"{REPORTS}/tables/mtst_table1.csv",
        t4=f"{REPORTS}/tables/mtst_table4.csv",
        fig=report(
            f"{REPORTS}/figures/mtst_trial.png",
            caption="../report/mtst.rst",
            category="MTST",
        ),
    params:
        dirs=lambda w: [str(Path(p).parent) for p in mtst_summaries(w)],
        methods=mtst_methods() + external_methods("mtst"),
        config=lambda w, input: input.configs[0],
        tables=parent_of("t3"),
        figures=parent_of("fig"),
        reports=parent_of("t3", up=1),
        chash=config_hash_when_run,
    priority: -10  # after every track job, beside the other tables (PRIORITIES in common.smk)
    log:
        "logs/mtst_tables.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval mtst-tables {params.dirs:q} --methods {params.methods:q}"
        " --config {params.config:q} --tables-dir {params.tables:q}"
        " --figures-dir {params.figures:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/mtst_table3.csv", f"{REPORTS}/figures/mtst_trial.png"]
        if trial_ids(study, ["mtst"])
        else []
    )
)
