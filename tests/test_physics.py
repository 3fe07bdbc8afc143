"""The physical checks of a simulated study (gaitval.simulate.physics), run on tiny."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitval.simulate.kinematics import GaitParams, leg_kinematics, make_path, plan_steps
from gaitval.simulate.physics import COLUMNS, SWING_BACKWARD_MPS, physics_table, poisson_ci
from gaitval.simulate.shin import point_profile


@pytest.fixture(scope="module")
def tiny(tiny_simulated) -> Path:
    return tiny_simulated


@pytest.fixture(scope="module")
def physics(tiny) -> pd.DataFrame:
    return pd.read_csv(tiny / "physics.csv")


def test_simulate_writes_the_physics_table(physics):
    assert list(physics.columns) == COLUMNS
    assert {"swing_shin_backward", "step_length", "cadence", "tug_phase_duration",
            "tug_occlusion", "tug_turn_to_sit", "tug_return_to_chair", "tug_marker_clearance",
            "mtst_cross_steps", "treadmill_stride_sd"} <= set(physics["check"])
    # every row states its reference source and its tolerance
    assert physics["source"].notna().all() and physics["tolerance"].notna().all()
    assert set(physics.loc[physics["check"] == "tug_occlusion", "phase"]) == {
        "forward", "turning", "return"}


@pytest.mark.slow
def test_physics_rows_are_the_same_with_the_swing_statistics_on_a_pool(tiny):
    """generate_study maps the per-trial swing statistics over its worker processes
    (issue 13); the table is the serial one, row for row."""
    import concurrent.futures as cf
    import multiprocessing as mp

    serial = physics_table(tiny)
    with cf.ProcessPoolExecutor(2, mp_context=mp.get_context("fork")) as ex:
        pooled = physics_table(tiny, map_fn=ex.map)
    pd.testing.assert_frame_equal(pooled, serial)
    assert (serial["check"] == "swing_shin_backward").any()


def test_no_swinging_shin_moves_backwards(physics):
    """Issue 10: the swing shin's forward speed stays >= 0 (within noise) in every swing,
    gait initiation from the chair included, in every protocol."""
    rows = physics[physics["check"] == "swing_shin_backward"]
    assert set(rows["protocol"]) == {"tug", "mtst", "rollator"}
    assert (rows["value"] == 0).all() and rows["passed"].astype(bool).all()


def test_first_swing_from_standing_in_every_protocol(tiny, physics):
    """One gait-initiation model for every protocol (issue 10): each trial's first swing
    from standing moves forward and lasts a steady swing, (1 - stance_frac) 2 T -- MTST
    included, whose first swing used to last 0.9 T (1.36 x its median swing in tiny)."""
    from gaitval.simulate.swings import first_swing, lrs_trials
    rows = physics[physics["check"] == "first_swing_backward"]
    assert set(rows["protocol"]) == {"tug", "mtst", "rollator"}
    assert (rows["value"] == 0).all() and rows["passed"].astype(bool).all()
    for trial in lrs_trials(tiny)["trial"]:
        fwd_min, ratio = first_swing(tiny, trial)
        assert fwd_min > SWING_BACKWARD_MPS, trial
        # the median swing mixes straight, turning (1.15 T) and target steps, and the
        # first step's own T varies by the step CV: not exactly 1
        assert 0.85 <= ratio <= 1.1, (trial, ratio)


def test_tug_path_is_out_and_back_around_the_marker(physics):
    p = physics.set_index("check")
    assert p.loc["tug_marker_clearance", "value"] > 0          # around the cone, not through
    assert p.loc["tug_return_to_chair", "value"] <= 0.25       # back to the chair, no loop
    assert 0.7 <= p.loc["tug_turn_to_sit", "value"] <= 2.7


def test_first_step_from_standing_swings_forward():
    """A walker starting from standing (feet side by side) takes a short first step: its
    shin point at 0.27 m never moves back (the old kinematics swung it back at ~1 m/s)."""
    gp = GaitParams(step_length_m=0.75, step_time_s=0.42, stance_frac=0.58,
                    shank_length_m=0.42, roll_fwd_m=0.145, roll_up_m=0.10)
    path = make_path((0.0, 0.0), 0.0, [("line", 4.0, "forward")])
    plan = plan_steps(path, gp, np.random.default_rng(3), t0=0.5)
    t = np.arange(0.0, plan.t_end + 0.5, 0.005)
    for side in (0, 1):
        xy = leg_kinematics(plan, side, t, gp).point_at_height(0.27)
        f = plan.foot(side)
        swings = [(a, b) for a, b in zip(f["t_off"], f["t_contact"]) if np.isfinite(a)]
        prof = point_profile(t, xy, swings, 200.0)
        assert len(prof["fwd_min"]) >= 3
        assert prof["fwd_min"].min() > SWING_BACKWARD_MPS


def test_poisson_interval_of_the_cross_step_count():
    """Garwood's exact interval through the gamma distribution instead of chi-square:
    [Gamma(19).ppf(0.025), Gamma(20).ppf(0.975)] = [11.44, 29.67] counts."""
    from scipy.stats import gamma
    lo, hi = poisson_ci(19)
    assert lo == pytest.approx(gamma.ppf(0.025, 19), rel=1e-9)
    assert hi == pytest.approx(gamma.ppf(0.975, 20), rel=1e-9)
    assert (round(lo, 2), round(hi, 2)) == (11.44, 29.67)


def test_physics_table_without_real_data_marks_shin_rows_unchecked(tiny, tmp_path):
    from gaitval.simulate.study import _subject_rows, load_preset
    walkers = [(p, s["group"], gp) for p, s, gp in _subject_rows(load_preset("tiny"), 7)]
    t = physics_table(tiny, walkers, realdata=tmp_path / "absent")
    shin = t[t["check"].isin(["shin_swing_peak", "shin_stance_speed"])]
    assert len(shin) and shin["passed"].isna().all()
    assert shin["source"].str.contains("not checked").all()


def test_contact_rows_pass_on_tiny(physics):
    """Issue 34: the contact rows exist for every protocol and pass -- no swing closer than
    0.95 leg widths, no scan with overlapping shanks, feet back at hip width when seated,
    no cross step in the turn to sit."""
    clear = physics[physics["check"] == "shank_clearance"]
    scans = physics[physics["check"] == "shank_overlap_scans"]
    assert set(clear["protocol"]) == set(scans["protocol"]) == {"tug", "mtst", "rollator"}
    assert (clear["value"] >= 0.95).all() and clear["passed"].astype(bool).all()
    assert (scans["value"] == 0).all() and scans["passed"].astype(bool).all()
    p = physics.set_index("check")
    assert p.loc["tug_sit_foot_separation", "value"] <= 0.05
    assert p.loc["tug_turn_to_sit_cross", "value"] == 0
    assert bool(p.loc["tug_turn_to_sit", "passed"])


def test_contact_statistics_see_overlapping_shanks(tmp_path):
    """The clearance statistic is not blind: a trial whose two shanks pass through each
    other (written by hand) gives a per-swing minimum below 0.95 and overlapping scans."""
    from gaitval.simulate.physics import contact_stats
    d = tmp_path / "truth" / "x_t1"
    d.mkdir(parents=True)
    pd.DataFrame({"trial": ["x_t1"], "subject": ["S1"]}).to_csv(tmp_path / "trials.csv",
                                                                index=False)
    pd.DataFrame({"subject": ["S1"], "leg_width_m": [0.10]}).to_csv(tmp_path / "subjects.csv",
                                                                    index=False)
    t = np.arange(0.0, 1.0, 0.01)
    xl = np.where(t < 0.2, -0.3, np.where(t > 0.8, 0.3, -0.3 + (t - 0.2) / 0.6 * 0.6))
    legs = pd.concat([pd.DataFrame({"t_s": t, "side": "L", "x_m": xl, "y_m": 0.02}),
                      pd.DataFrame({"t_s": t, "side": "R", "x_m": 0.0, "y_m": -0.02})])
    legs.to_parquet(d / "legs.parquet")
    pd.DataFrame({"t_s": [0.2, 0.8], "event": ["foot_off", "foot_contact"], "side": ["L", "L"],
                  "label": ["", "walk"], "x_m": [np.nan, 0.3], "y_m": [np.nan, 0.02]}
                 ).to_csv(d / "events.csv", index=False)
    sc = legs.rename(columns={"t_s": "t_mocap_s"}).assign(scan=lambda f: (f["t_mocap_s"] * 100
                                                                           ).round().astype(int))
    sc.to_parquet(d / "scans_legs.parquet")
    mins, n_close, n_scans = contact_stats(tmp_path, "x_t1")
    assert len(mins) == 1 and mins[0] == pytest.approx(0.4, abs=0.05)
    assert n_scans == 100 and 0 < n_close < 100


@pytest.mark.slow
def test_default_twin_gait_passes_the_step_and_cross_step_rows():
    """The rows that failed on the default study before the gait calibration (see
    docs/simulator.md, "Physical checks"): TUG cadence (141.5 > 140 /min), MTST step length
    (0.272 < 0.297 body heights), MTST cadence (103.7 < 105 /min) and MTST cross steps
    (2.54 < 2.76 per 100 steps).  Computed by physics.py's own row functions on the true
    events of every TUG and MTST trial of the default preset, built without rendering
    (the events are those written to truth/<trial>/events.csv); about 10 s."""
    from gaitval.simulate import study as S
    from gaitval.simulate.physics import mtst_cross_row, step_rows_from_events
    from gaitval.simulate.render import gait_events
    from gaitval.simulate.study import load_preset

    cfg = load_preset("default")
    seed = int(cfg["seed"])
    events = {"tug": [], "mtst": []}
    for idx, proto, build, bargs, subj, _drift in S._lrs_tasks(cfg, cfg["study"], seed, []):
        if proto in events:
            sim = build(S._rng(seed, 3, idx), *bargs)
            events[proto].append((gait_events(sim), float(subj["height_m"])))
    assert len(events["tug"]) == 28 and len(events["mtst"]) == 48
    rows = {(r["protocol"], r["check"]): r for proto, evs in events.items()
            for r in step_rows_from_events(proto, evs)}
    rows[("mtst", "mtst_cross_steps")] = mtst_cross_row([ev for ev, _ in events["mtst"]])
    for key in [("tug", "step_length"), ("tug", "cadence"), ("mtst", "step_length"),
                ("mtst", "cadence"), ("mtst", "mtst_cross_steps")]:
        r = rows[key]
        assert r["passed"] is True, (key, r["value"], r["lower"], r["upper"])
        assert r["lower"] <= r["value"] <= r["upper"], key


def test_occluders_name_what_stands_on_the_line_of_sight():
    """physics.occluders: a leg straight behind the turn marker (as seen from the sensor)
    is screened by the marker; a leg behind the other leg by that leg; a leg with the
    other leg behind it and nothing in front by neither (hand-made geometry, sensor turned
    and shifted in the field as the TUG sensor is)."""
    from gaitval.simulate.physics import occluders
    from gaitval.simulate.scene import ID_MARKER, ID_POLE

    pose = (-0.7, -1.0, 0.3)
    circles = np.array([[3.0, 0.0, 0.06, ID_MARKER], [1.4, -1.0, 0.025, ID_POLE]])
    c, s = np.cos(pose[2]), np.sin(pose[2])
    mx, my = c * (3.0 + 0.7) + s * 1.0, -s * (3.0 + 0.7) + c * 1.0   # marker, sensor frame
    k = 1.12                                     # 12 % farther along the marker's ray
    scans = pd.DataFrame({
        "scan": [0, 0, 1, 1, 2, 2], "side": ["L", "R"] * 3,
        # scan 0: L behind the marker, R well to the side; scan 1: L behind R (same
        # bearing, R 0.2 m nearer); scan 2: R behind L (same bearing, L 0.3 m nearer)
        "x_m": [k * mx, mx, 3.0, 2.8, 2.0, 2.3],
        "y_m": [k * my, my + 0.8, 0.5, 0.5 * 2.8 / 3.0, -1.0, -1.0 * 2.3 / 2.0],
        "occluded": [True, False, True, False, False, True],
        "phase": ["turning", "turning", "forward", "forward", "return", "return"]})
    out = occluders(scans, pose, 0.10, circles).set_index("scan")
    assert list(out.index) == [0, 1, 2]
    assert out.loc[0, "by_turn_marker"] and not out.loc[0, "by_leg"]
    assert out.loc[1, "by_leg"] and not out.loc[1, "by_turn_marker"]
    assert out.loc[2, "by_leg"] and out.loc[2, "side"] == "R"
    assert not out[["by_pole"]].to_numpy().any()
    # a leg with nothing in front of it (the other leg behind it) is screened by nothing
    far = scans.assign(occluded=[False, False, False, True, False, False])
    one = occluders(far, pose, 0.10, circles)
    assert len(one) == 1 and not one.iloc[0]["by_leg"] and not one.iloc[0]["by_turn_marker"]


def test_tug_occlusion_notes_name_the_screens_and_the_return_split(tiny, physics):
    """The tug_occlusion notes count, per phase, the occluded leg-scans with the turn
    marker on the line of sight (the walker goes around the cone on its far side, seen
    from the chair end) and those screened by the other leg only; on the straight walks
    only the legs hide each other.  The return row's note splits the phase into the walk
    back, the turn to sit and the sitting down, which add up to the phase; the phases
    span the TUG, from the start of the rise to seated, and the capture's still-seated
    spans around it are labelled "seated"."""
    import re

    from gaitval.simulate.physics import occluders, tug_scene_circles, tug_span, tug_timeline

    occ = physics[physics["check"] == "tug_occlusion"].set_index("phase")
    counts = {}
    for ph in ("forward", "turning", "return"):
        m = re.search(r"the (\d+) occluded leg-scans: the turn marker (\d+), the other leg "
                      r"only (\d+), neither (\d+)", occ.loc[ph, "note"])
        assert m, occ.loc[ph, "note"]
        n, mk, leg, none = map(int, m.groups())
        assert mk + leg + none == n
        counts[ph] = (n, mk, leg)
    for ph in ("forward", "return"):
        assert counts[ph][1] == 0 and counts[ph][2] == counts[ph][0], (ph, counts[ph])
    assert counts["turning"][1] > 0
    # the same from the function, trial by trial, and the return split
    trials = pd.read_csv(tiny / "trials.csv")
    subj = pd.read_csv(tiny / "subjects.csv").set_index("subject")
    poses = pd.read_csv(tiny / "truth" / "sensor_pose.csv").set_index("trial")
    n_turn = 0
    for _, tr in trials[trials["protocol"] == "tug"].iterrows():
        d = tiny / "truth" / tr["trial"]
        legs = pd.read_parquet(d / "legs.parquet")
        s = pd.read_parquet(d / "scans_legs.parquet")
        t_end = float(legs["t_s"].max())
        s = s[(s["t_mocap_s"] >= 0) & (s["t_mocap_s"] <= t_end)]
        o = occluders(s, poses.loc[tr["trial"], ["x_m", "y_m", "yaw_rad"]].to_numpy(float),
                      float(subj.loc[tr["subject"], "leg_width_m"]), tug_scene_circles(tiny))
        n_turn += int((o["phase"] == "turning").sum())
        ev = pd.read_csv(d / "events.csv")
        tl = tug_timeline(ev, s, t_end)
        assert all(v > 0 for v in tl.values()), tl
        t_rise, t_seated = tug_span(ev, t_end)
        ret = s.loc[s["phase"] == "return", "t_mocap_s"]
        span = t_seated - float(s.loc[s["phase"] == "turning", "t_mocap_s"].max())
        assert tl["walk_back"] + tl["turn_to_sit"] + tl["sitting_down"] == \
            pytest.approx(span, abs=1e-9)
        # the scans' span of the return phase, within a scan period at either end
        assert span == pytest.approx(ret.max() - ret.min(), abs=0.05)
        # the TUG phases start with the rise and end seated; before and after, the
        # capture's still-seated spans ("seated", no TUG phase) where no leg moves
        fwd = s.loc[s["phase"] == "forward", "t_mocap_s"]
        assert fwd.min() >= t_rise and fwd.min() - t_rise < 0.03
        assert ret.max() <= t_seated and t_seated - ret.max() < 0.03
        still = s[s["phase"] == "seated"]
        assert len(still) and still["t_mocap_s"].between(t_rise, t_seated).sum() == 0
        for span in (still[still["t_mocap_s"] < t_rise], still[still["t_mocap_s"] > t_seated]):
            moved = span.groupby("side")[["x_m", "y_m"]].agg(lambda v: v.max() - v.min())
            assert len(span) and float(moved.to_numpy().max()) < 1e-3, moved
    assert n_turn == counts["turning"][0]


def test_tug_variant_reproduces_the_study_and_the_marker_screens_only_the_turn(physics):
    """tug_variants.tug_occlusion_variant re-renders the preset's TUG trials in memory:
    with the twin's own choices it gives the written study's phase durations and truth
    occlusion (the physics rows); with the turn marker out of the scan plane only the
    turning phase changes (the marker stands at the turn), and its occlusion falls to at
    least the leg-on-leg count of the turning row's note."""
    import re

    from gaitval.simulate.tug_variants import tug_occlusion_variant

    same = tug_occlusion_variant("tiny")
    rows = physics.set_index(["check", "phase"])
    for ph in ("forward", "turning", "return"):
        assert same.loc[ph, "occlusion"] == pytest.approx(
            rows.loc[("tug_occlusion", ph), "value"], rel=1e-5)
        assert same.loc[ph, "seconds"] == pytest.approx(
            rows.loc[("tug_phase_duration", ph), "value"], rel=1e-5)
    low = tug_occlusion_variant("tiny", marker_in_scan_plane=False)
    for ph in ("forward", "return"):
        assert low.loc[ph].equals(same.loc[ph]), ph
    assert low.loc["turning", "leg_scans"] == same.loc["turning", "leg_scans"]
    assert low.loc["turning", "occluded"] < same.loc["turning", "occluded"]
    leg_only = int(re.search(r"the other leg only (\d+)",
                             rows.loc[("tug_occlusion", "turning"), "note"]).group(1))
    assert low.loc["turning", "occluded"] >= leg_only


def test_the_study_records_its_tug_scene_and_the_marker_section_reaches_the_laser(tiny):
    """The preset's ``tug.marker_scan_radius_m`` (the turn marker's section in the scan
    plane, docs/simulator.md "The TUG scene") is what the laser sees: the study writes it
    into ``truth/tug_scene.csv`` (read back by the physics rows), a radius of 0 leaves the
    marker out of the scene, exactly as a marker below the plane, and the walker's path
    does not depend on it (same phases, same leg-scans)."""
    import yaml

    from gaitval.simulate.physics import tug_scene_circles
    from gaitval.simulate.scene import ID_MARKER
    from gaitval.simulate.study import PRESET_DIR
    from gaitval.simulate.tug import MARKER_RADIUS_M, TUG_MARKER_XY, scene_circles
    from gaitval.simulate.tug_variants import tug_occlusion_variant

    preset = yaml.safe_load((PRESET_DIR / "tiny.yaml").read_text())
    radius = float(preset["tug"]["marker_scan_radius_m"])
    scene = pd.read_csv(tiny / "truth" / "tug_scene.csv")
    marker = scene[scene["object"] == "turn_marker"]
    assert len(marker) == 1 and marker["radius_m"].iloc[0] == pytest.approx(radius)
    assert tuple(marker[["x_m", "y_m"]].iloc[0]) == pytest.approx(TUG_MARKER_XY)
    assert np.array_equal(tug_scene_circles(tiny), scene_circles(radius))
    assert ID_MARKER not in scene_circles(0.0)[:, 3]
    assert len(scene_circles(0.0)) == len(scene_circles(MARKER_RADIUS_M)) - 1
    with pytest.raises(ValueError, match="marker_scan_radius_m"):
        scene_circles(-0.01)
    below = tug_occlusion_variant("tiny", marker_in_scan_plane=False)
    zero = tug_occlusion_variant("tiny", marker_scan_radius_m=0.0)
    wide = tug_occlusion_variant("tiny", marker_scan_radius_m=MARKER_RADIUS_M)
    assert zero.equals(below)
    assert wide["leg_scans"].equals(zero["leg_scans"]) and wide["seconds"].equals(zero["seconds"])
    # a marker in the plane hides turning leg-scans; on the way out the walker never has
    # it between the leg and the sensor (it can, at the start of the return)
    assert wide.loc["turning", "occluded"] > zero.loc["turning", "occluded"]
    assert wide.loc["forward", "occluded"] == zero.loc["forward", "occluded"]
    assert wide.loc["return", "occluded"] >= zero.loc["return", "occluded"]


def test_a_first_step_that_is_a_shuffle_has_no_direction_and_does_not_crash_the_checks():
    """A twin drawn by the robustness ensemble whose first step moves the shin point < 5 cm
    (a shuffle) stopped the simulation's physics table with an IndexError; that swing has
    no direction, so its forward speed is NaN and the second swing still measures."""
    import numpy as np
    import pandas as pd
    from gaitval.simulate.swings import _first

    t = np.arange(0.0, 4.0, 0.01)
    x_l = np.where(t < 1.0, 0.0, np.where(t < 1.5, 0.03 * (t - 1.0) / 0.5, 0.03))  # 3 cm
    x_r = np.where(t < 2.0, 0.0, np.where(t < 2.5, 0.6 * (t - 2.0) / 0.5, 0.6))
    legs = pd.concat([pd.DataFrame({"t_s": t, "side": s, "x_m": x, "y_m": 0.0})
                      for s, x in (("L", x_l), ("R", x_r))])
    ev = pd.DataFrame({"t_s": [1.0, 1.5, 2.0, 2.5],
                       "side": ["L", "L", "R", "R"],
                       "event": ["foot_off", "foot_contact"] * 2})
    fwd_min, ratio = _first(legs, ev)
    assert np.isnan(fwd_min)
    assert ratio == 1.0
