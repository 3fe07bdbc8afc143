# Robotic rollator (seed 002): the PF's parameters learned leave-one-subject-out, one job
# per (trial, method) for the KF and the PF that tracks and evaluates against the registered
# ground truth in the moving laser frame, then Tables I, II and the turning-trial figure.
# Paths stay under results/<study>/rollator/ with no "track/" or "evaluate/" folder, so the
# TUG rules' unconstrained patterns never match them.


include: "rollator_common.smk"


rule rollator_train:
    input:
        others=rollator_training_inputs,
        config=config_view_in("rollator"),
        sheet=lambda w: sheet_path(w.study),
    output:
        f"{RESULTS}/{{study}}/rollator/model/{{subject}}.json",
    wildcard_constraints:
        **ROLLATOR_WC,
    priority: 100  # critical path first (PRIORITIES in common.smk)
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        results=lambda w: f"{RESULTS}/{w.study}",
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/rollator_train/{study}/{subject}.log",
    shell:
        "{params.gv} rollator-train --results {params.results:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --subject {wildcards.subject:q}"
        " --config {input.config:q} --out {output:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule rollator_track:
    # the track and then its evaluation: two gaitval steps in one job (see rule track)
    input:
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        gt=f"{RESULTS}/{{study}}/register/{{trial}}/groundtruth.parquet",
        reg=f"{RESULTS}/{{study}}/register/{{trial}}/registration.json",
        mocap=f"{RESULTS}/{{study}}/ingest/{{trial}}/mocap.parquet",
        config=config_view_file,
        sheet=lambda w: sheet_path(w.study),
        model=rollator_model,
    output:
        track=f"{RESULTS}/{{study}}/rollator/{{method}}/{{trial}}.track.parquet",
        summary=f"{RESULTS}/{{study}}/rollator/{{method}}/{{trial}}/summary.parquet",
        frames=f"{RESULTS}/{{study}}/rollator/{{method}}/{{trial}}/frames.parquet",
    priority: -10  # last: fills both cores at the end (PRIORITIES in common.smk)
    wildcard_constraints:
        **ROLLATOR_WC,
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        model=lambda w, input: ["--model", str(input.model)] if input.model else [],
        ingest=lambda w, input: str(Path(input.mocap).parent),
        out=parent_of("summary"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/rollator_track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} rollator-track --sensor {input.sensor:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} {params.model:q} --out {output.track:q} > {log:q} 2>&1"
        " && {params.gv} rollator-evaluate --track {output.track:q} --groundtruth {input.gt:q}"
        " --registration {input.reg:q} --ingest {params.ingest:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {params.out:q} >> {log:q} 2>&1"
        " || (cat {log:q} >&2; exit 1)"


rule rollator_tables:
    input:
        evals=lambda w: [
            f"{RESULTS}/{study}/rollator/{method}/{trial}/summary.parquet"
            for study in config["run"]
            for method in rollator_methods() + external_methods("rollator")
            for trial in trial_ids(study, ["rollator"])
        ],
        models=lambda w: [
            f"{RESULTS}/{study}/rollator/model/{subject}.json"
            for study in config["run"]
            for subject in rollator_subjects(study)
        ],
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/rollator/{STUDY_VIEW}.json",
    output:
        t1=report(
            f"{REPORTS}/tables/rollator_table1.csv",
            caption="../report/rollator.rst",
            category="Rollator",
        ),
        t2=f"{REPORTS}/tables/rollator_table2.csv",
        imp=f"{REPORTS}/tables/rollator_improvement.csv",
        fig=report(
            f"{REPORTS}/figures/rollator_turning_trial.png",
            caption="../report/rollator.rst",
            category="Rollator",
        ),
    params:
        gv=GV,
        dirs=lambda w, input: [str(Path(p).parent) for p in input.evals],
        kf=lambda w: rollator_cfg()["kf_method"],
        pf=lambda w: rollator_cfg()["pf_method"],
        tables=parent_of("t1"),
        figures=parent_of("fig"),
        reports=parent_of("t1", up=1),
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/rollator_tables.log",
    shell:
        "{params.gv} rollator-tables {params.dirs:q} --kf {params.kf:q} --pf {params.pf:q}"
        " --models {input.models:q} --config {input.config:q}"
        " --tables-dir {params.tables:q} --figures-dir {params.figures:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/rollator_table1.csv"] if trial_ids(study, ["rollator"]) else []
    )
)
