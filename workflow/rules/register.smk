# Per-study analysis config, then registration + ground truth of every trial with mocap
# (one job per study and protocol family), then the registration table reviewers read first.
include: "register_common.smk"


rule study_config:
    input:
        sheet=lambda w: sheet_path(w.study),
    output:
        f"{RESULTS}/{{study}}/config.json",
    params:
        # canonical JSON (sorted keys): the same config given in another key order (e.g.
        # a section passed with --config) is no change
        sections=lambda w: analysis_sections_json(),
    log:
        "logs/study_config/{study}.log",
    run:
        from gaitval.pipeline.steps.config import study_config

        study_config(json.loads(params.sections), input.sheet, output[0])


# The config as the per-trial jobs of one method read it
# (gaitval.pipeline.steps.config.method_view): every per-trial job takes its view
# (config_view_file, common.smk) instead of config.json, so a change of one method's
# parameter reruns that method's tracking and evaluation and the tables of its study section
# (the pooled tables read the views too: study_views), not every trial's registration, every
# other method and the other tables.  view = a method name, or "study" for the jobs without
# a method; scope = the protocol family whose section it keeps (tug, mtst, rollator,
# ultrasonic; the others' left out), or "all".
rule config_view:
    input:
        sheet=lambda w: sheet_path(w.study),
    output:
        f"{RESULTS}/{{study}}/config_views/{{scope}}/{{view}}.json",
    wildcard_constraints:
        scope="|".join((*SCOPES, ALL_SCOPE)),
        view=r"[A-Za-z0-9_.\-]+",
    params:
        sections=lambda w: analysis_sections_json(w.view, w.scope),
    log:
        "logs/config_view/{study}/{scope}/{view}.log",
    priority: 200  # milliseconds each, and every job waits for its view (PRIORITIES in common.smk)
    run:
        from gaitval.pipeline.steps.config import study_config

        study_config(
            json.loads(params.sections), input.sheet, output[0], view=wildcards.view,
            scope=wildcards.scope,
        )


# REGISTRATION PER PROTOCOL FAMILY.  One job per (study, family): the trials with mocap of
# one protocol family (gaitval.pipeline.steps.config.PROTOCOL_SCOPE: tug, mtst, rollator,
# ultrasonic, or "all" for another protocol), each reading its family's study view
# (config_views/<family>/study.json), into results/<study>/register/<family>/<trial>/.  A
# change of one family's section (e.g. rollator.sensor_mount) thus reruns that family's
# registration and what reads it, not the other families' tracks (issue 38; with one job
# per study every family's view was its input).
rule register:
    # one job per (study, family): every trial with mocap of the family (HOW JOBS RUN in
    # common.smk), each reading the family's study view
    input:
        ingest=f"{RESULTS}/{{study}}/ingest",
        config=f"{RESULTS}/{{study}}/config_views/{{family}}/{STUDY_VIEW}.json",
        sheet=lambda w: sheet_path(w.study),
    output:
        directory(f"{RESULTS}/{{study}}/register/{{family}}"),
    wildcard_constraints:
        family="|".join((*SCOPES, ALL_SCOPE)),
    threads: BATCH_THREADS
    priority: 20  # everything after ingest reads it
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: family_mocap_trials(w.study, w.family),
        sizes=lambda w, input: trial_sizes(w.study, family_mocap_trials(w.study, w.family)),
    log:
        "logs/register/{study}/{family}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval register-trials --trials {params.trials:q} --sizes {params.sizes:q}"
        " --ingest {input.ingest:q} --sheet {input.sheet:q} --subjects {params.subjects:q}"
        " --config {input.config:q} --out {output:q} --threads {threads:q} --log {log:q}"


rule registration_summary:
    input:
        lambda w: register_dirs(w.study),
        sheet=lambda w: sheet_path(w.study),  # the params list its trials
    output:
        csv=f"{RESULTS}/{{study}}/registration.csv",
        table=report(
            f"{REPORTS}/tables/study_registration_{{study}}.csv",
            caption="../report/registration.rst",
            category="Study",
        ),
        md=f"{REPORTS}/tables/study_registration_{{study}}.md",
        tex=f"{REPORTS}/tables/study_registration_{{study}}.tex",
    params:
        registrations=lambda w: [f"{registration_dir(w.study, t)}/registration.json"
                                 for t in mocap_trial_ids(w.study)],
        stem=lambda w, output: output.table[: -len(".csv")],
        reports=parent_of("table", up=1),
        chash=config_hash_when_run,
    # with the tables (PRIORITIES in common.smk): at 0 it was picked, for its large input,
    # as soon as the last MTST track ended; on one core, with a table filling the other,
    # while the TUG tracks, which need both cores, waited (4.6 s, the run's Snakemake log)
    priority: -10
    log:
        "logs/registration_summary/{study}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval registration-summary {params.registrations:q} --study {wildcards.study:q}"
        " --out-csv {output.csv:q} --out-stem {params.stem:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q} > {log:q} 2>&1"


# Registration needs mocap: likewise absent for a study without any.
REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/study_registration_{study}.csv"] if mocap_trial_ids(study) else []
    )
)
