# External methods on the rollator (tracking.external.<m>.protocols: [rollator], issue 37):
# another tracker's tracks of each rollator trial, in the laser's frame (the laser moves with
# the rollator), converted to gaitval's per-scan track and evaluated like the KF and PF
# (seed 002 Tables I-II get its columns and rows).  The TUG and MTST external rules are
# track_external (tug.smk) and mtst_track_external (mtst.smk).
ruleorder: rollator_track_external > rollator_track


rule rollator_track_external:
    input:
        tracks=external_tracks_file,
        sensor=f"{RESULTS}/{{study}}/ingest/{{trial}}/sensor.parquet",
        gt=f"{RESULTS}/{{study}}/register/{{trial}}/groundtruth.parquet",
        reg=f"{RESULTS}/{{study}}/register/{{trial}}/registration.json",
        mocap=f"{RESULTS}/{{study}}/ingest/{{trial}}/mocap.parquet",
        config=config_view_file,
        sheet=lambda w: sheet_path(w.study),
    output:
        track=f"{RESULTS}/{{study}}/rollator/{{method}}/{{trial}}.track.parquet",
        summary=f"{RESULTS}/{{study}}/rollator/{{method}}/{{trial}}/summary.parquet",
        frames=f"{RESULTS}/{{study}}/rollator/{{method}}/{{trial}}/frames.parquet",
    wildcard_constraints:
        study="[^/]+",
        trial="[^/]+",
        method="|".join(re.escape(m) for m in external_methods("rollator")) or "(?!x)x",
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        ingest=lambda w, input: str(Path(input.mocap).parent),
        out=parent_of("summary"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/rollator_track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} import-tracks --tracks {input.tracks:q} --sensor {input.sensor:q}"
        " --registration {input.reg:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --moving-sensor --out {output.track:q} > {log:q} 2>&1"
        " && {params.gv} rollator-evaluate --track {output.track:q} --groundtruth {input.gt:q}"
        " --registration {input.reg:q} --ingest {params.ingest:q} --sheet {input.sheet:q}"
        " --subjects {params.subjects:q} --trial {wildcards.trial:q} --method {wildcards.method:q}"
        " --config {input.config:q} --out {params.out:q} >> {log:q} 2>&1"
        " || (cat {log:q} >&2; exit 1)"
