# The embedded default study: generated once, unless its files are already there -- or
# the twin that made them has changed: `twin` is a digest of the simulator's source
# (gaitval/simulate/), so a new twin regenerates the study on the next run instead of
# leaving a report of the old twin's data under the new code (Snakemake reruns a job whose
# params changed; a study folder copied without .snakemake/ metadata is taken as it is).

checkpoint simulate:
    input:
        preset=lambda w: PRESETS / f"{study_cfg(w.study)['simulate']['preset']}.yaml",
    output:
        sheet=f"{DATA}/{{study}}/trials.csv",
        subjects=f"{DATA}/{{study}}/subjects.csv",
        realism=f"{DATA}/{{study}}/realism.csv",
    params:
        seed=lambda w: study_cfg(w.study)["simulate"].get("seed", 0),
        twin=TWIN,
        out=parent_of("sheet"),
    log:
        "logs/simulate/{study}.log",
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval simulate --preset {input.preset:q} --seed {params.seed:q} --out {params.out:q}"
        " > {log:q} 2>&1 || (cat {log:q} >&2; exit 1)"
