"""The robustness ensemble of the twin (gaitval.robustness; docs/robustness.md):
the seeded design, the twins' presets, the share table and its class by the stated
criterion, the share beside the report's verdicts, and (slow) two twins at the tiny sizes
run end to end through the workflow."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from gaitval.report.robustness_share import NOT_RUN, config_digest, share_column
from gaitval.robustness.design import (PRESET_DIR, design, ensemble_name, load_config,
                                       twin_presets)
from gaitval.robustness.summary import ROBUST_SHARE, classify, robustness_table

ROOT = Path(__file__).resolve().parents[1]

TINY = {"n_twins": 2, "design_seed": 5, "base_preset": "tiny", "base_study": "tiny",
        "name_prefix": "robtest",
        "factors": {"tug_turn_to_sit": {"choices": ["left", "right"], "set": "tug.turn_to_sit"},
                    "tug_sensor_lateral_m": {"range": [-2.0, -1.0]},
                    "tug_sensor_behind_m": {"range": [-1.0, -0.4]},
                    "mtst_sensor_place": {"choices": ["line", "beside"]},
                    "mtst_sensor_distance": {"range": [0.0, 1.0]},
                    "leg_width_scale": {"range": [0.8, 1.3], "set": "leg_width_scale",
                                        "protocols": ["tug", "mtst", "rollator"]},
                    "seed": {"integer": [1, 99999999], "set": "seed"}}}


def _cfg(tmp_path, **over) -> dict:
    f = tmp_path / "robustness.yaml"
    f.write_text(yaml.safe_dump({**TINY, **over}))
    return load_config(f)


def test_the_shipped_configuration_draws_at_least_16_twins_over_every_factor():
    cfg = load_config()
    assert cfg["n_twins"] >= 16
    d = design(cfg)
    assert len(d) == cfg["n_twins"] and list(d.columns) == list(cfg["factors"])
    for name, spec in cfg["factors"].items():
        if "range" in spec:
            lo, hi = spec["range"]
            assert d[name].between(lo, hi).all(), name
        elif "choices" in spec:
            assert set(d[name]) == set(spec["choices"]), name       # every choice drawn


def test_design_is_seeded_and_space_filling(tmp_path):
    cfg = _cfg(tmp_path, n_twins=8)
    a, b = design(cfg), design(cfg)
    pd.testing.assert_frame_equal(a, b)
    other = design(_cfg(tmp_path, n_twins=8, design_seed=6))
    assert not a.equals(other)
    # a Latin hypercube: each of the 8 strata of a range factor holds exactly one twin
    u = (a["tug_sensor_lateral_m"] + 2.0) / 1.0
    assert sorted(np.floor(u * 8).astype(int)) == list(range(8))


def test_the_choices_are_a_full_factorial_so_no_two_are_confounded(tmp_path):
    # the shipped design: 16 twins, three two-way choices -> every combination twice (a
    # Latin hypercube paired the MTST sensor place with the attendant side in 14 of 16)
    cfg = load_config()
    d = design(cfg)
    choice = [n for n, f in cfg["factors"].items() if "choices" in f]
    assert len(choice) >= 2
    counts = d[choice].value_counts()
    n_combos = math.prod(len(cfg["factors"][c]["choices"]) for c in choice)
    assert len(counts) == n_combos and set(counts) == {len(d) // n_combos}
    # the range factors stay a Latin hypercube: one twin per stratum
    lo, hi = cfg["factors"]["mtst_attendant_lateral_m"]["range"]
    u = (d["mtst_attendant_lateral_m"] - lo) / (hi - lo)
    assert sorted(np.floor(u * len(d)).astype(int)) == list(range(len(d)))
    # too few twins for the factorial (2 twins, 4 combinations): the hypercube's draws
    small = design(_cfg(tmp_path, n_twins=2))
    assert small["tug_turn_to_sit"].nunique() == 2 and small["mtst_sensor_place"].nunique() == 2


def test_twin_presets_compose_the_sensor_poses(tmp_path):
    cfg = _cfg(tmp_path, n_twins=4)
    d = design(cfg)
    base = yaml.safe_load((PRESET_DIR / "tiny.yaml").read_text())
    presets = twin_presets(cfg, base, d)
    for twin, p in presets.items():
        row = d.loc[twin]
        x, y, yaw = p["tug"]["sensor_nominal_pose"]
        assert (x, y) == (round(row["tug_sensor_behind_m"], 4),
                          round(row["tug_sensor_lateral_m"], 4))
        assert math.isclose(yaw, math.atan2(-y, 3.0 - x), abs_tol=1e-3)   # looks at the marker
        mx, my, myaw = p["mtst"]["sensor_nominal_pose"]
        if row["mtst_sensor_place"] == "line":
            assert my == 0.0 and 5.85 + 0.5 <= mx <= 5.85 + 1.5
        else:
            assert mx == 2.0 and 0.575 + 0.8 <= my <= 0.575 + 1.5
        assert p["tug"]["turn_to_sit"] == row["tug_turn_to_sit"]
        assert p["seed"] == row["seed"] and p["study"] == twin
        assert p["leg_width_scale"] == pytest.approx(row["leg_width_scale"])
    assert ensemble_name(cfg).startswith("robustness_")


def test_the_shipped_ensemble_shifts_the_target_rows_and_sets_the_stick(tmp_path):
    """The shipped configuration's MTST layout and stick factors reach every twin's preset:
    the rows' spacing range is the default 1.0-1.4 m shifted by the drawn -0.2 to +0.2 m
    (rows 0.8-1.6 m apart), the lanes and the stick's hand and offset are the drawn ones."""
    cfg = load_config(ROOT / "config" / "robustness.yaml")
    d = design(cfg)
    base = yaml.safe_load((PRESET_DIR / "default.yaml").read_text())
    for twin, p in twin_presets(cfg, base, d).items():
        row = d.loc[twin]
        lo, hi = p["mtst"]["targets"]["row_spacing_m"]
        assert hi - lo == pytest.approx(0.4)
        assert lo == pytest.approx(1.0 + row["mtst_target_row_shift_m"], abs=1e-4)
        assert 0.8 - 1e-4 <= lo and hi <= 1.6 + 1e-4
        assert p["mtst"]["targets"]["lane_m"] == pytest.approx(row["mtst_target_lane_m"])
        assert 0.27 <= p["mtst"]["targets"]["lane_m"] <= 0.40
        assert p["mtst"]["stick"] == {"side": row["mtst_stick_side"],
                                      "offset_m": pytest.approx(row["mtst_stick_offset_m"])}
    assert set(d["mtst_stick_side"]) == {"left", "right"}


def test_classes_follow_the_stated_criterion():
    # 16 of 16: Wilson lower bound 0.806 -> robust; 15 of 16: 0.717 -> hinges
    from statsmodels.stats.proportion import proportion_confint

    assert classify(*proportion_confint(16, 16, method="wilson")) == "robust: reproduced"
    assert classify(*proportion_confint(15, 16, method="wilson")) == "hinges on the set-up"
    assert classify(*proportion_confint(0, 16, method="wilson")) == "robust: not reproduced"
    assert classify(0.0, 0.19, comparable=0) == "not comparable in any twin"
    assert ROBUST_SHARE == 0.8


def _outcomes(d: pd.DataFrame) -> pd.DataFrame:
    """Synthetic verdicts: one reproduced in every twin, one exactly when the TUG turn
    to sit is to the right, one never comparable."""
    rows = []
    for twin, r in d.iterrows():
        rows += [{"study": "tug", "comparison": "always", "source": "T3", "outcome": "reproduced",
                  "twin": twin},
                 {"study": "tug", "comparison": "right only", "source": "T4", "twin": twin,
                  "outcome": "reproduced" if r["tug_turn_to_sit"] == "right" else
                  "not reproduced"},
                 {"study": "mtst", "comparison": "never", "source": "T3", "twin": twin,
                  "outcome": "not comparable"}]
    return pd.DataFrame(rows)


def test_table_names_the_choice_that_moves_a_verdict(tmp_path):
    cfg = _cfg(tmp_path, n_twins=16)
    d = design(cfg)
    tab = robustness_table(d, _outcomes(d), cfg).set_index("comparison")
    assert tab.loc["always", "share"] == "16/16"
    assert tab.loc["always", "robustness"] == "robust: reproduced"
    right = int((d["tug_turn_to_sit"] == "right").sum())
    assert tab.loc["right only", "share"] == f"{right}/16"
    assert tab.loc["right only", "robustness"] == "hinges on the set-up"
    assert tab.loc["right only", "moved_most_by"].startswith("tug_turn_to_sit ρ=+1.00")
    assert "mtst_" not in tab.loc["right only", "moved_most_by"]      # another protocol's
    from gaitval.robustness.summary import relevant
    assert relevant(d.columns, "ultrasonic", cfg) == ["seed"]        # leg width: laser only
    assert "leg_width_scale" in relevant(d.columns, "tug", cfg)
    assert tab.loc["never", "robustness"] == "not comparable in any twin"


def _record(root: Path, tab: pd.DataFrame, cfg: dict, **over) -> None:
    from gaitval.report.provenance import source_digest

    d = root / "robustness"
    d.mkdir(parents=True, exist_ok=True)
    tab.to_csv(d / "robustness.csv", index=False)
    meta = {"code_digest": source_digest(), "config_digest": config_digest(cfg["_path"]),
            "config_path": cfg["_path"], "base_study": "tiny", **over}
    (d / "robustness.json").write_text(json.dumps(meta))


def test_report_shows_the_share_only_for_the_same_code_config_and_study(tmp_path):
    cfg = _cfg(tmp_path, n_twins=16)
    d = design(cfg)
    tab = robustness_table(d, _outcomes(d), cfg)
    v = pd.DataFrame({"study": ["tug", "tug", "rollator"],
                      "comparison": ["always", "right only", "absent"],
                      "source": ["T3", "T4", "T1"]})
    tables = tmp_path / "reports" / "tiny" / "tables"
    tables.mkdir(parents=True)
    assert share_column(v, tables) == [NOT_RUN] * 3                  # no ensemble yet
    _record(tmp_path / "reports", tab, cfg)
    got = share_column(v, tables)
    assert got[0].startswith("16/16 (") and got[0].endswith("robust: reproduced")
    assert got[1].endswith("hinges on the set-up") and got[2] == NOT_RUN
    other = tmp_path / "reports" / "default" / "tables"
    other.mkdir(parents=True)
    assert share_column(v, other) == [NOT_RUN] * 3                   # another study's report
    _record(tmp_path / "reports", tab, cfg, code_digest="000000000000")
    assert share_column(v, tables) == [NOT_RUN] * 3                  # another code


@pytest.mark.slow
def test_two_tiny_twins_run_through_the_workflow(tmp_path):
    """Two twins of the tiny study, each an ordinary study of the workflow, their table,
    and the base report's verdicts with the shares beside them.

    The twins run without gaitval's own people trackers (``people``, ``people_offline``:
    the extra rows of the TUG, MTST and rollator tables, which carry no verdict;
    gaitval.report.verdicts keeps the papers' methods only), so every verdict and every
    share is what the full method lists give, for a third less tracking.  (A second
    ``--configfile`` replaces the first, so the ensemble's own file is named again.)"""
    from gaitval.report.verdicts import build_verdicts
    from gaitval.robustness.runner import OUT, run_ensemble

    cfg = _cfg(tmp_path)
    presets = PRESET_DIR / ensemble_name(cfg)
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    papers = tmp_path / "papers_methods.yaml"
    papers.write_text(yaml.safe_dump({
        "tug": {"methods": [m for m in base["tug"]["methods"] if not m.startswith("people")]},
        "mtst": {"methods": [m for m in base["mtst"]["methods"]
                             if not m.startswith("people")]},
        "rollator": {"methods": [m for m in base["rollator"]["methods"]
                                 if not m.startswith("people")]}}))
    ensemble = tmp_path / OUT / "ensemble.yaml"         # written by run_ensemble
    try:
        rc = run_ensemble(cfg["_path"], tmp_path, ["--cores", "2", "--force-use-threads",
                                                   "--configfile", str(ensemble),
                                                   str(papers)])
    finally:
        shutil.rmtree(presets, ignore_errors=True)
    assert rc == 0
    out = tmp_path / "reports" / "robustness"
    twin_tug = pd.read_csv(out / "twins" / "robtest_00" / "tables" / "tug_table3.csv")
    assert not twin_tug["method"].str.startswith("people").any()     # the subset ran
    tab = pd.read_csv(out / "robustness.csv", keep_default_na=False)
    assert set(tab["twins"]) == {2}
    assert {"tug", "mtst", "rollator", "ultrasonic"} <= set(tab["study"])
    assert (out / "robustness.html").is_file()
    twin0 = pd.read_csv(out / "twins" / "robtest_00" / "verdicts.csv", keep_default_na=False)
    assert len(tab) == len(twin0.drop_duplicates(["study", "comparison", "source"]))
    # the base study's report (here: a copy of twin 0's tables under reports/tiny) shows
    # each verdict's share
    shutil.copytree(out / "twins" / "robtest_00" / "tables", tmp_path / "reports" / "tiny" /
                    "tables")
    v = build_verdicts(tmp_path / "reports" / "tiny" / "tables").merge(
        twin0[["study", "comparison", "source"]].drop_duplicates())   # the twins' verdicts
    assert len(v) == len(tab)
    assert all(s.split(" (")[0].endswith("/2") for s in v["robustness"]), v["robustness"]
