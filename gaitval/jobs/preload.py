"""Imported once by the pool's forkserver (:data:`gaitval.jobs.batch.PRELOAD`): the
step modules, the libraries they import lazily, and the trackers' compiled kernels, so
that every worker forked from it starts with them loaded."""
from __future__ import annotations

import importlib
import pkgutil

import matplotlib

matplotlib.use("Agg")

#: libraries some steps import lazily (an optional one may be absent: the step says so)
LIBRARIES = ("numpy", "pandas", "pyarrow", "pyarrow.parquet", "pyarrow.csv", "scipy.signal",
             "scipy.stats", "scipy.optimize", "scipy.interpolate", "scipy.linalg",
             "scipy.spatial", "matplotlib.pyplot", "ezc3d", "jinja2", "yaml",
             "sklearn.cluster", "sklearn.mixture", "motmetrics", "rosbags.highlevel",
             "jsonschema")
#: not needed by any step the workflow runs in a batch
SKIP = ("gaitval.__main__", "gaitval.simulate")

FAILED: list[str] = []


def _load() -> None:
    import gaitval

    for name in LIBRARIES:
        try:
            importlib.import_module(name)
        except Exception:
            FAILED.append(name)
    for mod in pkgutil.walk_packages(gaitval.__path__, "gaitval."):
        if mod.name.startswith(SKIP):
            continue
        try:
            importlib.import_module(mod.name)
        except Exception:
            FAILED.append(mod.name)
    for name in ("gaitval.track.pf", "gaitval.track.ukf", "gaitval.track.init_motion_kernel"):
        try:                           # the compiled kernels, loaded from numba's cache
            importlib.import_module(name).warm_up()
        except Exception:
            FAILED.append(f"{name}.warm_up")


_load()
