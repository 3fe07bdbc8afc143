"""gaitval: rerun validation studies of low-cost gait sensors against optical motion capture.

The package works in metres and seconds everywhere; file formats and unit conversion live
in :mod:`gaitval.io` only.  See ``README.md`` for the two commands and ``docs/formats.md``
for the file formats gaitval reads and writes.
"""
from gaitval.errors import GaitvalError

__version__ = "0.1.0"
__all__ = ["GaitvalError", "__version__"]
