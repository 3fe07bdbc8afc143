# Functions of the register rules (workflow/rules/register.smk): a trial's protocol
# family and the per-family registration folders.


def trial_family(study, trial):
    """The protocol family (config view scope) of a trial: its register folder's name."""
    return PROTOCOL_SCOPE.get(trial_row(study, trial)["protocol"], ALL_SCOPE)


def family_mocap_trials(study, family):
    """The trials with mocap of one protocol family: what its register job takes."""
    return [t for t in mocap_trial_ids(study) if trial_family(study, t) == family]


def register_dir(study, family):
    """results/<study>/register/<family>: the output of one register job."""
    return f"{RESULTS}/{study}/register/{family}"


def registration_dir(study, trial):
    """results/<study>/register/<family>/<trial>: one trial's registration.json and
    groundtruth.parquet."""
    return f"{register_dir(study, trial_family(study, trial))}/{trial}"


def register_dirs(study):
    """The register folders of every family with a trial with mocap (registration_summary)."""
    return sorted({register_dir(study, trial_family(study, t)) for t in mocap_trial_ids(study)})
