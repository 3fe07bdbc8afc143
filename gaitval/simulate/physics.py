"""Physical checks of a simulated study: does the twin move like people and look like the
papers' recordings?  Written to ``data/<study>/physics.csv`` by :func:`write_physics`
(:func:`gaitval.simulate.generate_study` calls it for every simulated study).

Every row is one check: the twin's value, a reference, where the reference comes from, the
tolerance and whether the twin passes.  **The tolerances below were written down before
any twin value of these checks was computed (issue 10); a failing row is a finding to
report (``docs/simulator.md``), never a knob to turn until a tracker wins.**

========================  ==============================================================
check                     twin value / reference / tolerance
========================  ==============================================================
swing_shin_backward       per protocol: swings whose shin point (at sensor height, 10 Hz
                          low-pass) moves backwards along the swing's own direction faster
                          than :data:`SWING_BACKWARD_MPS`; reference 0 (a swinging shank is
                          carried forward by the thigh; the real C3D walks measured the same
                          way never go backwards); pass: no such swing
shin_swing_peak           peak swing speed / walking speed of the study's walkers on steady
                          straight walks vs the three real C3D walks
                          (:mod:`gaitval.simulate.shin`); pass: within ±15 %
shin_stance_speed         mean stance speed / walking speed, same walks; pass: within ±30 %
step_length, cadence      straight-walking steps of the twin's footfalls vs the published
                          range of the population (:data:`STEP_RANGES`); pass: mean inside
tug_phase_duration        forward / turning / return seconds per trial vs seed 000 Table 4
                          (leg-scans / 25 trials / 2 legs / 40 Hz); pass: within ±25 %
tug_occlusion             per TUG phase, leg-scans with < 3 returning beams vs seed 000
                          Table 4 (Method 2: 3.5 / 11.3 / 5.1 %); pass: ratio in [2/3, 3/2]
tug_turn_to_sit           seconds from the last return-line contact to the last contact
                          before sitting vs 1.7 ± 0.5 s (final 180° turn of the TUG,
                          healthy adults); pass: inside mean ± 2 SD
tug_return_to_chair       lateral distance of the return path from the chair's axis where
                          the turn to sit starts (out-and-back, seed 000 §1); pass: ≤ 0.25 m
tug_marker_clearance      closest approach of a shank's surface to the marker cone's surface
                          during the turn (the legs go around it, not through it); pass: > 0
tug_turn_radius           radius of the feet-midpoint path around the marker; no published
                          value (shown; the clearance row is its check)
mtst_cross_steps          cross steps per 100 steps from the twin's truth footfalls vs seed 001
                          Table 4 (19 of 414 = 4.6); pass: inside the exact 95 % Poisson
                          interval of 19 counts (2.8–7.2 per 100)
treadmill_stride_sd       stride-to-stride SD of the reference stride length per trial vs
                          seed 003 Table 2 (Ref std, 0.019–0.056 m over subjects); pass: the
                          twin's mean inside that range
========================  ==============================================================

References
----------
Yorozu A, Moriguchi T, Takahashi M. Sensors 2015;15:22451–22472 (seed 000: Table 4).
Yorozu A et al. Sensors 2015;15:11151–11168 (seed 001: Table 4, 19 cross steps of 414).
Qi Y et al. Sensors 2014;14:15434–15457 (seed 003: Tables 2 and 8).
Podsiadlo D, Richardson S. The timed "Up & Go". J Am Geriatr Soc 1991;39:142–148.
Espy DD, Yang F, Bhatt T, Pai Y-C. Independent influence of gait speed and step length on
stability and fall risk. Gait Posture 2010;32:378–382, Table 2 (PMC2943048).
Aging Clin Exp Res 2020;33:1853–1864, doi:10.1007/s40520-020-01715-9, Table 3 (iTUG,
healthy controls: final 180° turn 1.7 ± 0.5 s).
Tudor-Locke C et al. (walk-to-run transition cadence ≈ 140 steps/min in adults; cited in
Sensors 2021;21:7910, PMC8629136).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from gaitval.io.atomic import write_csv

# --------------------------------------------------------------------------------------
# Tolerances and references: stated before any value of these checks was computed.
# --------------------------------------------------------------------------------------
#: A swing "moves backwards" when the shin point's speed along the swing's direction
#: drops below this (m/s): numerical noise of the low-passed truth is far smaller.
SWING_BACKWARD_MPS = -0.05
#: Shin speed profile against the real C3D walks (the tolerances of
#: tests/test_simulate.py::test_simulated_shin_speed_profile_matches_real_walks).
SHIN_PEAK_REL = 0.15
SHIN_STANCE_REL = 0.30
#: seed 000 Table 4, Method 2: leg-scans per TUG phase over 25 trials (40 Hz, 2 legs).
TUG_PHASE_LEG_SCANS = {"forward": 6364, "turning": 2264, "return": 6686}
TUG_PHASE_REL = 0.25
#: seed 000 Table 4, Method 2: occluded / all leg-scans per phase.
TUG_OCCLUSION = {"forward": (225, 6364), "turning": (255, 2264), "return": (344, 6686)}
OCCLUSION_FACTOR = 1.5
#: Final 180° turn (turn to sit) of the instrumented TUG, healthy controls: mean, SD (s).
TURN_TO_SIT_S = (1.7, 0.5)
RETURN_OFFSET_MAX_M = 0.25
MARKER_RADIUS_M = 0.06            # the TUG cone at shin height (gaitval.simulate.tug)
#: seed 001 Table 4: cross steps, steps.
MTST_CROSS = (19, 414)
#: seed 003 Table 2, reference system: per-subject stride-length SD range (m).
TREADMILL_STRIDE_SD_M = (0.019, 0.056)
#: Published step length (/ body height) and cadence (steps/min) ranges per walker group.
#: young: TUG at maximum speed — from seed 003's fast treadmill walking (stride
#: 1.410 ± 0.090 m at 1.714 m height, mean ± 2 SD; cadence 0.993 strides/s = 119 /min)
#: up to the walk-to-run transition cadence (≈ 140 /min).  elderly: the published older-
#: adult groups of Espy et al. 2010 Table 2 (step 0.297–0.403 body heights, speed / step
#: length 1.75–1.98 /s = 105–119 /min).  patient: no published range (seed 002 gives none).
STEP_RANGES = {
    "young": {"step_per_height": ((1.410 - 2 * 0.090) / 2 / 1.714,
                                  (1.410 + 2 * 0.090) / 2 / 1.714),
              "cadence_per_min": (0.993 * 120, 140.0),
              "source": "seed 003 Table 8 (fast, mean ± 2 SD); walk-run transition cadence"},
    "elderly": {"step_per_height": (0.297, 0.403), "cadence_per_min": (1.75 * 60, 1.98 * 60),
                "source": "Espy et al. 2010 Table 2 (older-adult groups)"},
}
GROUP_OF = {"tug": "young", "mtst": "elderly", "rollator": "patient"}
COLUMNS = ["check", "protocol", "group", "phase", "value", "reference", "lower", "upper",
           "unit", "tolerance", "source", "passed", "note"]


def _row(check, protocol, value, reference, lower, upper, unit, tolerance, source,
         group="", phase="", note="") -> dict:
    ok = (np.nan if not np.isfinite(value) or (lower is None and upper is None)
          else bool((lower is None or value >= lower) and (upper is None or value <= upper)))
    return {"check": check, "protocol": protocol, "group": group, "phase": phase,
            "value": float(value), "reference": float(reference),
            "lower": np.nan if lower is None else float(lower),
            "upper": np.nan if upper is None else float(upper), "unit": unit,
            "tolerance": tolerance, "source": source, "passed": ok, "note": note}


def poisson_ci(k: int, level: float = 0.95) -> tuple[float, float]:
    """Exact (Garwood) confidence interval of a Poisson count ``k``."""
    a = (1 - level) / 2
    lo = 0.0 if k == 0 else stats.chi2.ppf(a, 2 * k) / 2
    return float(lo), float(stats.chi2.ppf(1 - a, 2 * k + 2) / 2)
