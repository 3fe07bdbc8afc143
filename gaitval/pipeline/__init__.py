"""The pipeline's steps at file level: read the files of one rule's trial, call the
library, write files (issue 38: a package, formerly ``gaitval/steps*.py``).

:mod:`~gaitval.pipeline.steps` holds the shared steps, a module per concern (config views,
registration, TUG tracking and evaluation, ultrasonic, external trackers), and
:mod:`~gaitval.pipeline.mtst`, :mod:`~gaitval.pipeline.rollator`,
:mod:`~gaitval.pipeline.legbench` those of one protocol family; :mod:`gaitval.cli` exposes
each as a verb, and the workflow runs the verbs (:mod:`gaitval.jobs`).  Only this package
and :mod:`gaitval.io` know where files live.

What a step reads again -- the trial sheet's rows, a scan log read by a trial's tracking
and then its evaluation -- it keeps for the process's next step
(:mod:`~gaitval.pipeline.memo`): the library below (io, registration, tracking) keeps
nothing between calls.
"""
