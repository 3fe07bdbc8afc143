"""How the workflow runs the pipeline's verbs (issue 38): one Snakemake job per (study,
stage[, method]) hands its trials to :func:`gaitval.jobs.batch.run_batch`, which runs each
trial's verbs in a process pool of the rule's ``threads``.  Nothing here is needed to run
a step by hand (``gaitval VERB ...``)."""
