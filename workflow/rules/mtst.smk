# Multi-target stepping task (seed 001): one tracking and one evaluation job per (trial,
# method), then Tables 1, 3, 4 and the trial figure.  A trial without mocap (annotations
# only) is tracked from its raw scan log; its pose comes from mtst.poles_m and its clock
# from the trial sheet (gaitval.steps_mtst).
import yaml


def mtst_methods():
    """The MTST tracker methods to run (config mtst.methods)."""
    return list(
        config.get("mtst", {}).get(
            "methods", ["mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed"]
        )
    )


def mtst_has_mocap(study, trial):
    return bool(trial_row(study, trial)["mocap_path"])


def mtst_sensor(wildcards):
    """The ingested scan log, or the raw one for a trial without mocap."""
    if mtst_has_mocap(wildcards.study, wildcards.trial):
        return f"{RESULTS}/{wildcards.study}/ingest/{wildcards.trial}/sensor.parquet"
    return trial_row(wildcards.study, wildcards.trial)["sensor_path"]


def mtst_registration(wildcards):
    """registration.json and groundtruth.parquet when the trial has mocap."""
    if not mtst_has_mocap(wildcards.study, wildcards.trial):
        return {}
    reg = f"{RESULTS}/{wildcards.study}/register/{wildcards.trial}"
    return {
        "reg": f"{reg}/registration.json",
        "gt": f"{reg}/groundtruth.parquet",
    }


def mtst_targets_file(wildcards):
    """The trial's target layout (mtst.targets of study.yaml or the config), when it exists."""
    sheet = Path(sheet_path(wildcards.study))
    pattern = (config.get("mtst") or {}).get("targets")
    cal = sheet.parent / "study.yaml"
    if cal.is_file():
        pattern = ((yaml.safe_load(cal.read_text()) or {}).get("mtst") or {}).get(
            "targets", pattern
        )
    if not pattern:
        return []
    path = sheet.parent / str(pattern).replace("{trial}", wildcards.trial)
    return [str(path)] if path.is_file() else []


def mtst_track_inputs(wildcards):
    files = {
        "sensor": mtst_sensor(wildcards),
        "config": f"{RESULTS}/{wildcards.study}/config.json",
        "sheet": sheet_path(wildcards.study),
    }
    reg = mtst_registration(wildcards)
    if reg:
        files["reg"] = reg["reg"]
    return files


def mtst_eval_inputs(wildcards):
    files = {
        "track": f"{RESULTS}/{wildcards.study}/mtst_track/{wildcards.method}/{wildcards.trial}.parquet",
        "config": f"{RESULTS}/{wildcards.study}/config.json",
        "sheet": sheet_path(wildcards.study),
        "targets": mtst_targets_file(wildcards),
        **mtst_registration(wildcards),
    }
    ann = trial_row(wildcards.study, wildcards.trial)["annotation_path"]
    if ann:
        files["annotations"] = ann
    return files


def mtst_optional(name, flag):
    """Param function: ``--flag path`` when input `name` is there, else nothing."""
    return lambda wildcards, input: f"{flag} {input[name]}" if name in input.keys() else ""


rule mtst_track:
    input:
        unpack(mtst_track_inputs),
    output:
        f"{RESULTS}/{{study}}/mtst_track/{{method}}/{{trial}}.parquet",
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        reg=mtst_optional("reg", "--registration"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/mtst_track/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} mtst-track --sensor {input.sensor} --sheet {input.sheet}"
        " --subjects {params.subjects} --trial {wildcards.trial} --method {wildcards.method}"
        " --config {input.config} {params.reg} --out {output}"
        " > {log} 2>&1 || (cat {log} >&2; exit 1)"


rule mtst_evaluate:
    input:
        unpack(mtst_eval_inputs),
    output:
        summary=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/summary.parquet",
        contacts=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/contacts.parquet",
        steps=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/steps.parquet",
        events=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/events.parquet",
        gates=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/gates.parquet",
        track_field=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/track_field.parquet",
        targets=f"{RESULTS}/{{study}}/mtst_eval/{{method}}/{{trial}}/targets.parquet",
    params:
        gv=GV,
        subjects=lambda w: subjects_path(w.study),
        out=parent_of("summary"),
        reg=mtst_optional("reg", "--registration"),
        gt=mtst_optional("gt", "--groundtruth"),
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/mtst_evaluate/{study}/{method}/{trial}.log",
    shell:
        "{params.gv} mtst-evaluate --track {input.track} --sheet {input.sheet}"
        " --subjects {params.subjects} --trial {wildcards.trial} --method {wildcards.method}"
        " --config {input.config} {params.reg} {params.gt} --out {params.out}"
        " > {log} 2>&1 || (cat {log} >&2; exit 1)"


def mtst_summaries(wildcards):
    return [
        f"{RESULTS}/{study}/mtst_eval/{method}/{trial}/summary.parquet"
        for study in config["run"]
        for method in mtst_methods()
        for trial in trial_ids(study, ["mtst"])
    ]


rule mtst_tables:
    input:
        mtst_summaries,
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
        gv=GV,
        dirs=lambda w, input: " ".join(str(Path(p).parent) for p in input),
        methods=" ".join(mtst_methods()),
        config=lambda w: f"{RESULTS}/{config['run'][0]}/config.json",
        tables=parent_of("t3"),
        figures=parent_of("fig"),
        reports=parent_of("t3", up=1),
        chash=CONFIG_HASH,
    conda:
        "../envs/gaitval.yaml"
    log:
        "logs/mtst_tables.log",
    shell:
        "{params.gv} mtst-tables {params.dirs} --methods {params.methods}"
        " --config {params.config} --tables-dir {params.tables}"
        " --figures-dir {params.figures} --reports-dir {params.reports}"
        " --config-hash {params.chash} > {log} 2>&1 || (cat {log} >&2; exit 1)"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/mtst_table3.csv", f"{REPORTS}/figures/mtst_trial.png"]
        if trial_ids(study, ["mtst"])
        else []
    )
)
