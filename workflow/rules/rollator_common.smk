# Input functions and constants of workflow/rules/rollator.smk (seed 002, robotic rollator).
# Kept apart from the rules (snakemake --lint: functions belong in a common file).

ROLLATOR_WC = {"study": "[^/]+", "method": "(?!model$)[^/]+", "trial": "[^/]+", "subject": "[^/]+"}


def rollator_cfg():
    from gaitval.pipeline.rollator import rollator_cfg as _rc

    return _rc(config)


def rollator_methods():
    """The KF and the PF, then gaitval's own extra methods (rollator.methods, issue 36)."""
    rc = rollator_cfg()
    return [rc["kf_method"], rc["pf_method"]] + [
        m for m in rc["methods"] if m not in (rc["kf_method"], rc["pf_method"])]


def rollator_subjects(study):
    df = trials(study)
    return sorted(set(df.loc[df["protocol"] == "rollator", "subject"]))


def rollator_models(w):
    """The study's PF models (its model folder), for the PF method only."""
    if w.method != rollator_cfg()["pf_method"]:
        return []
    return [f"{RESULTS}/{w.study}/rollator/model"]


def rollator_model(w):
    """The held-out subject's PF model, for the PF method only."""
    if w.method != rollator_cfg()["pf_method"]:
        return []
    subject = trial_row(w.study, w.trial)["subject"]
    return [f"{RESULTS}/{w.study}/rollator/model/{subject}.json"]


def rollator_tasks(wildcards, input, output, params):
    """A (study, method) job's tasks: per trial, its track (the PF with its held-out
    subject's model) and then its evaluation."""
    tasks = []
    for t in params.trials:
        model = rollator_model(trial_wildcards(wildcards.study, t, wildcards.method))
        common = ["--sheet", input.sheet, "--subjects", params.subjects, "--trial", t,
                  "--method", wildcards.method, "--config", input.config]
        track = f"{output[0]}/{t}.track.parquet"
        tasks.append((t, [
            verb("rollator-track", "--sensor", f"{input.ingest}/{t}/sensor.parquet", common,
                 ["--model", model[0]] if model else [], "--out", track),
            verb("rollator-evaluate", "--track", track,
                 "--groundtruth", f"{input.register}/{t}/groundtruth.parquet",
                 "--registration", f"{input.register}/{t}/registration.json",
                 "--ingest", f"{input.ingest}/{t}", common, "--out", f"{output[0]}/{t}"),
        ]))
    return tasks
