# Input functions and constants of workflow/rules/rollator.smk (seed 002, robotic rollator).
# Kept apart from the rules (snakemake --lint: functions belong in a common file).

ROLLATOR_WC = {"study": "[^/]+", "method": "[^/]+", "trial": "[^/]+", "subject": "[^/]+"}


def rollator_cfg():
    from gaitval.steps_rollator import rollator_cfg as _rc

    return _rc(config)


def rollator_methods():
    rc = rollator_cfg()
    return [rc["kf_method"], rc["pf_method"]]


def rollator_subjects(study):
    df = trials(study)
    return sorted(set(df.loc[df["protocol"] == "rollator", "subject"]))


def rollator_training_inputs(w):
    """Every rollator trial of the other subjects: scans, truth, registration record."""
    df = trials(w.study)
    others = sorted(df.index[(df["protocol"] == "rollator") & (df["subject"] != w.subject)])
    return [
        f"{RESULTS}/{w.study}/{kind}/{t}/{name}"
        for t in others
        for kind, name in (
            ("ingest", "sensor.parquet"),
            ("register", "groundtruth.parquet"),
            ("register", "registration.json"),
        )
    ]


def rollator_model(w):
    """The held-out subject's PF model, for the PF method only."""
    if w.method != rollator_cfg()["pf_method"]:
        return []
    subject = trial_row(w.study, w.trial)["subject"]
    return [f"{RESULTS}/{w.study}/rollator/model/{subject}.json"]
