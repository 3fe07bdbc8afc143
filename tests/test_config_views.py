"""The per-method config views the per-trial jobs read
(gaitval.pipeline.steps.config.method_view)."""
from __future__ import annotations

import json

import pytest

from gaitval.pipeline.steps.config import STUDY_VIEW, method_definition, method_view, study_config


CFG = {
    "registration": {"sync_bin_deg": 0.5},
    "tracking": {
        "methods": {"tug_m1_stance_first": {"label": "variant"}, "custom": {"label": "c"}},
        "overrides": {"tug_m1": {"occlusion__max_n": 7}, "custom": {"gate__g": 9.0}},
    },
}


def test_a_methods_view_keeps_its_own_definition_and_nothing_of_the_others():
    v = method_view(CFG, "custom")
    assert v["tracking"] == {"methods": {"custom": {"label": "c"}},
                             "overrides": {"custom": {"gate__g": 9.0}}}
    assert v["registration"] == CFG["registration"]
    # what a job of that method looks up is the same in the view as in the full config
    assert method_definition(v, "custom") == method_definition(CFG, "custom")
    assert method_definition(v, "tug_m1") == "tug_m1"          # built-in: by name
    assert method_view(CFG, "tug_m1")["tracking"]["overrides"] == {"tug_m1": {"occlusion__max_n": 7}}
    assert CFG["tracking"]["overrides"]["custom"] == {"gate__g": 9.0}   # input not modified


def test_the_study_view_has_no_method_and_views_do_not_depend_on_other_methods():
    assert method_view(CFG, STUDY_VIEW)["tracking"] == {"methods": {}, "overrides": {}}
    other = json.loads(json.dumps(CFG))
    other["tracking"]["overrides"]["tug_m1"] = {"occlusion__max_n": 3}
    assert method_view(other, "custom") == method_view(CFG, "custom")
    assert method_view(other, STUDY_VIEW) == method_view(CFG, STUDY_VIEW)
    assert method_view(other, "tug_m1") != method_view(CFG, "tug_m1")


def test_study_config_writes_the_view_after_merging_study_yaml(tmp_path):
    sheet = tmp_path / "trials.csv"
    sheet.write_text("trial\n")
    (tmp_path / "study.yaml").write_text(
        "tracking:\n  overrides:\n    custom: {gate__g: 5.0}\n    tug_m1: {occlusion__max_n: 4}\n")
    out = tmp_path / "custom.json"
    cfg = study_config(CFG, sheet, out, view="custom")
    assert json.loads(out.read_text()) == cfg
    # study.yaml wins for this study, and the view still holds this method's entries only
    assert cfg["tracking"]["overrides"] == {"custom": {"gate__g": 5.0}}
    assert cfg["calibration_file"] == str(tmp_path / "study.yaml")


def test_a_scoped_view_leaves_out_the_other_protocol_families_sections():
    """Scope 'rollator' (the views of the rollator trials' jobs) keeps the rollator: section
    and the shared ones, not tug:/mtst:/ultrasonic:, so a new rollator.pf_seed changes no
    TUG, MTST or ultrasonic job's view (issue 13)."""
    from gaitval.errors import ConfigError
    from gaitval.pipeline.steps.config import PROTOCOL_SCOPE, SCOPES

    cfg = {**CFG, "rollator": {"pf_seed": 2017}, "tug": {"a": 1}, "mtst": {"b": 2},
           "ultrasonic": {"c": 3}, "evaluation": {"tug": {}}}
    v = method_view(cfg, STUDY_VIEW, "rollator")
    assert set(v) == {"registration", "tracking", "rollator", "evaluation"}
    assert set(method_view(cfg, "custom", "all")) == set(cfg)
    other = {**cfg, "rollator": {"pf_seed": 2018}}
    for scope in ("tug", "mtst", "ultrasonic"):
        assert method_view(other, "custom", scope) == method_view(cfg, "custom", scope)
    assert method_view(other, STUDY_VIEW, "rollator") != v
    assert set(PROTOCOL_SCOPE.values()) == set(SCOPES)
    with pytest.raises(ConfigError, match="walking"):
        method_view(cfg, STUDY_VIEW, "walking")
