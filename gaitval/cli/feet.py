"""Verbs of the ultrasonic foot tracking study (seed 003) and of other systems' heel
trajectories on its treadmill trials."""
from __future__ import annotations

import json


def cmd_ultrasonic_noise(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import ultrasonic_noise_step
    n = ultrasonic_noise_step(a.ingest, a.trials, a.config, a.out, a.table_stem,
                              a.reports_dir, a.config_hash)
    print(json.dumps(n, sort_keys=True))
    return 0


def cmd_external_gait_parameters(a) -> int:
    from gaitval.pipeline.steps.ultrasonic import external_gait_parameters_step
    gp = external_gait_parameters_step(a.foot, a.ingest, a.sheet, a.subjects, a.trial,
                                       a.method, a.config, a.out)
    print(f"{a.trial}: {gp['stride'].nunique()} strides matched")
    return 0
