# Helpers of workflow/rules/report.smk.


# THE PAPERS' EXAMPLE FIGURES (gaitval.pipeline.paper_figures): one job per protocol, from
# the per-trial results of the first study of `run` that has the protocol (its evaluations,
# tracks, scans and ground truth): seed 000 Figs. 12-13, seed 001 Figs. 6a, 8, 9, seed 002
# Fig. 5, seed 003 Figs. 2-4.  Every figure is declared; one the data cannot give is a PNG
# that says so.
PAPER_FIGURES = {
    "tug": ["tug_fig12", "tug_fig13"],
    "mtst": ["mtst_fig6a", "mtst_fig8", "mtst_fig9"],
    "rollator": ["rollator_fig5"],
    "ultrasonic": ["ultrasonic_fig2", "ultrasonic_fig3", "ultrasonic_fig4"],
}
_PAPER_FIGURE_TRIALS = {"tug": ["tug"], "mtst": ["mtst"], "rollator": ["rollator"],
                        "ultrasonic": ["treadmill"]}


def paper_figure_study(protocol):
    """The first study of `run` with a trial of the protocol (None: none has one)."""
    return next((s for s in config["run"] if trial_ids(s, _PAPER_FIGURE_TRIALS[protocol])),
                None)


def paper_figure_inputs(protocol):
    """What one protocol's figures read from its study's results."""
    s = paper_figure_study(protocol)
    if s is None:
        return []
    r = f"{RESULTS}/{s}"
    # the ingested scans, where the study has mocap trials (a study with rater annotations
    # only has no ingest job: its figures draw without the scans)
    ingest = [f"{r}/ingest"] if mocap_trial_ids(s) else []
    if protocol == "tug":
        ms = [m for m in ("tug_m1", "tug_m2", "tug_m3") if m in tug_runs()]
        return (ingest + [f"{r}/evaluate/{m}" for m in ms]
                + [f"{r}/config_views/tug/{m}.json" for m in ms])
    if protocol == "mtst":
        ms = [m for m in ("mtst_m1", "mtst_m2", "mtst_m3", "mtst_proposed")
              if m in mtst_methods()]
        return (ingest + [f"{r}/config_views/mtst/{STUDY_VIEW}.json"]
                + register_dirs(s) + [f"{r}/mtst_eval/{m}" for m in ms]
                + [f"{r}/mtst_track/{m}" for m in ms]
                + [f"{r}/config_views/mtst/{m}.json" for m in ms])
    if protocol == "rollator":
        rc = rollator_cfg()
        return ingest + [f"{r}/rollator/{m}" for m in (rc["kf_method"],
                                                                rc["pf_method"])]
    return [f"{r}/ultrasonic", f"{r}/config_views/ultrasonic/{STUDY_VIEW}.json"]

def paper_figures_args(protocol):
    """Param function: the arguments of `gaitval paper-figures` of one protocol (its
    rule's shell command).  It takes `input`, so it is no rerun trigger (the inputs are)."""

    def args(wildcards, input, output):
        study = paper_figure_study(protocol)
        config = [f for f in input if str(f).endswith(".json")]
        return [protocol, "--results", f"{RESULTS}/{study}",
                *(["--config", config[0]] if config else []),
                "--sheet", sheet_path(study), "--subjects", subjects_path(study),
                "--figures-dir", str(Path(output[0]).parent),
                "--reports-dir", str(Path(output[0]).parents[1]),
                "--config-hash", CONFIG_HASH]

    return args
