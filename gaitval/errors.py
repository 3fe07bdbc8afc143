"""gaitval's own exception types.

Every error a user can cause (a bad file, a typo in the trial sheet, a missing marker, a
gap too long) is raised as a subclass of :class:`GaitvalError` with one message that names
the file, the trial and the problem, and, where possible, what to do about it.
"""
from __future__ import annotations

from pathlib import Path


class GaitvalError(Exception):
    """Base class of every error gaitval raises on purpose.

    Parameters
    ----------
    problem : str
        What is wrong, in one sentence a user can act on.
    path : str or Path, optional
        The file the problem was found in.
    trial : str, optional
        The trial id (from the trial sheet) the file belongs to.
    hint : str, optional
        What to do about it.
    """

    def __init__(self, problem: str, *, path: str | Path | None = None,
                 trial: str | None = None, hint: str | None = None):
        self.problem = problem
        self.path = None if path is None else str(path)
        self.trial = trial
        self.hint = hint
        super().__init__(self._format())

    def _format(self) -> str:
        where = []
        if self.path is not None:
            where.append(f"file {self.path}")
        if self.trial is not None:
            where.append(f"trial {self.trial}")
        head = f"[{', '.join(where)}] " if where else ""
        tail = f" ({self.hint})" if self.hint else ""
        return f"{head}{self.problem}{tail}"

    def with_context(self, *, path=None, trial=None) -> "GaitvalError":
        """Return a copy of this error with the file and/or trial filled in where missing."""
        new = type(self).__new__(type(self))
        GaitvalError.__init__(new, self.problem,
                              path=self.path if self.path is not None else path,
                              trial=self.trial if self.trial is not None else trial,
                              hint=self.hint)
        return new


class FileFormatError(GaitvalError):
    """A file cannot be read, or does not follow its documented format."""


class TrialSheetError(GaitvalError):
    """The trial sheet or subject table is invalid (names the row and column)."""


class ConfigError(GaitvalError):
    """The workflow configuration is invalid."""


class MarkerError(GaitvalError):
    """A marker needed for ground truth or registration is missing or unusable."""


class RegistrationError(GaitvalError):
    """The sensor cannot be registered to the mocap field (poles, clocks)."""


class TimestampError(GaitvalError):
    """A sensor log's timestamps are unusable (reported, never silently reordered)."""
