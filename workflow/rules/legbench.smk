# Annotated recordings without mocap (issue 18; docs/legbench.md): every trial of protocol
# `legbench` is tracked with each legbench.methods x legbench.inits, scored with CLEAR-MOT
# (py-motmetrics, legbench.match_m) against its hand annotations, and tabulated.
# Input functions: legbench_common.smk (snakemake --lint: rules and functions apart).
include: "legbench_common.smk"


rule legbench_track:
    # one job per (study, method, init): each trial tracked, then scored with CLEAR-MOT
    # against its annotations (two verbs of one task; HOW JOBS RUN in common.smk); the
    # topics, benchmark set, sector and leg width are read from the trial sheet
    input:
        sensors=lambda w: [trial_row(w.study, t)["sensor_path"] for t in legbench_trials(w.study)],
        annotations=lambda w: [legbench_annotations(w.study, t) for t in legbench_trials(w.study)],
        config=f"{RESULTS}/{{study}}/config_views/{ALL_SCOPE}/{{method}}.json",
        sheet=lambda w: sheet_path(w.study),
    output:
        track=directory(f"{RESULTS}/{{study}}/legbench/{{method}}/{{init}}"),
        evaluate=directory(f"{RESULTS}/{{study}}/legbench_eval/{{method}}/{{init}}"),
    wildcard_constraints:
        **LEGBENCH_WC,
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: legbench_trials(w.study),
        sizes=lambda w, input: [size_of(p) for p in input.sensors],
        match_m=legbench_cfg()["match_m"],
        min_false_s=legbench_cfg()["min_false_s"],
    log:
        "logs/legbench_track/{study}/{method}/{init}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval legbench-trials --trials {params.trials:q} --sizes {params.sizes:q}"
        " --sheet {input.sheet:q} --subjects {params.subjects:q} --config {input.config:q}"
        " --method {wildcards.method:q} --init {wildcards.init:q}"
        " --match-m {params.match_m:q} --min-false-s {params.min_false_s:q}"
        " --out {output.track:q} {output.evaluate:q} --threads {threads:q} --log {log:q}"


rule legbench_tables:
    input:
        evals=lambda w: [f"{RESULTS}/{study}/legbench_eval/{m}/{i}"
                         for study in config["run"] if legbench_trials(study)
                         for m in legbench_cfg()["methods"] for i in legbench_cfg()["inits"]],
        # the method views the tracks ran with: a method run with tracking.overrides is
        # named with its changes in the table
        views=study_views(legbench_cfg()["methods"], ALL_SCOPE),
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        table=report(
            f"{REPORTS}/tables/legbench_clearmot.csv",
            caption="../report/legbench.rst",
            category="Annotated recordings",
        ),
        md=f"{REPORTS}/tables/legbench_clearmot.md",
        fig=report(
            f"{REPORTS}/figures/legbench_tracks.png",
            caption="../report/legbench.rst",
            category="Annotated recordings",
        ),
    params:
        dirs=lambda w: [d for study in config["run"] for d in legbench_eval_dirs(study)],
        views=lambda w, input: str(Path(input.views[0]).parent),
        methods=legbench_cfg()["methods"],
        inits=legbench_cfg()["inits"],
        tables=parent_of("table"),
        figures=parent_of("fig"),
        reports=parent_of("table", up=1),
        chash=LEGBENCH_HASH,
    log:
        "logs/legbench_tables.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval legbench-tables {params.dirs:q} --methods {params.methods:q}"
        " --inits {params.inits:q} --views-dir {params.views:q}"
        " --tables-dir {params.tables:q} --figures-dir {params.figures:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q} > {log:q} 2>&1"


rule legbench_crowd:
    # the multi-person benchmark: rendered scenes, no recording read (docs/crowd.md)
    output:
        table=report(
            f"{REPORTS}/tables/legbench_crowd.csv",
            caption="../report/legbench.rst",
            category="Annotated recordings",
        ),
        md=f"{REPORTS}/tables/legbench_crowd.md",
        scenes=f"{REPORTS}/tables/legbench_crowd_scenes.csv",
    params:
        tables=parent_of("table"),
        # no file input: gaitval's source digest makes new tracker code rerun the scenes
        source=SOURCE_DIGEST,
    log:
        "logs/legbench_crowd.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval legbench-crowd --tables-dir {params.tables:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/legbench_clearmot.csv", f"{REPORTS}/figures/legbench_tracks.png",
         f"{REPORTS}/tables/legbench_crowd.csv"]
        if legbench_trials(study)
        else []
    )
)
