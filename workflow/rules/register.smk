# Per-study analysis config, then registration + ground truth per trial, then the
# registration table reviewers read first.


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
        from gaitval.steps import study_config

        study_config(json.loads(params.sections), input.sheet, output[0])


# The config as the per-trial jobs of one method read it (gaitval.steps.method_view): every
# per-trial job takes its view (config_view_file, common.smk) instead of config.json, so a
# change of one method's parameter reruns that method's tracking and evaluation and the
# tables of its study section (the pooled tables read the views too: study_views), not
# every trial's registration, every other method and the other tables.  view = a method
# name, or "study" for the jobs without a method; scope = the protocol family whose section
# it keeps (tug, mtst, rollator, ultrasonic; the others' left out), or "all".
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
    run:
        from gaitval.steps import study_config

        study_config(
            json.loads(params.sections), input.sheet, output[0], view=wildcards.view,
            scope=wildcards.scope,
        )


rule register:
    input:
        mocap=f"{RESULTS}/{{study}}/ingest/{{trial}}/mocap.parquet",
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        config=config_view_file,
        sheet=lambda w: sheet_path(w.study),
    output:
        record=f"{RESULTS}/{{study}}/register/{{trial}}/registration.json",
        gt=f"{RESULTS}/{{study}}/register/{{trial}}/groundtruth.parquet",
    priority: 20  # critical path first (PRIORITIES in common.smk)
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        ingest=lambda w, input: str(Path(input.mocap).parent),
        out=parent_of("record"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/register/{study}/{trial}.log",
    shell:
        "{params.gv} register --ingest {params.ingest:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --config {input.config:q}"
        " --out {params.out:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


rule registration_summary:
    input:
        lambda w: expand(
            f"{RESULTS}/{{study}}/register/{{trial}}/registration.json",
            study=w.study,
            trial=mocap_trial_ids(w.study),
        ),
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
        gv=GV,
        stem=lambda w, output: output.table[: -len(".csv")],
        reports=parent_of("table", up=1),
        chash=config_hash_when_run,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/registration_summary/{study}.log",
    shell:
        "{params.gv} registration-summary {input:q} --study {wildcards.study:q}"
        " --out-csv {output.csv:q} --out-stem {params.stem:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"


# Registration needs mocap: likewise absent for a study without any.
REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/study_registration_{study}.csv"] if mocap_trial_ids(study) else []
    )
)
