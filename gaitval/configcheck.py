"""Check a workflow config or a study's ``study.yaml`` against the config schema.

The schema (``workflow/schemas/config.schema.yaml``) describes every section and key and
refuses unknown ones.  A problem is raised as one :class:`~gaitval.errors.ConfigError`
that names the file the key came from, the key's full path and, for a typo, the nearest
valid key::

    [file config/config.yaml] unknown key groundtruth.lowpas_hz — did you mean
    groundtruth.lowpass_hz?

Only jsonschema and PyYAML are imported: the Snakefile calls this at parse time.
"""
from __future__ import annotations

import difflib
import functools
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import jsonschema
import yaml

from gaitval.errors import ConfigError

#: The config schema, found beside the package in the repository (the workflow's copy).
SCHEMA_PATH = (Path(__file__).resolve().parents[1] / "workflow" / "schemas"
               / "config.schema.yaml")

_TYPE_NAMES = {"number": "a number", "integer": "an integer", "string": "a string",
               "boolean": "true or false", "array": "a list", "object": "a mapping",
               "null": "null"}


@dataclass(frozen=True)
class Problem:
    """One schema violation: where (key path) and what, in words."""

    path: tuple
    message: str
    source: str = ""


#: An id (study, subject, trial) names a folder (``results/<study>/ingest/<trial>/``), a
#: word of a job's command line and part of a Snakemake file pattern.
ID_MAX_LEN = 128
_ID_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_.-")


def id_problem(value: str) -> str | None:
    """Why ``value`` cannot be an id (study, subject, trial), or None.

    Ids name folders (``results/<study>/ingest/<trial>/``) and are words of the verbs'
    command lines: letters, digits and ``_ . -`` only (no braces, which Snakemake reads
    as a wildcard), at most 128 characters, not starting with ``-`` (every verb would
    read it as an option), and neither ``.`` nor ``..`` (they would name the folder
    itself or its parent)."""
    if not value:
        return "is empty"
    if len(value) > ID_MAX_LEN:
        return f"is {len(value)} characters long (at most {ID_MAX_LEN})"
    if value in (".", ".."):
        return f"{value!r} names a folder's own or parent folder"
    bad = sorted(set(value) - _ID_CHARS)
    if bad:
        shown = ", ".join(repr(c) for c in bad[:5])
        return f"has the character(s) {shown}; ids use letters, digits and _ . - only"
    if value.startswith("-"):
        return "starts with '-' (a command line would read it as an option)"
    return None


def path_value_problem(value: str, *, strict: bool = False) -> str | None:
    """Why ``value`` cannot be a folder or file path the workflow forms file patterns
    from (a trial sheet's file, ``data_dir``, ``results_dir``, ``reports_dir``), or None:
    no braces (Snakemake would read ``{...}`` as a wildcard), no control characters, and,
    ``strict``: every part of the path an id (:func:`id_problem`; ``..`` and a leading
    ``/`` allowed), for the folders gaitval writes into."""
    text = str(value)
    if not text.strip():
        return "is empty"
    if "{" in text or "}" in text:
        return "holds a brace ('{' or '}'), which Snakemake reads as a wildcard"
    ctl = sorted({repr(ch) for ch in text if ord(ch) < 32 or ord(ch) == 127})
    if ctl:
        return f"holds control character(s) {', '.join(ctl)}"
    if strict:
        for part in text.split("/"):
            if part in ("", "..", "."):
                continue
            why = id_problem(part)
            if why:
                return f"has the folder name {part[:40]!r} that {why}"
    return None


@functools.lru_cache(maxsize=4)
def _load_schema(path: str) -> dict:
    p = Path(path)
    if not p.is_file():
        raise ConfigError("the config schema is missing", path=p,
                          hint="gaitval checks configs against the repository's "
                               "workflow/schemas/config.schema.yaml")
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)                       # libyaml
    with open(p, encoding="utf-8") as fh:
        schema = yaml.load(fh, Loader=loader)
    # the $defs kept in sibling files (the protocols' sections), merged in the named order
    for name in schema.pop("x-defs-files", ()):
        with open(p.parent / name, encoding="utf-8") as fh:
            schema.setdefault("$defs", {}).update(yaml.load(fh, Loader=loader)["$defs"])
    return schema


def load_schema(path: str | Path | None = None) -> dict:
    """The config schema (cached; do not modify it)."""
    return _load_schema(str(path or SCHEMA_PATH))


def dotted(path: Sequence) -> str:
    """``("groundtruth", "lowpass_hz")`` -> ``groundtruth.lowpass_hz``; ``run[0]``."""
    out = ""
    for k in path:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else str(k))
    return out or "(top level)"


def _key_paths(schema: dict, root: dict, prefix=(), depth=0) -> list[tuple]:
    """Every fixed key path the schema describes (following local ``$ref``)."""
    if depth > 8 or not isinstance(schema, dict):
        return []
    if "$ref" in schema:
        name = schema["$ref"].rsplit("/", 1)[-1]
        schema = {**root.get("$defs", {}).get(name, {}), **schema}
    out = []
    for k, sub in (schema.get("properties") or {}).items():
        out.append(prefix + (k,))
        out += _key_paths(sub, root, prefix + (k,), depth + 1)
    return out


def _suggest(key: str, parent: tuple, here: list[str], root: dict) -> str:
    close = difflib.get_close_matches(key, here, n=1, cutoff=0.6)
    if close:
        return f" — did you mean {dotted(parent + (close[0],))}?"
    elsewhere = [p for p in _key_paths(root, root) if p[-1] == key]
    if elsewhere and tuple(elsewhere[0]) == tuple(parent) + (key,):
        # the same key at the same place of the workflow config: valid there, not here
        # (reports_dir in a study.yaml)
        return (f" — {dotted(elsewhere[0])} is a key of the workflow config "
                "(config/config.yaml, a --configfile or --config), not of this file")
    if elsewhere:
        return f" — did you mean {dotted(elsewhere[0])}?"
    return f" (valid keys here: {', '.join(sorted(here))})" if here else ""


def _at(instance: Any, path: Sequence) -> Any:
    for k in path:
        instance = instance[k]
    return instance


def _describe(value: Any) -> str:
    return f"{value!r} ({type(value).__name__})"


def _problems_of(error: jsonschema.ValidationError, instance: Any, root: dict
                 ) -> list[Problem]:
    """One error of jsonschema -> the problems to report, in words."""
    path = tuple(error.absolute_path)
    where, v, s = dotted(path), error.validator, error.schema
    if v == "additionalProperties":
        here = list(s.get("properties") or {})
        extra = [k for k in error.instance if k not in here]
        return [Problem(path + (k,), f"unknown key {dotted(path + (k,))}"
                        f"{_suggest(str(k), path, here, root)}") for k in extra]
    if v == "type":
        want = error.validator_value
        want = [want] if isinstance(want, str) else list(want)
        hint = ""
        if "boolean" in want and isinstance(error.instance, str) and \
                error.instance.strip().lower() in ("true", "false", "yes", "no", "on", "off"):
            hint = (" (on Snakemake's command line write True or False: "
                    f"--config {where}=False)")
        return [Problem(path, f"{where} must be {' or '.join(_TYPE_NAMES[t] for t in want)}"
                              f", got {_describe(error.instance)}{hint}")]
    if v == "enum":
        choices = [str(c) for c in error.validator_value]
        close = difflib.get_close_matches(str(error.instance), choices, n=1)
        tip = f" — did you mean {close[0]}?" if close else ""
        return [Problem(path, f"{where} must be one of {', '.join(choices)}, got "
                              f"{error.instance!r}{tip}")]
    if v == "required":
        missing = [k for k in error.validator_value if k not in error.instance]
        return [Problem(path, f"{where} is missing the key(s) {', '.join(missing)}")]
    if v == "pattern":
        parent = _at(instance, path)
        if isinstance(parent, dict) and error.instance in parent:    # via propertyNames
            key = path + (error.instance,)
            return [Problem(key, f"bad key {dotted(key)}: {s.get('description', '')}")]
        if s.get("description"):                 # a value: say what it must be
            return [Problem(path, f"{where}: {error.instance!r} is not {s['description']}")]
    if v in ("anyOf", "oneOf") and s.get("description"):
        return [Problem(path, f"{where}: {s['description']}")]
    return [Problem(path, f"{where}: {error.message}")]


def find_problems(instance: Any, schema: dict, root: dict | None = None) -> list[Problem]:
    """Every problem of ``instance`` against ``schema``, sorted by key path.

    ``root`` is the document holding ``$defs`` when ``schema`` is one of them.
    """
    root = root or schema
    full = schema if schema is root else {**schema, "$defs": root.get("$defs", {})}
    validator = jsonschema.Draft202012Validator(full)
    out = []
    for err in validator.iter_errors(instance):
        out += _problems_of(err, instance, root)
    # unknown / malformed keys first: a typo is usually the cause of the other problems
    typo = ("unknown key", "bad key")
    return sorted(set(out), key=lambda p: (not p.message.startswith(typo),
                                           [str(k) for k in p.path], p.message))


def _has_path(layer: Any, path: Sequence) -> bool:
    for k in path:
        if isinstance(layer, Mapping) and k in layer:
            layer = layer[k]
        elif isinstance(layer, list) and isinstance(k, int) and k < len(layer):
            layer = layer[k]
        else:
            return False
    return True


def _source(path: tuple, layers: Sequence[tuple[str, Any]]) -> str:
    """The highest-precedence layer that sets ``path`` (else the lowest layer)."""
    for name, layer in reversed(layers):
        if _has_path(layer, path):
            return name
    return layers[0][0] if layers else ""


def raise_problems(problems: list[Problem]) -> None:
    """Raise the first problem as a :class:`ConfigError`; the rest in its hint."""
    if not problems:
        return
    first, rest = problems[0], problems[1:]
    hint = None
    if rest:
        more = "; ".join(f"{p.source}: {p.message}" if p.source else p.message
                         for p in rest[:5])
        hint = f"{len(rest)} more: {more}" + ("; ..." if len(rest) > 5 else "")
    if first.source.startswith("--"):          # a command-line option, not a file
        raise ConfigError(f"{first.source}: {first.message}", hint=hint)
    raise ConfigError(first.message, path=first.source or None, hint=hint)


def display_path(path: str | Path) -> str:
    """``path`` relative to the working directory when it is below it."""
    rel = os.path.relpath(Path(path).resolve(), Path.cwd().resolve())
    return str(path) if rel.startswith("..") else rel


def retype_command_line(value: Any) -> Any:
    """The scalars nested in a ``--config`` value, typed as YAML types them.

    Snakemake parses a top-level ``--config`` value with int, float and bool first, but a
    mapping or list with YAML's BaseLoader, which keeps every scalar inside it a string:
    ``--config 'rollator={"pf_seed": 2018}'`` gives ``{"pf_seed": "2018"}``, not what the
    same line in a config file gives.  Here a nested string becomes the int, float, bool or
    None that ``yaml.safe_load`` reads from it; any other string (a name, a date) stays as
    it is, and the top level is left alone.
    """
    def scalar(v: Any) -> Any:
        if not isinstance(v, str) or not v.strip():
            return v
        try:
            typed = yaml.safe_load(v)
        except yaml.YAMLError:
            return v
        return typed if typed is None or isinstance(typed, (bool, int, float)) else v

    def walk(v: Any) -> Any:
        if isinstance(v, Mapping):
            return {k: walk(x) for k, x in v.items()}
        if isinstance(v, list):
            return [walk(x) for x in v]
        return scalar(v)

    if isinstance(value, Mapping):
        return {k: (walk(v) if isinstance(v, (Mapping, list)) else v)
                for k, v in value.items()}
    return value


def check_config(config: Mapping, layers: Sequence[tuple[str, Any]] | None = None, *,
                 schema: dict | None = None) -> None:
    """Check a whole workflow config; raise :class:`ConfigError` on the first problem.

    Parameters
    ----------
    config : mapping
        The merged config (Snakemake's ``config``).
    layers : sequence of (name, dict), optional
        The sources merged into ``config``, lowest precedence first (the Snakefile's
        ``configfile``, each ``--configfile``, ``--config``): a problem names the last
        one that sets the key.  Default: ``config/config.yaml`` alone.
    schema : dict, optional
        Default :func:`load_schema`.
    """
    schema = schema or load_schema()
    layers = list(layers) if layers else [("config/config.yaml", config)]
    probs = find_problems(dict(config), schema)
    raise_problems(with_sources(probs, layers))


def run_problems(config: Mapping) -> list[Problem]:
    """Each name in ``run`` that is no key of ``studies`` (with the nearest one), each
    study name that is no id (:func:`id_problem`: it names folders and file patterns), and
    ``reports_dir``, ``results_dir``, ``data_dir`` that cannot name the folders the
    workflow writes (:func:`path_value_problem`): a clear config error before any job."""
    studies = list((config.get("studies") or {}) if isinstance(config, Mapping) else {})
    out = []
    for name in studies:
        why = id_problem(str(name))
        if why:
            out.append(Problem(("studies", name), f"studies: the study name {str(name)[:40]!r} "
                                                  f"{why}"))
    for i, name in enumerate(config.get("run") or []):
        why = id_problem(str(name))
        if why:
            out.append(Problem(("run", i), f"run[{i}]: the study name {str(name)[:40]!r} "
                                           f"{why}"))
            continue
        if name in studies:
            continue
        close = difflib.get_close_matches(str(name), studies, n=1, cutoff=0.6)
        tip = f" — did you mean {close[0]}?" if close else ""
        out.append(Problem(("run", i), f"run[{i}]: no study {name!r} under studies:{tip} "
                                       f"(studies: {', '.join(sorted(studies))})"))
    lowered: dict[str, str] = {}
    for name in studies:                  # folders that differ in case only are one folder
        other = lowered.setdefault(str(name).lower(), str(name))  # on macOS and Windows
        if other != name:
            out.append(Problem(("studies", name), f"studies: {name!r} and {other!r} differ "
                                                  "only in case (one folder on macOS and "
                                                  "Windows)"))
    for key, strict in (("reports_dir", True), ("results_dir", True), ("data_dir", False)):
        value = config.get(key) if isinstance(config, Mapping) else None
        if value is None:
            continue
        why = path_value_problem(str(value), strict=strict)
        if why:
            out.append(Problem((key,), f"{key}: {str(value)[:60]!r} {why}"))
    for study, entry in (config.get("studies") or {}).items():
        for key in ("trial_sheet", "subjects"):
            value = (entry or {}).get(key) if isinstance(entry, Mapping) else None
            why = path_value_problem(str(value)) if value else None
            if why:
                out.append(Problem(("studies", study, key),
                                   f"studies.{study}.{key}: {str(value)[:60]!r} {why}"))
    return out


def with_sources(problems: list[Problem], layers: Sequence[tuple[str, Any]]
                 ) -> list[Problem]:
    """``problems`` each naming the config layer that sets its key (for
    :func:`raise_problems`)."""
    return [Problem(p.path, p.message, p.source or _source(p.path, layers))
            for p in problems]


def check_study_file(study: Any, path: str | Path, *, schema: dict | None = None,
                     definition: str = "study_file") -> None:
    """Check a study's ``study.yaml`` (already loaded) against ``$defs/study_file`` (or
    another definition: ``external_file``, the study's ``external.yaml``)."""
    schema = schema or load_schema()
    src = display_path(path)
    if not isinstance(study, Mapping):
        raise ConfigError(f"{Path(path).name} must be a mapping of sections, got "
                          f"{_describe(study)}", path=src)
    probs = find_problems(dict(study), schema["$defs"][definition], root=schema)
    raise_problems([Problem(p.path, p.message, src) for p in probs])
