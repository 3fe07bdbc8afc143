# External methods on the rollator (tracking.external.<m>.protocols: [rollator], issue 37):
# another tracker's tracks of each rollator trial, in the laser's frame (the laser moves with
# the rollator), converted to gaitval's per-scan track and evaluated like the KF and PF
# (seed 002 Tables I-II get its columns and rows).  One job per (study, method), its
# trials in a process pool like rollator_track (HOW JOBS RUN in common.smk).  The TUG and
# MTST external rules are track_external (tug.smk) and mtst_track_external (mtst.smk).
ruleorder: rollator_track_external > rollator_track


rule rollator_track_external:
    input:
        tracks=lambda w: [external_tracks_file(trial_wildcards(w.study, t, w.method))
                          for t in trial_ids(w.study, ["rollator"])],
        ingest=f"{RESULTS}/{{study}}/ingest",
        register=f"{RESULTS}/{{study}}/register/rollator",
        config=f"{RESULTS}/{{study}}/config_views/rollator/{{method}}.json",
        sheet=lambda w: sheet_path(w.study),
    output:
        directory(f"{RESULTS}/{{study}}/rollator/{{method}}"),
    wildcard_constraints:
        study="[^/]+",
        method="|".join(re.escape(m) for m in external_methods("rollator")) or "(?!x)x",
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["rollator"]),
    log:
        "logs/rollator_track/{study}/{method}.log",
    run:
        run_trials(
            [(t, [verb("import-tracks", "--tracks", tracks,
                       "--sensor", f"{input.ingest}/{t}/sensor.parquet",
                       "--registration", f"{input.register}/{t}/registration.json",
                       "--trial", t, "--method", wildcards.method, "--config", input.config,
                       "--moving-sensor", "--out", f"{output[0]}/{t}.track.parquet"),
                  verb("rollator-evaluate", "--track", f"{output[0]}/{t}.track.parquet",
                       "--groundtruth", f"{input.register}/{t}/groundtruth.parquet",
                       "--registration", f"{input.register}/{t}/registration.json",
                       "--ingest", f"{input.ingest}/{t}", "--sheet", input.sheet,
                       "--subjects", params.subjects, "--trial", t,
                       "--method", wildcards.method, "--config", input.config,
                       "--out", f"{output[0]}/{t}")])
             for t, tracks in zip(params.trials, input.tracks)],
            threads, log[0], outdirs=output,
        )
