"""Methods as configuration (seed 000 Table 3): registries, build_tracker, track_trial."""
from __future__ import annotations

import numpy as np
import pytest

from gaitval.detect import DETECTORS
from gaitval.errors import ConfigError
from gaitval.methods import METHODS, ROLES, build_tracker, get_method, set_params, track_trial
from gaitval.track import ROLE_REGISTRIES, TRACKER_KINDS
from gaitval.track.tracker import TRACK_COLUMNS
from tug_synth import tug_scans

REGISTRIES = {"detector": DETECTORS, **ROLE_REGISTRIES}


@pytest.fixture(scope="module")
def scans_truth():
    return tug_scans(seed=2)


def test_table3_definitions_and_table2_defaults():
    m1, m2, m3 = (METHODS[k] for k in ("tug_m1", "tug_m2", "tug_m3"))
    assert m1["associator"]["name"] == "gnn" and m1["occlusion"]["name"] == "predict_only"
    assert m2["associator"]["name"] == "gait_phase" and m2["occlusion"]["name"] == "predict_only"
    assert m3["associator"]["name"] == "gait_phase" and m3["occlusion"]["name"] == "catmull_rom"
    for m in (m1, m2, m3):                                  # seed 000 Table 2
        assert m["filter"]["q_accel_sd_mps2"] == 15.0 and m["filter"]["r_sd_m"] == 0.04
        assert m["phase"]["v_st_th"] == 0.47 and m["phase"]["v_sw_th"] == 0.93
        assert m["gate"]["g"] == 13.82 and m["motion"]["n_ac"] == 40


@pytest.mark.parametrize("role", ROLES)
def test_every_method_part_is_registered(role):
    for m in METHODS.values():
        if role not in m and "kind" in m:     # a raw-scan tracker (seed 002's PF) names its kind
            assert m["kind"]["name"] in TRACKER_KINDS
            continue
        spec = m[role]
        name = spec if isinstance(spec, str) else spec["name"]
        assert name in REGISTRIES[role]


def test_registries_cover_every_role():
    """A method names exactly the roles the tracker is built from."""
    assert set(REGISTRIES) == set(ROLES)


def test_nested_overrides_by_path():
    det, tr = build_tracker("tug_m3", {"occlusion__n_bo": 4, "gate__g": 9.21,
                                       "phase__v_st_th": 0.3, "tracker__dt_s": 0.05})
    assert tr.occlusion.n_bo == 4 and tr.gate.g == 9.21 and tr.phase.v_st_th == 0.3
    assert tr.dt_s == 0.05
    assert METHODS["tug_m3"]["occlusion"]["n_bo"] == "match"       # defaults untouched
    with pytest.raises(ConfigError, match="role"):
        set_params(METHODS["tug_m1"], {"nonsense": 1})


def test_unknown_names_are_config_errors():
    with pytest.raises(ConfigError, match="unknown tracking method"):
        get_method("tug_m9")
    with pytest.raises(ConfigError, match="unknown associator"):
        build_tracker("tug_m1", {"associator__name": "jpda"})
    with pytest.raises(ConfigError, match="missing the role"):
        get_method({"detector": "leg_patterns"})


def test_a_new_method_is_a_config_entry(scans_truth):
    scans, _ = scans_truth
    custom = get_method("tug_m2")
    custom["gate"] = {"name": "fixed_radius", "radius_leg_widths": 1.5}
    custom["motion"] = "constant_velocity"
    df = track_trial(scans, custom, 0.1)
    assert len(df) == 2 * scans.n_scans


@pytest.mark.parametrize("method", sorted(METHODS))
def test_track_trial_contract(scans_truth, method):
    scans, legs = scans_truth
    df = track_trial(scans, method, 0.1)
    assert list(df.columns) == list(TRACK_COLUMNS)
    assert len(df) == 2 * scans.n_scans
    assert df["side"].tolist()[:4] == ["L", "R", "L", "R"]
    assert set(df["pattern"]) <= {"SL", "LT", "FS_O", "FS_U", "UO", ""}
    assert df["phase"].between(-1, 5).all()
    assert not (df["observed"] & (df["pattern"] == "UO")).any()
    # sensor-frame positions follow the synthetic legs: a seed 000 TUG at 40 Hz with 5 m/s
    # swings, so the accuracy bar is for that protocol's methods (the MTST methods' Q =
    # 5² m²/s⁴ is for elderly walkers at 20 Hz: tests/test_mtst_track.py)
    if not METHODS[method].get("paper", "").startswith("seed 000"):
        return
    for s in "LR":
        d = df[df.side == s]
        e = np.hypot(d.x_m.to_numpy() - legs[s][:, 0], d.y_m.to_numpy() - legs[s][:, 1])
        assert np.sqrt(np.nanmean(e ** 2)) < 0.05


def test_track_trial_is_deterministic(scans_truth):
    scans, _ = scans_truth
    a = track_trial(scans, "tug_m3", 0.1)
    b = track_trial(scans, "tug_m3", 0.1)
    assert a.equals(b)


