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
    log:
        "logs/mtst_track/{study}/{method}.log",
    run:
        run_trials(mtst_tasks(wildcards, input, output, params), threads, log[0],
                   outdirs=output, sizes=mtst_sizes(wildcards, params.trials))


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
    log:
        "logs/mtst_track/{study}/{method}.log",
    run:
        run_trials(mtst_tasks(wildcards, input, output, params, external=True), threads,
                   log[0], outdirs=output)


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
        tables=parent_of("t3"),
        figures=parent_of("fig"),
        reports=parent_of("t3", up=1),
        chash=config_hash_when_run,
    priority: -10  # after every track job, beside the other tables (PRIORITIES in common.smk)
    log:
        "logs/mtst_tables.log",
    run:
        run_verb_job(
            verb("mtst-tables", params.dirs, "--methods", params.methods,
                 "--config", input.configs[0], "--tables-dir", params.tables,
                 "--figures-dir", params.figures, "--reports-dir", params.reports,
                 "--config-hash", params.chash),
            log[0],
        )


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/mtst_table3.csv", f"{REPORTS}/figures/mtst_trial.png"]
        if trial_ids(study, ["mtst"])
        else []
    )
)
