"""Issue 37: the verbs a user validating their own tracker runs by hand say what each
option is (``gaitval <verb> --help``): no option without its text."""
from __future__ import annotations

import argparse

import pytest

from gaitval.cli import build_parser

VERBS = ("evaluate-tug", "import-tracks", "export-tracks", "leg-detections",
         "leg-detections-table", "peer", "init-study")


@pytest.mark.parametrize("verb", VERBS)
def test_every_option_of_the_external_tracker_verbs_has_help(verb):
    sub = next(a for a in build_parser()._actions
               if isinstance(a, argparse._SubParsersAction))
    sp = sub.choices[verb]
    assert sp.description or next(c for c in sub._choices_actions if c.dest == verb).help
    bare = [a.option_strings[0] if a.option_strings else a.dest for a in sp._actions
            if not a.help and not isinstance(a, argparse._HelpAction)]
    assert bare == [], f"gaitval {verb}: options without help text: {bare}"
