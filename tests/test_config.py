"""The config schema catches typos (gaitval.configcheck), and Table 2 shows the methods run.

Every problem must name the file, the key's full path and, for a typo, the nearest valid
key; the shipped config and every key the code reads with a default must validate.
"""
from __future__ import annotations

import copy
import inspect
import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

from gaitval.configcheck import check_config, check_study_file, load_schema
from gaitval.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"


@pytest.fixture
def cfg() -> dict:
    with open(CONFIG, encoding="utf-8") as fh:
        return yaml.safe_load(fh)


def error_of(config: dict, layers=None) -> str:
    with pytest.raises(ConfigError) as exc:
        check_config(config, layers)
    return str(exc.value)


# -- the shipped files ------------------------------------------------------------------
def test_shipped_config_validates(cfg):
    check_config(cfg)


def test_simulated_study_yaml_validates(tiny_simulated):
    """The study.yaml the simulator writes beside a generated trial sheet (the session's
    tiny preset, tests/conftest.py: generated once for every test that reads it)."""
    with open(tiny_simulated / "study.yaml", encoding="utf-8") as fh:
        study = yaml.safe_load(fh)
    assert "rollator" in study and "registration" in study
    check_study_file(study, tiny_simulated / "study.yaml")


def test_every_analysis_section_is_in_both_schemas():
    from gaitval.pipeline.steps.config import ANALYSIS_SECTIONS

    schema = load_schema()
    for section in ANALYSIS_SECTIONS:
        assert section in schema["properties"], section
        assert section in schema["$defs"]["study_file"]["properties"], section


# -- typos ------------------------------------------------------------------------------
def test_top_level_typo(cfg):
    cfg["groundtruh"] = cfg.pop("groundtruth")
    msg = error_of(cfg)
    assert "config/config.yaml" in msg
    assert "unknown key groundtruh — did you mean groundtruth?" in msg


def test_numbers_nested_in_a_command_line_value_are_numbers():
    """Snakemake reads the scalars inside a --config mapping as strings (YAML BaseLoader);
    the workflow types them as a config file would (rollator={"pf_seed": 2018} -> 2018)."""
    from gaitval.configcheck import retype_command_line

    cli = {"rollator": {"pf_seed": "2018", "error_m": "0.1", "figure_trial": "rollator_P01"},
           "tracking": {"overrides": {"tug_m3": {"occlusion__max_n": "7", "x": ["1", "a"]}}},
           "mtst": {"poles_m": "null", "flag": "true", "label": "", "day": "2026-11-26"},
           "run": ["tiny"], "data_dir": "false"}
    out = retype_command_line(cli)
    assert out["rollator"] == {"pf_seed": 2018, "error_m": 0.1, "figure_trial": "rollator_P01"}
    assert out["tracking"]["overrides"]["tug_m3"] == {"occlusion__max_n": 7, "x": [1, "a"]}
    assert out["mtst"] == {"poles_m": None, "flag": True, "label": "", "day": "2026-11-26"}
    assert out["run"] == ["tiny"]
    assert out["data_dir"] == "false"         # top level: Snakemake's own parsing, checked
    assert cli["rollator"]["pf_seed"] == "2018"                        # input not modified


def test_nested_typo(cfg):
    cfg["groundtruth"]["lowpas_hz"] = 6
    msg = error_of(cfg)
    assert msg == ("[file config/config.yaml] unknown key groundtruth.lowpas_hz — did you "
                   "mean groundtruth.lowpass_hz?")


def test_deep_typo(cfg):
    cfg["ultrasonic"]["ukf"]["alpah"] = cfg["ultrasonic"]["ukf"].pop("alpha")
    assert "unknown key ultrasonic.ukf.alpah — did you mean ultrasonic.ukf.alpha?" in \
        error_of(cfg)


def test_key_in_the_wrong_section_points_to_its_section(cfg):
    cfg["lowpass_hz"] = 6
    assert "unknown key lowpass_hz — did you mean groundtruth.lowpass_hz?" in error_of(cfg)


def test_unlike_any_key_lists_the_valid_ones(cfg):
    cfg["evaluation"]["tug"] = {"zzz": 1}
    msg = error_of(cfg)
    assert "unknown key evaluation.tug.zzz (valid keys here: drift_max_m," in msg


def test_typo_in_a_config_defined_method_and_an_override(cfg):
    from gaitval.methods import METHODS

    m = copy.deepcopy(METHODS["tug_m3"])
    m["occlusoin"] = m.pop("occlusion")
    cfg["tracking"]["methods"]["my_m3"] = m
    assert "unknown key tracking.methods.my_m3.occlusoin — did you mean " \
           "tracking.methods.my_m3.occlusion?" in error_of(cfg)
    cfg["tracking"]["methods"] = {}
    cfg["tracking"]["overrides"] = {"tug_m3": {"occlusion_max_n": 10}}
    assert "bad key tracking.overrides.tug_m3.occlusion_max_n: an override is " \
           "<role>__<param>" in error_of(cfg)


def test_several_problems_in_one_message(cfg):
    cfg["groundtruth"]["lowpas_hz"] = 6
    cfg["registration"]["pole_diamter_m"] = 0.05
    msg = error_of(cfg)
    assert msg.startswith("[file config/config.yaml] unknown key groundtruth.lowpas_hz")
    assert "1 more: config/config.yaml: unknown key registration.pole_diamter_m — did you " \
           "mean registration.pole_diameter_m?" in msg


# -- types and values ---------------------------------------------------------------------
def test_wrong_type_names_path_and_type(cfg):
    cfg["groundtruth"]["lowpass_hz"] = "ten"
    assert "groundtruth.lowpass_hz must be a number, got 'ten' (str)" in error_of(cfg)
    cfg["groundtruth"]["lowpass_hz"] = 10.0
    cfg["ultrasonic"]["ukf"]["max_reject"] = 1.5
    assert "ultrasonic.ukf.max_reject must be an integer, got 1.5 (float)" in error_of(cfg)
    cfg["ultrasonic"]["ukf"]["max_reject"] = 2
    cfg["run"] = "tiny"
    assert "run must be a list, got 'tiny' (str)" in error_of(cfg)


def test_wrong_choice_suggests_one(cfg):
    cfg["groundtruth"]["leg_point"] = "cylnder"
    assert "groundtruth.leg_point must be one of auto, axis, cylinder, got 'cylnder' — " \
           "did you mean cylinder?" in error_of(cfg)


def test_study_entry_needs_sheet_or_simulate(cfg):
    cfg["studies"]["lab"] = {"trial_sheet": "t.csv"}
    assert "studies.lab: a real study needs trial_sheet and subjects" in error_of(cfg)


# -- which file --------------------------------------------------------------------------
def test_problem_names_the_layer_that_set_the_key(cfg):
    typo = {"groundtruth": {"lowpas_hz": 6}}
    merged = copy.deepcopy(cfg)
    merged["groundtruth"].update(typo["groundtruth"])
    base = ("config/config.yaml", cfg)
    assert error_of(merged, [base, ("--config", typo)]).startswith(
        "--config: unknown key groundtruth.lowpas_hz")
    assert error_of(merged, [base, ("/tmp/mine.yaml", typo), ("--config", {})]).startswith(
        "[file /tmp/mine.yaml] unknown key groundtruth.lowpas_hz")


def test_study_yaml_typo_names_the_study_yaml(cfg, tmp_path):
    from gaitval.pipeline.steps.config import study_config

    (tmp_path / "study.yaml").write_text("registration:\n  pole_diamter_m: 0.06\n")
    with pytest.raises(ConfigError) as exc:
        study_config(cfg, tmp_path / "trials.csv", tmp_path / "config.json")
    msg = str(exc.value)
    assert str(tmp_path / "study.yaml") in msg
    assert "unknown key registration.pole_diamter_m — did you mean " \
           "registration.pole_diameter_m?" in msg
    assert not (tmp_path / "config.json").exists()
    (tmp_path / "study.yaml").write_text("registraton:\n  pole_diameter_m: 0.06\n")
    with pytest.raises(ConfigError, match="unknown key registraton — did you mean "
                                          "registration?"):
        study_config(cfg, tmp_path / "trials.csv", tmp_path / "config.json")
    (tmp_path / "study.yaml").write_text("study: lab\nregistration: {pole_diameter_m: 0.06}\n")
    out = study_config(cfg, tmp_path / "trials.csv", tmp_path / "config.json")
    assert out["registration"]["pole_diameter_m"] == 0.06


def dry_run(*args: str) -> subprocess.CompletedProcess:
    snakemake = Path(sys.executable).parent / "snakemake"
    cmd = [str(snakemake), "--snakefile", str(ROOT / "Snakefile"), "-n", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=ROOT)


def test_override_keys_are_checked_against_the_methods_parameters():
    """Issue 35: a typo'd override names the key and the nearest valid one."""
    from gaitval.methods import METHODS
    from gaitval.overrides import check_overrides, override_problems

    defs = {m: m for m in METHODS}
    ok = {"tug_m3": {"occlusion__max_n": 10, "gate__g": 9.21, "tracker__dt_s": 0.025,
                     "detector__background": {"name": "percentile", "q": 90.0}},
          "rollator_pf": {"kind__n_particles": 100},
          "tug_m1": {"occlusion__name": "catmull_rom", "occlusion__max_n": 5}}
    assert override_problems(ok, defs) == []
    msgs = [p.message for p in override_problems(
        {"tug_m3": {"occlusion__maxn": 10, "occlusoin__max_n": 1, "tracker__dt": 0.1,
                    "occlusion__name": "catmul_rom"},
         "tug_m33": {"gate__g": 1}, "tug_m1": {"occlusion__max_n": 5}}, defs)]
    text = "\n".join(msgs)
    assert ("tracking.overrides.tug_m33: no method 'tug_m33' — did you mean "
            "tracking.overrides.tug_m3?") in text
    assert "tug_m3 has no role 'occlusoin' — did you mean occlusion__max_n?" in text
    assert "tracker__dt: the tracker loop of tug_m3 has no parameter 'dt' — did you " \
           "mean tracker__dt_s?" in text
    assert "no occlusion handler 'catmul_rom' — did you mean catmull_rom?" in text
    # tug_m1's occlusion handler (predict only) has no max_n
    assert "tug_m1.occlusion__max_n: the occlusion handler 'predict_only' of tug_m1 " \
           "has no parameter 'max_n'" in text
    with pytest.raises(ConfigError, match="did you mean occlusion__max_n"):
        check_overrides({"tug_m3": {"occlusion__maxn": 10}}, defs)


@pytest.mark.slow
def test_a_typo_in_an_override_or_run_stops_the_dry_run_with_the_message_only():
    res = dry_run("--config", 'run=["tiny"]',
                  'tracking={"overrides": {"tug_m3": {"occlusion__maxn": 10}}}')
    assert res.returncode != 0
    assert ("--config: tracking.overrides.tug_m3.occlusion__maxn: the occlusion handler "
            "'catmull_rom' of tug_m3 has no parameter 'maxn' — did you mean "
            "occlusion__max_n?") in res.stderr
    res2 = dry_run("--config", 'run=["tinyy"]')
    assert res2.returncode != 0
    assert "--config: run[0]: no study 'tinyy' under studies: — did you mean tiny?" \
        in res2.stderr
    for r in (res, res2):
        assert "Traceback" not in r.stderr and "File \"" not in r.stderr
        assert "Exception" not in r.stderr


@pytest.mark.slow
def test_snakemake_stops_with_the_message_only(tmp_path):
    res = dry_run("--config", 'run=["tiny"]', 'groundtruth={"lowpas_hz": 6}')
    assert res.returncode != 0
    assert "--config: unknown key groundtruth.lowpas_hz — did you mean " \
           "groundtruth.lowpass_hz?" in res.stderr
    assert "Traceback" not in res.stderr and "File \"" not in res.stderr
    # a real study's study.yaml is checked before any job runs
    (tmp_path / "study.yaml").write_text("registration: {pole_diamter_m: 0.06}\n")
    lab = {"studies": {"lab": {"trial_sheet": str(tmp_path / "trials.csv"),
                               "subjects": str(tmp_path / "subjects.csv")}}, "run": ["lab"]}
    (tmp_path / "lab.yaml").write_text(yaml.safe_dump(lab))
    res = dry_run("--configfile", str(tmp_path / "lab.yaml"))
    assert res.returncode != 0
    assert f"[file {tmp_path / 'study.yaml'}] unknown key registration.pole_diamter_m" \
        in res.stderr


# -- every key the code reads validates, with the code's defaults ------------------------
def schema_defaults(node: dict, schema: dict) -> dict:
    if "$ref" in node:
        node = {**schema["$defs"][node["$ref"].rsplit("/", 1)[-1]], **node}
    out = {}
    for k, sub in (node.get("properties") or {}).items():
        if "properties" in sub or "$ref" in sub and "default" not in sub:
            out[k] = schema_defaults(sub, schema)
        elif "default" in sub:
            out[k] = sub["default"]
    return out


def test_code_defaults_validate_and_match_the_schema(cfg):
    from gaitval.evaluate.tug_truth import DEFAULTS as TUG
    from gaitval.groundtruth.build import DEFAULTS as GT
    from gaitval.registration import clock, poles, trial

    reg = {**trial.DEFAULTS, **poles.DEFAULTS, **clock.DEFAULTS}
    schema = load_schema()
    defaults = schema_defaults(schema, schema)
    assert {k: defaults["registration"][k] for k in reg} == reg
    assert {k: defaults["groundtruth"][k] for k in GT} == GT
    assert defaults["evaluation"]["tug"] == TUG
    cfg["registration"].update(reg)
    cfg["groundtruth"].update(GT)
    cfg["evaluation"]["tug"] = dict(TUG)
    check_config(cfg)


def test_ultrasonic_defaults_validate_and_match_the_schema(cfg):
    from gaitval.evaluate.ultrasonic_config import DEFAULT_CFG as us

    schema = load_schema()
    want = schema_defaults(schema, schema)["ultrasonic"]
    assert {k: want[k] for k in us} == us
    cfg["ultrasonic"] = copy.deepcopy(us)
    check_config(cfg)


def test_builtin_methods_validate_and_roles_match():
    from gaitval.methods import METHODS, ROLES
    from gaitval.track.tracker import Tracker

    schema = load_schema()
    method = schema["$defs"]["method"]["properties"]
    assert set(ROLES) <= set(method)
    params = set(inspect.signature(Tracker.__init__).parameters) - set(ROLES) - {"self"}
    assert set(method["tracker"]["properties"]) == params
    cfg = {"studies": {}, "run": ["x"], "tracking": {"methods": copy.deepcopy(METHODS)}}
    check_config(cfg)


# -- Table 2 shows the methods actually run ----------------------------------------------
def my_m3() -> dict:
    from gaitval.methods import METHODS

    m = copy.deepcopy(METHODS["tug_m3"])
    m["label"] = "my Method 3"
    m["gate"] = {"name": "chi2", "g": 9.21}
    return m


def g_of(t2: pd.DataFrame, method: str) -> str:
    return t2[(t2.symbol == "G") & (t2.method == method)].iloc[0]["value"]


def study_results(root: Path, study: str, cfg: dict, methods) -> list[Path]:
    """A results/<study>/ tree as the workflow leaves it: config.json and one evaluation
    folder per method."""
    from gaitval.evaluate.tug import FRAME_COLUMNS

    (root / study).mkdir(parents=True)
    (root / study / "config.json").write_text(json.dumps(cfg))
    dirs = []
    for m in methods:
        d = root / study / "evaluate" / m / "t1"
        d.mkdir(parents=True)
        pd.DataFrame(columns=list(FRAME_COLUMNS)).to_parquet(d / "frames.parquet")
        pd.DataFrame([{"trial": "t1", "method": m, "success": True,
                       "category": "success"}]).to_parquet(d / "summary.parquet")
        pd.DataFrame(columns=["trial", "method", "side", "kind", "t_start_s", "t_end_s",
                              "tug_phase"]).to_parquet(d / "events.parquet")
        dirs.append(d)
    return dirs


@pytest.fixture
def table2_of(monkeypatch, tmp_path):
    """Run tug_tables_step; return Table 2 built from the definitions it passed on."""
    import gaitval.report.tug_figures as figures
    import gaitval.tables.tug as tables
    from gaitval.pipeline.steps.tug import tug_tables_step

    seen = {}

    def spy(frames, summaries, out_dir, *, methods, dt_measured_s=None):
        seen["methods"] = methods
        return []

    monkeypatch.setattr(tables, "write_tug_tables", spy)
    monkeypatch.setattr(figures, "write_tug_figures", lambda *a, **k: [])

    def run(dirs, methods, configs=None):
        tug_tables_step(dirs, tmp_path / "t", tmp_path / "f", tmp_path / "r",
                        methods=methods, configs=configs)
        return tables.tug_table2(seen["methods"])
    return run


def test_table2_config_only_method(tmp_path, table2_of):
    from gaitval.tables.tug import tug_table2

    with pytest.raises(ConfigError):         # what the table did before: built-ins only
        tug_table2(["my_m3"])
    cfg = {"tracking": {"methods": {"my_m3": my_m3()}, "overrides": {}}}
    t2 = table2_of(study_results(tmp_path / "res", "s", cfg, ["tug_m1", "my_m3"]),
                   ["tug_m1", "my_m3"])
    assert g_of(t2, "my_m3") == "9.21" and g_of(t2, "tug_m1") == "13.82"
    nbo = t2[t2.symbol == "N_bo"].set_index("method")["value"]
    assert nbo["my_m3"] == "match"


def test_table2_shows_overrides(tmp_path, table2_of):
    cfg = {"tracking": {"methods": {"my_m3": my_m3()},
                        "overrides": {"my_m3": {"gate__g": 5.99},
                                      "tug_m3": {"occlusion__n_bo": 5,
                                                 "filter__r_sd_m": 0.03}}}}
    t2 = table2_of(study_results(tmp_path / "res", "s", cfg, ["tug_m3", "my_m3"]),
                   ["tug_m3", "my_m3"])
    v = t2.set_index(["method", "symbol"])["value"]
    # a built-in method run with overrides is named with them (issue 35); a config-defined
    # method is its own definition
    m3 = "tug_m3 (filter.r_sd_m = 0.03, occlusion.n_bo = 5)"
    assert list(dict.fromkeys(t2.method)) == [m3, "my_m3"]
    assert v["my_m3", "G"] == "5.99" and v[m3, "G"] == "13.82"
    assert v[m3, "N_bo"] == "5" and v[m3, "N_ao"] == "match"
    assert v[m3, "√R"] == "0.03" and v["my_m3", "√R"] == "0.04"
    pub = t2.set_index(["method", "symbol"])["value_published"]
    assert pub[m3, "√R"] == "0.04"                    # the paper's value beside the run one


def test_table2_has_a_row_for_an_overridden_parameter_it_does_not_list(tmp_path, table2_of):
    """Issue 35: occlusion.max_n is no row of Table 2; overridden, it gets one."""
    cfg = {"tracking": {"overrides": {"tug_m3": {"occlusion__max_n": 10}}}}
    t2 = table2_of(study_results(tmp_path / "res", "s", cfg, ["tug_m1", "tug_m3"]),
                   ["tug_m1", "tug_m3"])
    m3 = "tug_m3 (occlusion.max_n = 10)"
    assert list(dict.fromkeys(t2.method)) == ["tug_m1", m3]
    row = t2[t2.parameter.str.startswith("occlusion.max_n")]
    assert list(row.method) == [m3] and list(row.value) == ["10"]
    assert row.parameter.iloc[0] == "occlusion.max_n (changed; built in: 20)"


def test_a_modified_method_is_named_with_its_changes_in_every_tug_table(tmp_path):
    from gaitval.evaluate.tug import FRAME_COLUMNS
    from gaitval.methods import get_method, set_params
    from gaitval.tables.tug import write_tug_tables

    frames = pd.DataFrame(columns=list(FRAME_COLUMNS))
    summaries = pd.DataFrame([{"trial": "t1", "method": m, "success": False,
                               "category": "false_tracking_turning"}
                              for m in ("tug_m1", "tug_m3")])
    defs = {"tug_m1": get_method("tug_m1"),
            "tug_m3": set_params(get_method("tug_m3"), {"occlusion__max_n": 10})}
    write_tug_tables(frames, summaries, tmp_path, methods=defs)
    for name in ("tug_table2", "tug_table3", "tug_table4", "tug_table5"):
        t = pd.read_csv(tmp_path / f"{name}.csv")
        shown = set(t["method"].dropna())
        assert "tug_m3 (occlusion.max_n = 10)" in shown, (name, shown)
        assert "tug_m3" not in shown and "tug_m1" in shown, (name, shown)


def test_table2_without_config_changes_is_the_builtin_table(tmp_path, table2_of):
    from gaitval.tables.tug import tug_table2

    names = ["tug_m1", "tug_m2", "tug_m3"]
    cfg = {"tracking": {"methods": {}, "overrides": {}}}
    t2 = table2_of(study_results(tmp_path / "res", "s", cfg, names), names)
    assert t2.equals(tug_table2(names))


def test_table2_studies_that_ran_a_method_differently(tmp_path, table2_of):
    a = {"tracking": {"overrides": {"tug_m3": {"gate__g": 9.21}}}}
    b = {"tracking": {"overrides": {}}}
    dirs = (study_results(tmp_path / "res", "a", a, ["tug_m1", "tug_m3"])
            + study_results(tmp_path / "res", "b", b, ["tug_m1", "tug_m3"]))
    t2 = table2_of(dirs, ["tug_m1", "tug_m3"])
    a3 = "tug_m3 (a) (gate.g = 9.21)"
    assert list(dict.fromkeys(t2.method)) == ["tug_m1", a3, "tug_m3 (b)"]
    assert g_of(t2, a3) == "9.21" and g_of(t2, "tug_m3 (b)") == "13.82"


def test_table2_from_the_method_views_is_the_table_from_config_json(tmp_path, table2_of):
    """The workflow hands tug_tables each study's method views (config_views/tug/<method>.json,
    one method's definition and override each), not config.json, so that another section's
    change does not rerun the table (issue 13): Table 2 is the same, studies still apart."""
    from gaitval.pipeline.steps.config import method_view

    a = {"registration": {"sync_bin_deg": 0.5},
         "tracking": {"methods": {"my_m3": my_m3()},
                      "overrides": {"my_m3": {"gate__g": 5.99}, "tug_m3": {"occlusion__n_bo": 5}}}}
    b = {"tracking": {"methods": {"my_m3": my_m3()}, "overrides": {}}}
    names = ["tug_m3", "my_m3"]
    res = tmp_path / "res"
    dirs = study_results(res, "a", a, names) + study_results(res, "b", b, names)
    whole = table2_of(dirs, names)
    views = []
    for study, cfg in (("a", a), ("b", b)):
        (res / study / "config_views" / "tug").mkdir(parents=True)
        for m in names:
            views.append(res / study / "config_views" / "tug" / f"{m}.json")
            views[-1].write_text(json.dumps(method_view(cfg, m, "tug")))
    from_views = table2_of(dirs, names, configs=views)
    assert from_views.equals(whole)
    assert {"tug_m3 (a) (occlusion.n_bo = 5)", "tug_m3 (b)", "my_m3 (a)", "my_m3 (b)"} \
        <= set(from_views.method)


def test_tug_tables_verb_hands_the_configs_it_is_given_to_the_step(monkeypatch):
    """The workflow gives `gaitval tug-tables` the method views with --configs: a run that
    asks for the TUG tables only has no config.json to fall back on (test_resume)."""
    import gaitval.pipeline.steps.tug as steps
    from gaitval.cli import main

    seen = {}
    monkeypatch.setattr(steps, "tug_tables_step",
                        lambda *a, **k: seen.update(k) or [])
    assert main(["tug-tables", "e1", "--tables-dir", "t", "--figures-dir", "f",
                 "--configs", "v/tug_m1.json", "v/tug_m2.json"]) == 0
    assert seen["configs"] == ["v/tug_m1.json", "v/tug_m2.json"]
    assert main(["tug-tables", "e1", "--tables-dir", "t", "--figures-dir", "f"]) == 0
    assert seen["configs"] is None                                # config.json convention


def test_tables_steps_name_a_method_with_its_overrides_from_its_view(tmp_path):
    """Issue 35: the MTST tables step reads each method's view beside its study view."""
    from gaitval.pipeline.steps.config import method_display_names, method_view

    cfg = {"tracking": {"methods": {}, "overrides": {"mtst_m3": {"gate__radius_leg_widths": 1.2}}}}
    for m in ("mtst_m1", "mtst_m3"):
        (tmp_path / f"{m}.json").write_text(json.dumps(method_view(cfg, m, "mtst")))
    assert method_display_names(tmp_path, ["mtst_m1", "mtst_m3", "mtst_proposed"]) == {
        "mtst_m1": "mtst_m1", "mtst_m3": "mtst_m3 (gate.radius_leg_widths = 1.2)"}


def test_a_modified_rollator_method_is_named_in_a_note_of_every_rollator_table(
        tmp_path, monkeypatch):
    """Issue 35: the rollator tables keep their _kf/_pf columns; a note names a KF or PF
    run with overrides (the table bodies are stubbed: only the notes are under test)."""
    import gaitval.tables.rollator as rollator
    import gaitval.tables.rollator_notes as notes

    one = pd.DataFrame({"scenario": ["straight"], "rmse_kf": [0.01]})
    for name in ("rollator_table1", "rollator_table2"):
        monkeypatch.setattr(rollator, name, lambda *a, **k: one)
    monkeypatch.setattr(rollator, "improvement", lambda t1: one)
    monkeypatch.setattr(notes, "table1_notes", lambda *a, **k: [])
    monkeypatch.setattr(notes, "table2_notes", lambda *a, **k: [])
    paths = rollator.write_rollator_tables(
        pd.DataFrame(), pd.DataFrame(), tmp_path, kf="rollator_kf", pf="rollator_pf",
        shown={"rollator_kf": "rollator_kf (filter.r_sd_m = 0.03)",
               "rollator_pf": "rollator_pf"})
    mds = [p for p in paths if p.suffix == ".md"]
    assert len(mds) == 3
    for p in mds:
        text = p.read_text()
        assert "KF ran as rollator_kf (filter.r_sd_m = 0.03)" in text, p.name
        assert "PF ran as" not in text
    plain = rollator.write_rollator_tables(pd.DataFrame(), pd.DataFrame(), tmp_path / "b",
                                           kf="rollator_kf", pf="rollator_pf")
    assert not any("KF ran as" in p.read_text() for p in plain if p.suffix == ".md")
