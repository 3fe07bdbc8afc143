"""Seed 001 walking parameters on constructed footfalls: foot contacts (§2.5.1), target-step
judgement (§2.5.2, the foot-model region) and cross steps (eq. (11)), crossing / not
crossing and on / off target."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from mtst_synth import walk

from gaitval.gait.mtst import (FootModel, cross_steps, foot_contacts, judge_target_steps,
                               judgement_region)

W_L = 0.10                      # leg width: w_c = w_l / 2 = 0.05 m


NORMAL = [("L", 0.4, 0.1), ("R", 0.8, -0.1), ("L", 1.2, 0.1), ("R", 1.6, -0.1),
          ("L", 2.0, 0.1)]


def test_one_contact_per_foothold_at_the_stance_speed_minimum():
    tr = walk(NORMAL)
    c = foot_contacts(tr)
    assert list(c["side"]) == [f[0] for f in NORMAL]             # standing start: none
    assert np.allclose(c[["x_m", "y_m"]].to_numpy(), [f[1:] for f in NORMAL], atol=0.02)
    for r in c.itertuples():
        d = tr[(tr.side == r.side) & tr.k.between(r.k_stance_start, r.k_stance_end)]
        assert r.speed_mps == pytest.approx(np.hypot(d.vx_mps, d.vy_mps).min())


def test_normal_walking_has_no_cross_step():
    tr = walk(NORMAL)
    c = foot_contacts(tr)
    assert not cross_steps(c, tr, (1.0, 0.0), W_L / 2).any()


def test_a_crossed_foot_is_detected_on_the_swing_round_it():
    # the right foot lands 0.05 m left of the left foot (across its line); the left leg
    # then swings round it to its own side: eq. (11) fires at that left contact
    steps = [("L", 0.4, 0.1), ("R", 0.8, -0.1), ("L", 1.2, 0.1), ("R", 1.6, 0.15),
             ("L", 2.0, 0.25), ("R", 2.4, -0.1), ("L", 2.8, 0.1)]
    tr = walk(steps)
    c = foot_contacts(tr)
    flags = cross_steps(c, tr, (1.0, 0.0), W_L / 2)
    assert list(flags) == [False, False, False, False, True, False, False]
    # the other reading of y' (towards the swinging leg's own side) flags the crossing
    # swing itself, and also the left foot's later move back towards the midline
    other = cross_steps(c, tr, (1.0, 0.0), W_L / 2, y_towards="swing_side")
    assert list(other) == [False, False, False, True, False, False, True]


def test_a_narrow_step_inside_w_c_is_not_a_cross_step():
    steps = [("L", 0.4, 0.1), ("R", 0.8, 0.06), ("L", 1.2, 0.12), ("R", 1.6, -0.1)]
    tr = walk(steps)
    c = foot_contacts(tr)
    assert not cross_steps(c, tr, (1.0, 0.0), W_L / 2).any()


def test_walking_direction_is_respected():
    """The crossing walk turned by 180° (walking towards −x) is found at the same step."""
    steps = [("L", 0.4, 0.1), ("R", 0.8, -0.1), ("L", 1.2, 0.1), ("R", 1.6, 0.15),
             ("L", 2.0, 0.25), ("R", 2.4, -0.1), ("L", 2.8, 0.1)]
    tr = walk(steps)
    for col in ("x_m", "y_m", "vx_mps", "vy_mps"):
        tr[col] = -tr[col]
    c = foot_contacts(tr)
    assert list(cross_steps(c, tr, (-1.0, 0.0), W_L / 2)) == [False] * 4 + [True] + [False] * 2


# -- target-step judgement ------------------------------------------------------------------
TARGETS = pd.DataFrame({"target": ["T0", "T1", "T2"], "x_m": [1.0, 1.0, 2.0],
                        "y_m": [0.0, 0.35, 0.0], "color": ["red", "blue", "red"],
                        "assigned": [True, False, True]})
SIZE = (0.165, 0.160)


def test_region_is_the_set_where_the_foot_overlaps_the_target():
    foot = FootModel.for_height(1.60)                 # L_f 0.243, W_f 0.088 m
    assert foot.toe == pytest.approx(0.75 * 0.152 * 1.6)
    assert foot.heel == pytest.approx(0.25 * 0.152 * 1.6)
    a_min, a_max, l_half = judgement_region(foot, SIZE)
    assert a_min == pytest.approx(-(0.0825 + 0.1824))   # toe just reaches the near edge
    assert a_max == pytest.approx(0.0825 + 0.0608)      # heel just on the far edge
    assert l_half == pytest.approx((0.160 + 0.088) / 2)


@pytest.mark.parametrize("xy, want", [
    ((1.0, 0.0), "T0"),                 # on the target
    ((0.80, 0.02), "T0"),               # ankle 0.2 m short: the toes are on it
    ((0.70, 0.0), ""),                  # 0.3 m short: off
    ((1.12, 0.0), "T0"),                # heel on its far edge
    ((1.18, 0.0), ""),                  # beyond the heel's reach
    ((1.0, 0.11), "T0"),                # foot's side overlaps
    ((1.0, 0.14), ""),                  # beside it
    ((1.0, 0.35), ""),                  # on a target of another colour
    ((2.0, -0.05), "T2"),
])
def test_contacts_on_and_off_target(xy, want):
    region = judgement_region(FootModel.for_height(1.60), SIZE)
    got = judge_target_steps(np.array([xy]), TARGETS, region, (1.0, 0.0))
    assert got[0] == want


def test_judgement_follows_the_walking_direction():
    """Walking towards −x, the toes reach the other way."""
    region = judgement_region(FootModel.for_height(1.60), SIZE)
    t = TARGETS.assign(x_m=-TARGETS["x_m"])
    assert judge_target_steps(np.array([[-0.80, 0.0]]), t, region, (-1.0, 0.0))[0] == "T0"
    assert judge_target_steps(np.array([[-1.18, 0.0]]), t, region, (-1.0, 0.0))[0] == ""
