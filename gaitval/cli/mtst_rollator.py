"""Verbs of the multi-target stepping task (seed 001) and the robotic rollator (seed 002)."""
from __future__ import annotations


def cmd_mtst_evaluate(a) -> int:
    from gaitval.pipeline.mtst import mtst_evaluate_step
    s = mtst_evaluate_step(a.track, a.sheet, a.subjects, a.trial, a.method, a.config,
                           a.registration, a.groundtruth, a.out)
    print(s.to_string(index=False))
    return 0


def cmd_rollator_evaluate(a) -> int:
    from gaitval.pipeline.rollator import rollator_evaluate_step
    s = rollator_evaluate_step(a.track, a.groundtruth, a.registration, a.ingest, a.sheet,
                               a.subjects, a.trial, a.method, a.config, a.out)
    print(s.to_string(index=False))
    return 0
