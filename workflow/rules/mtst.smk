# Multi-target stepping task (seed 001): one job per (trial, method) that tracks and
# evaluates, then Tables 1, 3, 4 and the trial figure.  A trial without mocap (annotations
# only) is tracked from its raw scan log; its pose comes from mtst.poles_m and its clock
# from the trial sheet (gaitval.steps_mtst).
include: "mtst_common.smk"


rule mtst_track:
    # the tracking and then its evaluation: two gaitval steps in one job (see rule track)
    input:
        unpack(mtst_inputs),
    output:
        track=f"{RESULTS}/{{study}}/mtst_track/{{method}}/{{trial}}.parquet",
        summary=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/summary.parquet",
        contacts=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/contacts.parquet",
        steps=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/steps.parquet",
        events=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/events.parquet",
        gates=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/gates.parquet",
        track_field=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/track_field.parquet",
        targets=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/targets.parquet",
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        out=parent_of("summary"),
        reg=mtst_optional("reg", "--registration"),
        gt=mtst_optional("gt", "--groundtruth"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/mtst_track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} mtst-track --sensor {input.sensor:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} {params.reg:q} --out {output.track:q} > {log:q} 2>&1"
        " && {params.gv} mtst-evaluate --track {output.track:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} {params.reg:q} {params.gt:q} --out {params.out:q}"
        " >> {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


# An external method (tracking.external, issue 37): the other tracker's file of the trial,
# converted to gaitval's track (sensor clock and frame; a trial with mocap: with its
# registration), then the same evaluation as above.
ruleorder: mtst_track_external > mtst_track


rule mtst_track_external:
    input:
        unpack(mtst_inputs),
        tracks=external_tracks_file,
    output:
        track=f"{RESULTS}/{{study}}/mtst_track/{{method}}/{{trial}}.parquet",
        summary=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/summary.parquet",
        contacts=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/contacts.parquet",
        steps=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/steps.parquet",
        events=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/events.parquet",
        gates=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/gates.parquet",
        track_field=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/track_field.parquet",
        targets=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/targets.parquet",
    wildcard_constraints:
        method="|".join(re.escape(m) for m in external_methods("mtst")) or "(?!x)x",
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        out=parent_of("summary"),
        reg=mtst_optional("reg", "--registration"),
        gt=mtst_optional("gt", "--groundtruth"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/mtst_track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} import-tracks --tracks {input.tracks:q} --sensor {input.sensor:q}"
        " {params.reg:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {output.track:q} > {log:q} 2>&1"
        " && {params.gv} mtst-evaluate --track {output.track:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} {params.reg:q} {params.gt:q} --out {params.out:q}"
        " >> {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule mtst_tables:
    input:
        evals=mtst_summaries,
        configs=study_views([STUDY_VIEW], "mtst"),  # the mtst: section
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
        gv=GV,
        dirs=lambda w, input: [str(Path(p).parent) for p in input.evals],
        methods=mtst_methods() + external_methods("mtst"),
        config=lambda w, input: input.configs[0],
        tables=parent_of("t3"),
        figures=parent_of("fig"),
        reports=parent_of("t3", up=1),
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/mtst_tables.log",
    shell:
        "{params.gv} mtst-tables {params.dirs:q} --methods {params.methods:q}"
        " --config {params.config:q} --tables-dir {params.tables:q}"
        " --figures-dir {params.figures:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/mtst_table3.csv", f"{REPORTS}/figures/mtst_trial.png"]
        if trial_ids(study, ["mtst"])
        else []
    )
)
