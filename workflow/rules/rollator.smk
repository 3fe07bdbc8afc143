# Robotic rollator (seed 002): the PF's parameters learned leave-one-subject-out, one job
# per (study, method) for the KF and the PF that tracks and evaluates each trial against its
# registered ground truth in the moving laser frame, then Tables I, II and the turning-trial figure.
# Paths stay under results/<study>/rollator/ with no "track/" or "evaluate/" folder, so the
# TUG rules' unconstrained patterns never match them.


include: "rollator_common.smk"


rule rollator_train:
    # one job per study: the PF model of each held-out subject, learned from the others'
    # trials (leave-one-subject-out; HOW JOBS RUN in common.smk)
    input:
        ingest=f"{RESULTS}/{{study}}/ingest",
        register=f"{RESULTS}/{{study}}/register/rollator",
        config=f"{RESULTS}/{{study}}/config_views/rollator/{STUDY_VIEW}.json",
        sheet=lambda w: sheet_path(w.study),
    output:
        directory(f"{RESULTS}/{{study}}/rollator/model"),
    wildcard_constraints:
        **ROLLATOR_WC,
    threads: BATCH_THREADS
    priority: 100  # the PF tracks wait for it
    params:
        subjects=lambda w: subjects_path(w.study),
        results=lambda w: f"{RESULTS}/{w.study}",
        held_out=lambda w: rollator_subjects(w.study),
    log:
        "logs/rollator_train/{study}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval rollator-train-subjects --trials {params.held_out:q}"
        " --results {params.results:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --out {output:q} --threads {threads:q} --log {log:q}"


rule rollator_track:
    # one job per (study, method): each rollator trial tracked (the KF, or the PF with its
    # held-out subject's model), then evaluated (two verbs of one task)
    input:
        ingest=f"{RESULTS}/{{study}}/ingest",
        register=f"{RESULTS}/{{study}}/register/rollator",
        config=f"{RESULTS}/{{study}}/config_views/rollator/{{method}}.json",
        sheet=lambda w: sheet_path(w.study),
        models=rollator_models,
    output:
        directory(f"{RESULTS}/{{study}}/rollator/{{method}}"),
    wildcard_constraints:
        **ROLLATOR_WC,
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["rollator"]),
        models=rollator_trial_models,
        sizes=lambda w, input: trial_sizes(w.study, trial_ids(w.study, ["rollator"])),
    log:
        "logs/rollator_track/{study}/{method}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval rollator-trials --trials {params.trials:q} --models {params.models:q}"
        " --sizes {params.sizes:q} --ingest {input.ingest:q}"
        " --register {input.register:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --method {wildcards.method:q} --out {output:q} --threads {threads:q}"
        " --log {log:q}"


rule rollator_tables:
    input:
        evals=lambda w: [f"{RESULTS}/{study}/rollator/{method}"
                         for study in config["run"] if trial_ids(study, ["rollator"])
                         for method in rollator_methods() + external_methods("rollator")],
        models=lambda w: [f"{RESULTS}/{study}/rollator/model"
                          for study in config["run"] if trial_ids(study, ["rollator"])],
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/rollator/{STUDY_VIEW}.json",
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
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
        dirs=lambda w: [f"{RESULTS}/{study}/rollator/{method}/{trial}"
                        for study in config["run"]
                        for method in rollator_methods() + external_methods("rollator")
                        for trial in trial_ids(study, ["rollator"])],
        models=lambda w: [f"{RESULTS}/{study}/rollator/model/{subject}.json"
                          for study in config["run"]
                          for subject in rollator_subjects(study)],
        kf=lambda w: rollator_cfg()["kf_method"],
        pf=lambda w: rollator_cfg()["pf_method"],
        tables=parent_of("t1"),
        figures=parent_of("fig"),
        reports=parent_of("t1", up=1),
        chash=config_hash_when_run,
    priority: -10  # after every track job, beside the other tables (PRIORITIES in common.smk)
    log:
        "logs/rollator_tables.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval rollator-tables {params.dirs:q} --kf {params.kf:q} --pf {params.pf:q}"
        " --models {params.models:q} --config {input.config:q}"
        " --tables-dir {params.tables:q} --figures-dir {params.figures:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/rollator_table1.csv"] if trial_ids(study, ["rollator"]) else []
    )
)
