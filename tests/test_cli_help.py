"""Issue 37 (CLI usability): every verb of ``gaitval`` says what it does, and every option
and positional argument says what it is (``gaitval <verb> --help``), and ``--help`` of
every verb prints and exits 0.  In-process (gaitval.cli.main), not subprocesses."""
from __future__ import annotations

import argparse

import pytest

from gaitval.cli import build_parser, main

SHARED = {"verbose", "quiet"}           # -v/-q: added to every verb by cli_exit.add_verbosity


def _verbs() -> argparse._SubParsersAction:
    return next(a for a in build_parser()._actions
                if isinstance(a, argparse._SubParsersAction))


SUB = _verbs()
VERBS = sorted(SUB.choices)


def test_the_parser_lists_the_verbs():
    # a walk over an empty parser would pass every check below: the verbs are there
    assert len(VERBS) >= 30
    for verb in ("ingest", "register", "track", "evaluate-tug", "ultrasonic-noise",
                 "mtst-tables", "rollator-train", "legbench-track", "compare-tables",
                 "report"):
        assert verb in VERBS


def test_every_verb_has_a_one_line_help_and_a_description():
    helps = {c.dest: c.help for c in SUB._choices_actions}
    assert sorted(helps) == VERBS
    bare = [v for v in VERBS if not (helps[v] or "").strip()]
    assert bare == [], f"verbs without help in `gaitval --help`: {bare}"
    no_desc = [v for v in VERBS if not (SUB.choices[v].description or "").strip()]
    assert no_desc == [], f"verbs whose --help does not say what they do: {no_desc}"


@pytest.mark.parametrize("verb", VERBS)
def test_every_argument_of_every_verb_has_help(verb):
    sp = SUB.choices[verb]
    args = [a for a in sp._actions
            if not isinstance(a, argparse._HelpAction) and a.dest not in SHARED]
    bare = [a.option_strings[0] if a.option_strings else a.dest for a in args
            if not (a.help or "").strip() or a.help == argparse.SUPPRESS]
    assert bare == [], f"gaitval {verb}: arguments without help text: {bare}"


def test_the_main_parser_options_have_help():
    p = build_parser()
    bare = [a.option_strings for a in p._actions
            if a.option_strings and not (a.help or "").strip()]
    assert bare == []


@pytest.mark.parametrize("verb", VERBS)
def test_verb_help_prints_and_exits_0(verb, capsys):
    with pytest.raises(SystemExit) as exc:
        main([verb, "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: gaitval {verb}")
    # the description (the verb's help line) opens the text after the usage
    first = " ".join(SUB.choices[verb].description.split()[:3])
    assert first in " ".join(out.split())
    for action in SUB.choices[verb]._actions:
        if action.option_strings and action.dest not in SHARED:
            assert action.option_strings[-1] in out


def test_main_help_lists_every_verb(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for verb in VERBS:
        assert verb in out
