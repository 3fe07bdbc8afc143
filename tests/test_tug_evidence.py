"""Per-step evidence of the TUG tables and the reading of eq. (3)-(4) per method."""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.tables.tug import tug_table3
from gaitval.tables.tug_evidence import EVIDENCE_COLUMNS, failure_evidence, method_reading


def test_method_reading_from_definition_or_name():
    assert method_reading("tug_m2") == ("tug_m2", "swing_first")
    assert method_reading("tug_m2_stance_first") == ("tug_m2", "stance_first")
    defs = {"mine": {"phase": {"name": "speed_thresholds", "reading": "stance_first"}}}
    assert method_reading("mine", defs) == ("mine", "stance_first")


def _frames(trial, method, n=40, swap_at=30):
    """Two legs 0.3 m apart; the left track jumps onto the right leg from scan swap_at."""
    k = np.arange(n)
    t = k * 0.025
    rows = []
    for side, y in (("L", 0.15), ("R", -0.15)):
        x = np.linspace(0.0, 1.0, n)
        ty = np.full(n, y)
        if side == "L":
            ty[swap_at:] = -0.15
        rows.append(pd.DataFrame({
            "trial": trial, "method": method, "k": k, "t_sensor_s": t, "side": side,
            "x_m": x, "y_m": ty, "xs_m": x, "ys_m": np.full(n, y), "valid": True,
            "err_x_m": 0.0, "err_y_m": ty - y, "observed": True, "interpolated": False,
            "pattern": np.where((side == "L") & (k >= swap_at - 5) & (k < swap_at), "UO", "SL"),
            "phase": np.where(k < 20, 3, 4), "swing": False,
            "tug_phase": np.where(k < 25, "forward", "turning"),
            "bad": (side == "L") & (k >= swap_at)}))
    return pd.concat(rows, ignore_index=True).sort_values(["k", "side"], ignore_index=True)


def test_failure_evidence_names_trial_time_leg_and_what_was_seen():
    f = _frames("t1", "tug_m2_stance_first")
    s = pd.DataFrame([{"trial": "t1", "method": "tug_m2_stance_first", "success": False,
                       "category": "false_tracking_turning"}])
    ev = failure_evidence(f, s)
    assert list(ev.columns) == EVIDENCE_COLUMNS and len(ev) == 1
    r = ev.iloc[0]
    assert (r.side, r.kind, r.tug_phase, r.phase_reading, r.base_method) == (
        "L", "swap", "turning", "stance_first", "tug_m2")
    assert r.t_s == 30 * 0.025 and r.uo_scans_before == 5
    assert r.legs_apart_m == 0.3 and r.other_leg_m < 1e-9
    assert "UO×5" in r.patterns_before and "3×" in r.gait_phases_before
    assert r.evidence.startswith("t1 tug_m2_stance_first: at 0.75 s (turning) L track jumped")


def test_table3_reading_rows_carry_the_base_methods_published_values():
    s = pd.DataFrame([{"trial": "a", "method": m, "success": True, "category": "success"}
                      for m in ("tug_m2", "tug_m2_stance_first")])
    t = tug_table3(s).set_index("method")
    assert t.loc["tug_m2_stance_first", "phase_reading"] == "stance_first"
    assert t.loc["tug_m2_stance_first", "n_success_published"] == 25
    assert t.loc["tug_m2", "phase_reading"] == "swing_first"
