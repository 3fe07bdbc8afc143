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
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval rollator-import-trials --trials {params.trials:q} --files {input.tracks:q}"
        " --ingest {input.ingest:q} --register {input.register:q}"
        " --sheet {input.sheet:q} --subjects {params.subjects:q}"
        " --config {input.config:q} --method {wildcards.method:q}"
        " --out {output:q} --threads {threads:q} --log {log:q}"


# External leg detectors (external_detections: of a study's study.yaml or external.yaml,
# issue 37): per scan, legs without identity or side (leg_tracker/LegArray in a bag, or a
# *.detections.csv), scored per trial against the registered mocap legs (`gaitval
# leg-detections`, gaitval.evaluate.leg_detections); one job per (study, detector), its
# trials in a process pool; on rollator trials (protocols: [rollator]) the laser moves,
# so their files must be in its frame (--moving-sensor).  No track, so no row in the
# tracking tables: the detection table (detections_table) is theirs.  The entry is a param, so a changed entry (path,
# topic, protocols) reruns its own job and the table, not another detector's.
rule leg_detections:
    input:
        files=lambda w: [detection_file(w.study, w.detector, t)
                         for t, _ in detection_trials(w.study, w.detector)],
        ingest=f"{RESULTS}/{{study}}/ingest",
        register=lambda w: sorted({f"{RESULTS}/{w.study}/register/{p}"
                                   for _, p in detection_trials(w.study, w.detector)}),
        sheet=lambda w: sheet_path(w.study),  # the params list its trials
    output:
        directory(f"{RESULTS}/{{study}}/leg_detections/{{detector}}"),
    wildcard_constraints:
        study="[^/]+",
        detector="|".join(re.escape(m) for m in external_detectors()) or "(?!x)x",
    threads: BATCH_THREADS
    params:
        trials=lambda w: detection_trials(w.study, w.detector),
        entry=lambda w: json.dumps(_DETECTIONS[w.study][w.detector], sort_keys=True),
        topic=lambda w: _DETECTIONS[w.study][w.detector].get("topic") or "",
        trial_ids=lambda w: [t for t, _ in detection_trials(w.study, w.detector)],
        protocols=lambda w: [p for _, p in detection_trials(w.study, w.detector)],
        register=lambda w: f"{RESULTS}/{w.study}/register",
    log:
        "logs/leg_detections/{study}/{detector}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval leg-detections-trials --trials {params.trial_ids:q} --files {input.files:q}"
        " --protocols {params.protocols:q} --topic={params.topic:q}"
        " --ingest {input.ingest:q} --register {params.register:q}"
        " --method {wildcards.detector:q} --out {output:q} --threads {threads:q}"
        " --log {log:q}"


rule detections_table:
    input:
        dets=lambda w: [f"{RESULTS}/{s}/leg_detections/{d}" for s in config["run"]
                        for d in external_detectors()],
        # the trial sheets: the params list their trials (a checkpoint's output for a
        # simulated study, which a cluster job's Snakemake must see as an input)
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        csv=report(f"{REPORTS}/tables/detections_table.csv", category="External detectors"),
        md=f"{REPORTS}/tables/detections_table.md",
        tex=f"{REPORTS}/tables/detections_table.tex",
    params:
        dirs=lambda w: [f"{RESULTS}/{s}/leg_detections/{d}/{t}" for s in config["run"]
                        for d in external_detectors()
                        for t, _ in detection_trials(s, d)],
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    priority: -10  # after the jobs it pools, beside the other tables (PRIORITIES in common.smk)
    log:
        "logs/detections_table.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval leg-detections-table {params.dirs:q} --out-stem {params.stem:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/detections_table.csv"] if external_detectors() else []
)


# External foot-tracking systems on the treadmill trials (external_methods: with
# protocols: [treadmill], issue 37): each trial's heel trajectory (*.foot.csv, gaitval.io.
# foot) goes through seed 003's stride extraction against the camera reference, exactly
# as gaitval's UKF track does (`gaitval external-gait-parameters`); one job per (study,
# method), its trials in a process pool.  The agreement table (method_agreement) puts the
# systems' rows beside gaitval's UKF; seed 003's Tables 2-8 stay the UKF's alone.
rule ultrasonic_external:
    input:
        feet=lambda w: [external_tracks_file(trial_wildcards(w.study, t, w.method))
                        for t in trial_ids(w.study, ["treadmill"])],
        ingest=f"{RESULTS}/{{study}}/ingest",
        config=f"{RESULTS}/{{study}}/config_views/ultrasonic/{STUDY_VIEW}.json",
        sheet=lambda w: sheet_path(w.study),
    output:
        directory(f"{RESULTS}/{{study}}/ultrasonic_external/{{method}}"),
    wildcard_constraints:
        study="[^/]+",
        method="|".join(re.escape(m) for m in external_methods("treadmill")) or "(?!x)x",
    threads: BATCH_THREADS
    params:
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, ["treadmill"]),
    log:
        "logs/ultrasonic_external/{study}/{method}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval external-gait-trials --trials {params.trials:q} --files {input.feet:q}"
        " --ingest {input.ingest:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --config {input.config:q}"
        " --method {wildcards.method:q} --out {output:q} --threads {threads:q}"
        " --log {log:q}"


rule method_agreement:
    input:
        ukf=lambda w: sorted({f"{RESULTS}/{s}/ultrasonic" for s, _ in treadmill_trials()}),
        ext=lambda w: sorted({f"{RESULTS}/{s}/ultrasonic_external/{m}"
                              for s, _ in treadmill_trials()
                              for m in external_methods("treadmill")}),
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config_views/ultrasonic/{STUDY_VIEW}.json",
        sheets=lambda w: [sheet_path(s) for s in config["run"]],
    output:
        csv=report(f"{REPORTS}/tables/ultrasonic_agreement_methods.csv",
                   category="External systems"),
        md=f"{REPORTS}/tables/ultrasonic_agreement_methods.md",
        tex=f"{REPORTS}/tables/ultrasonic_agreement_methods.tex",
    params:
        gait=lambda w: [
            x
            for m, d in [(UKF_SYSTEM, "ultrasonic/gait"),
                         *((m, f"ultrasonic_external/{m}")
                           for m in external_methods("treadmill"))]
            for x in ["--gait", m, *(f"{RESULTS}/{s}/{d}/{t}.parquet"
                                     for s, t in treadmill_trials())]
        ],
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    priority: -10  # after the jobs it pools, beside the other tables (PRIORITIES in common.smk)
    log:
        "logs/method_agreement.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval method-agreement {params.gait:q} --out-stem {params.stem:q}"
        " --config {input.config:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/ultrasonic_agreement_methods.csv"]
    if external_methods("treadmill") and trial_ids(study, ["treadmill"])
    else []
)
