"""The study's analysis config, the view of it each job reads, and the method definitions
those views resolve.

Per-study configuration (``results/<study>/config.json``) is the workflow config's
analysis sections merged with the study's own calibration file ``study.yaml`` beside
the trial sheet (pole diameter, the sensor mount on the rollator, ...): a calibration
belongs to the study, not to gaitval.
"""
from __future__ import annotations

import json
from pathlib import Path

import yaml

from gaitval.config import deep_merge
from gaitval.errors import ConfigError
from gaitval.io.atomic import write_text
from gaitval.pipeline.steps.declarations import study_external


#: Config sections that parameterise the analysis (copied into the per-study config).
ANALYSIS_SECTIONS = ("registration", "groundtruth", "rollator", "tracking", "tug",
                     "ultrasonic", "evaluation", "mtst")


STUDY_VIEW = "study"

#: the sections of one protocol family's own settings: a job of one family reads its own
#: and the shared sections (registration, groundtruth, tracking, evaluation), never another
#: family's (a view's scope, :func:`method_view`)
SCOPES = ("tug", "mtst", "rollator", "ultrasonic")
ALL_SCOPE = "all"
#: trial-sheet protocol -> scope of its jobs' views (another protocol: ALL_SCOPE)
PROTOCOL_SCOPE = {"tug": "tug", "mtst": "mtst", "rollator": "rollator",
                  "treadmill": "ultrasonic", "pendulum": "ultrasonic"}


def method_view(cfg: dict, view: str, scope: str = ALL_SCOPE) -> dict:
    """``cfg`` as the jobs of one method and protocol family read it: ``tracking.methods``
    and ``tracking.overrides`` reduced to method ``view``'s entries, or to none for
    ``view == STUDY_VIEW`` (the jobs without a method: registration, ultrasonic, ...), and,
    for a ``scope`` in :data:`SCOPES`, the other families' sections left out (``all``: none
    left out).  Every other key is kept.  A job looks up no other method's definition (it
    calls :func:`method_definition` with its own method) and no other family's section, so
    its results depend on this view only; the workflow reruns a method's jobs when its view
    changes, not on any change of another method or family (``workflow/rules/register.smk``,
    rule ``config_view``)."""
    if scope != ALL_SCOPE and scope not in SCOPES:
        raise ConfigError(f"unknown config view scope {scope!r} (one of {SCOPES + (ALL_SCOPE,)})")
    out = {k: v for k, v in cfg.items()
           if scope == ALL_SCOPE or k not in SCOPES or k == scope}
    tracking = dict(out.get("tracking") or {})
    for key in ("methods", "overrides", "external"):
        entries = tracking.get(key) or {}
        if key == "external" and view not in entries:
            tracking.pop(key, None)   # declaring an external method changes no other view
            continue
        tracking[key] = {view: entries[view]} if view in entries else {}
    out["tracking"] = tracking
    return out


def analysis_config(config: dict, sheet: str | Path, *, check: bool = False) -> dict:
    """A study's analysis config: the workflow config's :data:`ANALYSIS_SECTIONS`, with
    ``study.yaml`` beside the trial sheet, when present, merged over them (``check``:
    checked against the config schema first, :func:`gaitval.configcheck.check_study_file`)."""
    from gaitval.configcheck import check_study_file

    cfg = {k: config[k] for k in ANALYSIS_SECTIONS if k in config}
    cal = Path(sheet).parent / "study.yaml"
    if cal.is_file():
        with open(cal, encoding="utf-8") as fh:
            study = yaml.safe_load(fh) or {}
        if check:
            check_study_file(study, cal)
        cfg = deep_merge(cfg, {k: v for k, v in study.items() if k in ANALYSIS_SECTIONS})
        cfg["calibration_file"] = str(cal)
    own = study_external(sheet)     # the study's own external methods (issue 37): its
    if own:                         # study.yaml's and external.yaml's
        tracking = cfg.setdefault("tracking", {})
        tracking["external"] = {**(tracking.get("external") or {}), **own}
    return cfg


def study_config(config: dict, sheet: str | Path, out: str | Path,
                 view: str | None = None, scope: str = ALL_SCOPE) -> dict:
    """Write the effective analysis config of one study (JSON) and return it.

    The workflow config's :data:`ANALYSIS_SECTIONS` are the base; ``study.yaml`` beside the
    trial sheet, when present, overrides them (the study's calibration); it is checked
    against the config schema first, so a typo in it stops with the file and key named
    (:func:`gaitval.configcheck.check_study_file`).  With ``view`` (a method name or
    :data:`STUDY_VIEW`), only that view of it, in ``scope``, is written
    (:func:`method_view`).
    """
    cfg = analysis_config(config, sheet, check=True)
    if view is not None:
        cfg = method_view(cfg, view, scope)
    write_text(out, json.dumps(cfg, indent=1, sort_keys=True) + "\n")
    return cfg


def load_json(path: str | Path) -> dict:
    return json.loads(Path(path).read_text(encoding="utf-8"))


def method_display_names(view_dir: str | Path, methods) -> dict[str, str]:
    """method -> its name in the tables (``tug_m3 (occlusion.max_n = 10)`` when run with
    overrides), from the method views ``<view_dir>/<method>.json`` beside a tables step's
    study view (the views its tracks ran with); a method without a view keeps its name."""
    from gaitval.methods import display_name

    out = {}
    for m in methods:
        d = _resolved_method(view_dir, m)
        if d is not None:
            out[m] = display_name(m, d)
    return out


def offline_methods(view_dir: str | Path | None, methods) -> set[str]:
    """The methods that report a scan using scans recorded after it (issue 36:
    ``people_offline``), judged on the definitions the tracks ran with (the method views in
    ``view_dir``; a method without a view: its built-in definition, if there is one)."""
    from gaitval.methods import METHODS, get_method, reads_later_scans

    out = set()
    for m in methods:
        d = _resolved_method(view_dir, m) if view_dir else None
        if d is None and m in METHODS:
            d = get_method(m)
        if d is not None and reads_later_scans(d):
            out.add(m)
    return out


def _resolved_method(view_dir: str | Path, m: str) -> dict | None:
    """Method ``m``'s definition as its view ``<view_dir>/<m>.json`` resolves it
    (``tracking.methods`` and ``tracking.overrides``); None without a view, or for an
    external method (issue 37)."""
    from gaitval.methods import get_method, set_params

    p = Path(view_dir) / f"{m}.json"
    if not p.is_file():
        return None
    cfg = load_json(p)
    if m in ((cfg.get("tracking") or {}).get("external") or {}):
        return None
    return set_params(get_method(method_definition(cfg, m)), method_overrides(cfg, m))


def method_definition(cfg: dict, method: str):
    """A method's definition: ``tracking.methods.<name>`` from config, else the built-in."""
    custom = (cfg.get("tracking") or {}).get("methods") or {}
    return custom.get(method, method)


def method_overrides(cfg: dict, method: str) -> dict:
    """The user's ``tracking.overrides.<name>`` (``role__param: value``), a new dict, empty
    when there are none."""
    return dict(((cfg.get("tracking") or {}).get("overrides") or {}).get(method) or {})
