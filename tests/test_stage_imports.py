"""What a stage job's process loads before its pool forks (gaitval.jobs.stages.preload).

Every workflow job is a fresh Python process, so what it imports is paid once per job
(docs/speed.md).  A TUG or MTST tracking job must not pay for modules its trials never use:
matplotlib (it draws nothing), scipy.stats (the people tracker's gate needs one normal
quantile), the particle filter's or the UKF's compiled kernels."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

PROBE = """
import json, sys
from gaitval.jobs.stages import preload
preload({stage!r})
{after}
print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in
      ('matplotlib', 'scipy', 'sklearn', 'numba', 'pyarrow', 'gaitval'))))
"""


def _loaded(stage: str, after: str = "") -> set[str]:
    out = subprocess.run([sys.executable, "-c", PROBE.format(stage=stage, after=after)],
                         capture_output=True, text=True, check=True)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


@pytest.mark.slow
@pytest.mark.parametrize("stage", ["track-trials", "mtst-trials"])
def test_a_leg_tracking_job_loads_its_kernel_only(stage):
    mods = _loaded(stage)
    assert "gaitval.track.init_motion_kernel" in mods
    assert "gaitval.track.pf_kernels" not in mods and "gaitval.track.ukf_kernel" not in mods
    assert "matplotlib" not in mods and "scipy.stats" not in mods


@pytest.mark.slow
def test_the_people_trackers_gate_needs_no_scipy_stats():
    # refind's leg_tracker gate: the normal quantile from the standard library
    mods = _loaded("track-trials", after=(
        "from gaitval.track.refind import leg_tracker_person_gate\n"
        "import numpy as np\n"
        "g = leg_tracker_person_gate(0.1)\n"
        "assert 0.8 < g[0] < 1.0 and np.all(np.diff(g) > 0), g"))  # z·sqrt(P+0.25), z 1.645
    assert "scipy.stats" not in mods


@pytest.mark.slow
def test_a_rollator_job_loads_the_pf_and_the_detectors_kmeans_before_forking():
    mods = _loaded("rollator-trials")
    assert {"gaitval.track.pf_kernels", "sklearn.cluster"} <= mods
    assert "matplotlib" not in mods
