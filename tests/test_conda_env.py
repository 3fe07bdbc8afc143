"""workflow/envs/gaitval.yaml, the software environment every rule declares (``conda:``),
holds gaitval's direct dependencies at the versions requirements.lock pins, and gaitval
itself from the checkout: a conda run computes with what the tests ran with."""
from __future__ import annotations

import re
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def _name(requirement: str) -> str:
    return re.split(r"[<>=!~;\[ ]", requirement.strip(), maxsplit=1)[0].lower().replace("_", "-")


def test_the_rules_environment_pins_every_dependency_at_its_locked_version():
    import tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    lock = dict(re.findall(r"^([A-Za-z0-9_.\-]+)==(\S+)", (ROOT / "requirements.lock")
                           .read_text(), re.M))
    lock = {k.lower().replace("_", "-"): v for k, v in lock.items()}
    env = yaml.safe_load((ROOT / "workflow" / "envs" / "gaitval.yaml").read_text())
    pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
    pinned = dict(p.lower().split("==") for p in pip if "==" in p)
    wanted = {_name(d): lock[_name(d)] for d in deps}
    assert pinned == wanted
    assert "-e ../.." in pip                     # gaitval itself, from this checkout


def test_every_shell_rule_declares_the_environment():
    for path in sorted((ROOT / "workflow" / "rules").glob("*.smk")):
        text = path.read_text()
        shells = text.count("\n    shell:\n")
        assert text.count("\n    conda:\n        CONDA_ENV\n") == shells, path.name
