"""How ``gaitval <verb>`` ends: exit codes, one-line errors, progress messages.

Exit codes (also in the README):

=====  ==============================================================================
0      the verb did what was asked
1      a data or analysis error: a bad or missing file, a trial-sheet or config problem,
       a trial that cannot be registered — one line ``gaitval: error: ...`` naming the
       file, the trial and the problem (``gaitval validate`` lists every problem)
2      a usage error: an unknown verb or option, a missing argument (argparse's message)
130    interrupted (Ctrl-C)
=====  ==============================================================================

A user error never prints a traceback.  An exception gaitval did not expect is a bug: it
exits with 1, says so, and prints the traceback so it can be reported.  Progress messages
of long steps go to stderr (``-q`` hides them, ``-v`` adds detail).
"""
from __future__ import annotations

import json
import logging
import os
import sys
import traceback

from gaitval.errors import GaitvalError

EXIT_OK, EXIT_DATA, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130


def add_verbosity(parser, subparsers) -> None:
    """``-v``/``-q`` on the main parser and on every verb (before or after the verb)."""
    for p, default in [(parser, 0)] + [(s, argparse_suppress()) for s in
                                       subparsers.choices.values()]:
        p.add_argument("-v", "--verbose", action="count", default=default,
                       help="more progress detail (-vv: debug)")
        p.add_argument("-q", "--quiet", action="count", default=default,
                       help="only warnings and errors")


def argparse_suppress():
    import argparse
    return argparse.SUPPRESS


class _StderrHandler(logging.StreamHandler):
    """A stream handler that writes to whatever ``sys.stderr`` is when it writes: the CLI
    called in-process (a library caller, a test capturing stderr) may have replaced the
    stream it had when the handler was made, and that one may be closed."""

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value):       # StreamHandler.__init__ assigns it: always sys.stderr
        pass


def configure_logging(verbose: int, quiet: int) -> None:
    """gaitval's log messages to stderr: INFO (progress) by default, -q WARNING, -v DEBUG."""
    level = logging.INFO - 10 * (verbose or 0) + 10 * (quiet or 0)
    log = logging.getLogger("gaitval")
    if not any(getattr(h, "_gaitval_cli", False) for h in log.handlers):
        h = _StderrHandler()
        h.setFormatter(logging.Formatter("gaitval: %(message)s"))
        h._gaitval_cli = True
        log.addHandler(h)
    log.setLevel(max(logging.DEBUG, min(level, logging.ERROR)))


def run_verb(func, args) -> int:
    """``func(args)`` with every way it can end mapped to an exit code and one message."""
    try:
        return int(func(args) or 0)
    except GaitvalError as exc:
        return _error(str(exc))
    except OSError as exc:                       # a path the user gave: missing, a folder,
        if isinstance(exc, BrokenPipeError):     # unreadable, too long ...
            _silence_stdout()
            return EXIT_OK
        where = f"[file {exc.filename}] " if exc.filename else ""
        return _error(f"{where}{exc.strerror or exc}")
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        return _error(f"a file given on the command line cannot be parsed: {exc}")
    except KeyboardInterrupt:
        print("gaitval: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception:                            # noqa: BLE001 - a bug: say so, show it
        traceback.print_exc()
        return _error("internal error (a bug in gaitval, not in your data; please report "
                      "it with the traceback above)")


def _error(message: str) -> int:
    print(f"gaitval: error: {message}", file=sys.stderr)
    return EXIT_DATA


def _silence_stdout() -> None:
    """After a closed pipe (``gaitval inspect FILE | head``): no second error at exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
