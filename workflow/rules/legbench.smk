# Annotated recordings without mocap (issue 18; docs/legbench.md): every trial of protocol
# `legbench` is tracked with each legbench.methods x legbench.inits, scored with CLEAR-MOT
# (py-motmetrics, legbench.match_m) against its hand annotations, and tabulated.
# Input functions: legbench_common.smk (snakemake --lint: rules and functions apart).
include: "legbench_common.smk"


rule legbench_track:
    input:
        sensor=lambda w: trial_row(w.study, w.trial)["sensor_path"],
        annotations=lambda w: legbench_annotations(w.study, w.trial),
        config=config_view_file,
    output:
        f"{RESULTS}/{{study}}/legbench/{{method}}/{{init}}/{{trial}}/track.parquet",
    wildcard_constraints:
        **LEGBENCH_WC,
    params:
        gv=GV,
        topics=legbench_args,
        leg_width=legbench_leg_width,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/legbench_track/{study}/{method}/{init}/{trial}.log",
    shell:
        "{params.gv} legbench-track --sensor {input.sensor:q} --annotations {input.annotations:q}"
        " {params.topics:q} --method {wildcards.method:q} --init {wildcards.init:q}"
        " --leg-width-m {params.leg_width:q} --config {input.config:q}"
        " --trial {wildcards.trial:q} --out {output:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule legbench_evaluate:
    input:
        track=f"{RESULTS}/{{study}}/legbench/{{method}}/{{init}}/{{trial}}/track.parquet",
        annotations=lambda w: legbench_annotations(w.study, w.trial),
    output:
        summary=f"{RESULTS}/{{study}}/legbench_eval/{{method}}/{{init}}/{{trial}}/summary.parquet",
        frames=f"{RESULTS}/{{study}}/legbench_eval/{{method}}/{{init}}/{{trial}}/frames.parquet",
    wildcard_constraints:
        **LEGBENCH_WC,
    params:
        gv=GV,
        topics=legbench_args,
        score=legbench_score_args,
        out=parent_of("summary"),
        match_m=legbench_cfg()["match_m"],
        min_false_s=legbench_cfg()["min_false_s"],
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/legbench_evaluate/{study}/{method}/{init}/{trial}.log",
    shell:
        "{params.gv} legbench-evaluate --track {input.track:q} --annotations {input.annotations:q}"
        " {params.topics:q} {params.score:q} --match-m {params.match_m:q}"
        " --min-false-s {params.min_false_s:q}"
        " --trial {wildcards.trial:q} --out {params.out:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule legbench_tables:
    input:
        evals=lambda w: [
            f"{d}/summary.parquet" for study in config["run"] for d in legbench_eval_dirs(study)
        ],
        # the method views the tracks ran with: a method run with tracking.overrides is
        # named with its changes in the table
        views=study_views(legbench_cfg()["methods"], ALL_SCOPE),
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
        gv=GV,
        dirs=lambda w, input: [str(Path(p).parent) for p in input.evals],
        views=lambda w, input: str(Path(input.views[0]).parent),
        methods=legbench_cfg()["methods"],
        inits=legbench_cfg()["inits"],
        tables=parent_of("table"),
        figures=parent_of("fig"),
        reports=parent_of("table", up=1),
        chash=LEGBENCH_HASH,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/legbench_tables.log",
    shell:
        "{params.gv} legbench-tables {params.dirs:q} --methods {params.methods:q}"
        " --inits {params.inits:q} --views-dir {params.views:q} --tables-dir {params.tables:q}"
        " --figures-dir {params.figures:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/legbench_clearmot.csv", f"{REPORTS}/figures/legbench_tracks.png"]
        if legbench_trials(study)
        else []
    )
)
