"""The crowd benchmark: seeded multi-person scenes from the twin's ray caster, scored as
the leg_tracker benchmark scores its general sets (gaitval/crowd/)."""
import numpy as np
import pandas as pd
import pytest

from gaitval.crowd import bench, scenes
from gaitval.crowd.scenes import KINDS, make_scene


def _points(scans, k):
    a = scans.angle_min + scans.angle_increment * np.arange(scans.n_beams)
    r = scans.ranges[k]
    ok = np.isfinite(r)
    return np.column_stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])])


def test_a_scene_is_its_kind_and_seed():
    a, b = make_scene("crossing_moving", 11), make_scene("crossing_moving", 11)
    np.testing.assert_array_equal(a.scans.ranges, b.scans.ranges)
    pd.testing.assert_frame_equal(a.truth, b.truth)
    c = make_scene("crossing_moving", 12)
    assert a.scans.ranges.shape != c.scans.ranges.shape or \
        not np.array_equal(a.scans.ranges, c.scans.ranges, equal_nan=True)


def test_development_and_test_scenes_differ():
    assert not set(scenes.DEV_SEEDS) & set(scenes.TEST_SEEDS)
    assert {k for _, k, _ in bench.scenes("dev")} == set(KINDS) == \
        {k for _, k, _ in bench.scenes("test")}


@pytest.mark.parametrize("kind", list(KINDS))
def test_ground_truth_is_a_person_the_scan_sees(kind):
    """Every annotated person has ≥ 3 returns within a leg's reach of its centre on that
    scan (the benchmark's 'visible'), and the scene has the people its kind asks for."""
    sc = make_scene(kind, 11)
    lo, _ = KINDS[kind]["walkers"]
    assert sc.truth["id"].nunique() >= min(lo, 2)
    for row in sc.truth.sample(40, random_state=0).itertuples():
        p = _points(sc.scans, row.k)
        near = np.hypot(p[:, 0] - row.x_m, p[:, 1] - row.y_m) < 0.45
        assert near.sum() >= 3, (kind, row)


def test_a_moving_scene_moves_the_walls():
    st, mv = make_scene("crossing_static", 11), make_scene("crowd_moving", 11)
    assert mv.choices["sensor_speed_mps"] >= scenes.CHOICES["sensor_speed_mps"].lo
    assert st.choices["sensor_speed_mps"] == 0.0
    # the far wall straight ahead (9 m beyond the sensor's last position) comes nearer as
    # the sensor drives towards it: out of range (11 m) at the start
    mid = mv.scans.n_beams // 2
    r = mv.scans.ranges[:, mid - 3:mid + 4]
    last = np.nanmedian(r[-5:])
    assert 8.5 < last < 9.6
    assert np.isnan(r[:5]).all() or np.nanmedian(r[:5]) > last + 1.0


def test_scoring_counts_like_the_benchmark():
    truth = pd.DataFrame({"k": [0, 0, 1, 1, 2, 2], "id": ["a", "b"] * 3,
                          "x_m": [2.0, 3.0] * 3, "y_m": [0.0, 1.0] * 3})
    perfect = truth.rename(columns={"id": "hyp_id"}).assign(
        hyp_id=lambda d: d["hyp_id"].map({"a": 1, "b": 2}))
    s = bench.score(truth, perfect, 3)
    assert (s["matched"], s["misses"], s["fp"], s["idsw_ref"], s["mota_pct"]) == \
        (6, 0, 0, 0, 100.0)
    # a hypothesis behind the sensor is outside the sector: neither FP nor match
    behind = pd.concat([perfect, pd.DataFrame({"k": [1], "hyp_id": [9], "x_m": [-2.0],
                                               "y_m": [0.0]})])
    assert bench.score(truth, behind, 3)["fp"] == 0
    # one far-away hypothesis is a false positive; the id taken over is a reference switch
    extra = pd.concat([perfect, pd.DataFrame({"k": [1], "hyp_id": [7], "x_m": [6.0],
                                              "y_m": [0.0]})])
    s = bench.score(truth, extra, 3)
    assert s["fp"] == 1 and s["mota_pct"] == pytest.approx(100 * (1 - 1 / 6))
    swap = perfect.copy()
    swap.loc[(swap["k"] == 2) & (swap["hyp_id"] == 1), "hyp_id"] = 3
    s = bench.score(truth, swap, 3)
    assert s["idsw_ref"] == 1 and s["matched"] == 5


@pytest.mark.slow
def test_benchmark_table_is_written(tmp_path):
    rows = bench.run("dev", methods=("people",))
    assert set(rows["kind"]) == set(KINDS) and (rows["gt"] > 0).all()
    bench.write_crowd_table(rows, tmp_path / "legbench_crowd")
    t = pd.read_csv(tmp_path / "legbench_crowd.csv")
    assert set(t["method"]) == {"people"} and len(t) == len(KINDS)
    np.testing.assert_allclose(
        t["mota_pct"], 100 * (1 - (t["misses"] + t["fp"] + t["idsw_ref"]) / t["gt"]),
        rtol=1e-5)


@pytest.mark.parametrize("kind", ["crossing_static", "crowd_moving", "assisted"])
def test_no_track_outlives_the_returns_in_its_gate(kind):
    """A reported person whose gate (``return_gate_m`` around its centre) holds no scan
    return for longer than ``max_no_return_s`` has ended: clutter cannot coast.  (An
    observation assigned to a leg counts as returns there; it lies within a leg's radius
    of the returns it was made of.)"""
    from gaitval.track.staticmap import scan_points
    sc = make_scene(kind, 11)
    tr = bench.tracker("people")
    res = tr.track(sc.scans, bench.LEG_WIDTH_M)
    limit, gate = tr.deleter.max_no_return_s, tr.deleter.return_gate_m
    assert limit == pytest.approx(0.5) and len(res.people)
    centres = res.people.groupby(["k", "person_id"], sort=True)[["x_m", "y_m"]].mean()
    t = sc.scans.t
    last: dict = {}
    longest = 0.0
    for (k, pid), (x, y) in centres.iterrows():
        pts = scan_points(sc.scans, k)
        if pid not in last or (np.hypot(pts[:, 0] - x, pts[:, 1] - y)
                               <= gate + bench.LEG_WIDTH_M / 2).any():
            last[pid] = t[k]
        longest = max(longest, t[k] - last[pid])
    assert longest <= limit + 1e-9


@pytest.mark.slow
def test_the_crowd_tables_are_byte_identical_run_to_run(tmp_path):
    """Same seeds, same machine: the same bytes (no CPU time or other run-to-run figure
    in the tables; the CPU seconds stay in :func:`gaitval.crowd.bench.run`'s rows)."""
    from gaitval.crowd.bench import crowd_step

    for d in ("a", "b"):
        crowd_step(tmp_path / d, "dev")
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert names and names == sorted(p.name for p in (tmp_path / "b").iterdir())
    for n in names:
        assert (tmp_path / "a" / n).read_bytes() == (tmp_path / "b" / n).read_bytes(), n
