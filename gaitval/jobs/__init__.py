"""How the workflow runs the pipeline's verbs: one Snakemake job per (study, stage[,
method]) runs a stage verb (:mod:`gaitval.jobs.stages`), which runs each trial's verbs in a
process pool of the rule's ``threads`` (:mod:`gaitval.jobs.batch`); what a killed run left
is redone (:mod:`gaitval.jobs.resume`) and no job outlives its Snakemake
(:mod:`gaitval.jobs.lifeline`).  Nothing here is needed to run a step by hand
(``gaitval VERB ...``)."""
