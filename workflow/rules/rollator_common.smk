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


def rollator_trial_models(w):
    """Param function: each rollator trial's PF model (its held-out subject's), "-" (none)
    for a method other than the PF."""
    return [(rollator_model(trial_wildcards(w.study, t, w.method)) or ["-"])[0]
            for t in trial_ids(w.study, ["rollator"])]
