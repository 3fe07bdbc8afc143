"""The verb table, the files of ``gaitval/cli/verbs/`` read in name order (shared
arguments in ``0_args.toml``, then the verbs by stage), read into argparse.

The table lists every verb in pipeline order: its name, what it runs, its help and its
arguments.  What it runs is either ``handler`` (``module:function`` in this package,
called with the parsed arguments) or, for a verb that only passes its arguments on,
``step`` (``module:function`` in gaitval) with ``call``, the arguments in the step's
order (``"name"``: positional; ``"key=name"``: keyword ``key``, ``"key="`` when both are
the same); either module is imported when the verb runs.  Each argument is written as
``add_argument(*flags, **keywords)`` would take it (``type``: ``path``, ``float`` or
``int``).  An argument several verbs share is written once under ``[args.NAME]`` and
named by a verb as ``use = "NAME"``.  ``stages = true`` stands for the workflow's stage
verbs, one per :data:`gaitval.jobs.stages.STAGES` entry with the options of
:data:`gaitval.jobs.stages.OPTIONS`."""
from __future__ import annotations

import argparse
import tomllib
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path

#: the table's folder
TABLE = Path(__file__).with_name("verbs")
#: the table's ``type`` names
TYPES = {"path": Path, "float": float, "int": int}


@dataclass(frozen=True)
class Handler:
    """A verb's handler, ``gaitval.cli.<module>.<function>(args)`` returning the exit
    code; the module is imported when the verb runs, not when the parser is built."""

    ref: str

    def __call__(self, args: argparse.Namespace) -> int:
        return _resolve(f"gaitval.cli.{self.ref}")(args)


@dataclass(frozen=True)
class Step:
    """A verb that passes its arguments on: ``gaitval.<module>.<function>`` called with
    ``call``'s arguments in order (``"name"`` positional, ``"key=name"`` keyword); exit
    code 0 when it returns."""

    ref: str
    call: tuple[str, ...]

    def __call__(self, args: argparse.Namespace) -> int:
        pos = [getattr(args, c) for c in self.call if "=" not in c]
        kw = {k: getattr(args, v or k)
              for k, _, v in (c.partition("=") for c in self.call if "=" in c)}
        _resolve(f"gaitval.{self.ref}")(*pos, **kw)
        return 0


def _resolve(ref: str):
    module, name = ref.split(":")
    return getattr(import_module(module), name)


def read_table(folder: Path = TABLE) -> dict:
    """The verb table as a dict: ``args`` (the shared arguments) and ``verbs`` (in the
    order of ``gaitval --help``: the folder's files by name, each file's verbs in turn)."""
    table: dict = {"args": {}, "verbs": []}
    for path in sorted(folder.glob("*.toml")):
        with open(path, "rb") as f:
            part = tomllib.load(f)
        table["args"].update(part.get("args", {}))
        table["verbs"] += part.get("verbs", [])
    return table


def add_verbs(sub: argparse._SubParsersAction, table: dict) -> None:
    """One sub-parser per verb of ``table``; ``gaitval VERB --help`` opens with what the
    verb does (its help)."""
    from gaitval.jobs.stages import OPTIONS, STAGES

    for verb in table["verbs"]:
        if verb.get("stages"):
            for name, (_, text) in STAGES.items():
                s = sub.add_parser(name, help=_stage_help(text), description=_stage_help(text))
                for opt, kw in OPTIONS.items():
                    s.add_argument(f"--{opt.replace('_', '-')}", **kw)
                s.set_defaults(func=Handler("jobs:cmd_stage"))
            continue
        s = sub.add_parser(verb["name"], help=verb["help"], description=verb["help"])
        for arg in verb.get("args", ()):
            spec = dict(table["args"][arg["use"]] if "use" in arg else arg)
            flags = spec.pop("flags")
            if "type" in spec:
                spec["type"] = TYPES[spec["type"]]
            s.add_argument(*flags, **spec)
        s.set_defaults(func=Handler(verb["handler"]) if "handler" in verb
                       else Step(verb["step"], tuple(verb["call"])))


def _stage_help(text: str) -> str:
    return f"{text} (a workflow job: the per-trial verbs in a pool of --threads processes)"
