"""The pipeline's steps at file level and how the workflow runs them (issue 38).

:mod:`gaitval.pipeline.batch` runs one rule's trials in a process pool of the rule's
``threads``; the workflow's rules (``workflow/rules/*.smk``) call it from their ``run:``
blocks with one task per trial.  The step functions themselves live in
:mod:`gaitval.steps` and its siblings (file in, file out, one trial each).
"""
