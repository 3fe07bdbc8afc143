# Leg detections shared by the TUG and MTST methods that detect alike (issue 38;
# gaitval.pipeline.detections, docs/speed.md).  A detector spec that two or more of a
# study's methods of one protocol family run once over a trial's scans (seed 000's methods,
# their reading variants and the people tracker; three of seed 001's methods and the people
# tracker) is run by one `detect` job per (study, family, detector), which writes each
# trial's observation table to results/<study>/detect/<family>/<name>-<digest>/<trial>.parquet;
# those methods' track jobs read it (`--detections`) instead of detecting again.  A method
# with a detector of its own detects in its track job.  The folder is named by the spec's
# digest, so a changed detector parameter asks for a new folder (a new job) and any other
# parameter change reruns no detection.
include: "detect_common.smk"


rule detect:
    # one job per (study, family, shared detector): each trial's observation table
    # (HOW JOBS RUN in common.smk)
    input:
        unpack(detect_inputs),
    output:
        directory(f"{RESULTS}/{{study}}/detect/{{family}}/{{detector}}"),
    wildcard_constraints:
        family="tug|mtst",
        detector=r"[A-Za-z0-9_.\-]+",
    threads: BATCH_THREADS
    priority: 20  # every shared method's track job reads it
    params:
        spec=detector_spec_json,
        subjects=lambda w: subjects_path(w.study),
        trials=lambda w: trial_ids(w.study, [w.family]),
        sensors=lambda w: [detect_sensor(w.study, w.family, t)
                           for t in trial_ids(w.study, [w.family])],
        sizes=lambda w, input: [size_of(detect_sensor(w.study, w.family, t))
                                for t in trial_ids(w.study, [w.family])],
    log:
        "logs/detect/{study}/{family}/{detector}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval detect-trials --family {wildcards.family:q} --trials {params.trials:q}"
        " --sensors {params.sensors:q} --sizes {params.sizes:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --detector {params.spec:q}"
        " --config {input.view:q} --out {output:q} --threads {threads:q} --log {log:q}"
