# Per-study analysis config, then registration + ground truth of every trial with mocap
# (one job per study), then the registration table reviewers read first.


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
        from gaitval.pipeline.steps import study_config

        study_config(json.loads(params.sections), input.sheet, output[0])


# The config as the per-trial jobs of one method read it (gaitval.pipeline.steps.method_view): every
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
        from gaitval.pipeline.steps import study_config

        study_config(
            json.loads(params.sections), input.sheet, output[0], view=wildcards.view,
            scope=wildcards.scope,
        )


rule register:
    # one job per study: every trial with mocap (HOW JOBS RUN in common.smk); each trial
    # reads the study view of its protocol family's scope (config_view_file)
    input:
        ingest=f"{RESULTS}/{{study}}/ingest",
        configs=lambda w: sorted({config_view_file(trial_wildcards(w.study, t))
                                  for t in mocap_trial_ids(w.study)}),
        sheet=lambda w: sheet_path(w.study),
    output:
        directory(f"{RESULTS}/{{study}}/register"),
    threads: BATCH_THREADS
    priority: 20  # everything after ingest reads it
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: mocap_trial_ids(w.study),
    log:
        "logs/register/{study}.log",
    run:
        run_trials(
            [(t, [verb("register", "--ingest", f"{input.ingest}/{t}", "--sheet", input.sheet,
                       "--subjects", params.subjects, "--trial", t,
                       "--config", config_view_file(trial_wildcards(wildcards.study, t)),
                       "--out", f"{output[0]}/{t}")])
             for t in params.trials],
            threads, log[0], outdirs=output,
            sizes=[trial_bytes(wildcards.study, t) for t in params.trials],
        )


rule registration_summary:
    input:
        f"{RESULTS}/{{study}}/register",
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
        trials=lambda w: mocap_trial_ids(w.study),
        stem=lambda w, output: output.table[: -len(".csv")],
        reports=parent_of("table", up=1),
        chash=config_hash_when_run,
    log:
        "logs/registration_summary/{study}.log",
    run:
        run_verb_job(
            verb("registration-summary",
                 [f"{input[0]}/{t}/registration.json" for t in params.trials],
                 "--study", wildcards.study, "--out-csv", output.csv,
                 "--out-stem", params.stem, "--reports-dir", params.reports,
                 "--config-hash", params.chash),
            log[0],
        )


# Registration needs mocap: likewise absent for a study without any.
REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/study_registration_{study}.csv"] if mocap_trial_ids(study) else []
    )
)
