"""Fuzz harness: every mutant is read in a child process with a time-out and rlimits, and
must end as a load or a gaitval error that names the file.

Outcomes of one mutant (``run_mutant``):

``load``          the loader returned, with every count at least the seed's and every
                  key number finite
``warned``        the loader returned and listed warnings the seed does not give
                  (``meta["warnings"]``, which ``gaitval inspect`` prints): loud, so not
                  a failure
``short``         the loader returned fewer frames, markers, scans or samples than the
                  unmutated seed holds, or lost a topic, without a warning     (a failure)
``nonfinite``     the loader returned, but a key number (rate, duration, count, start
                  time, temperature) is NaN, inf or missing                  (a failure)
``implausible``   a mutant of a plausibility class (``fuzz_mutators.IMPLAUSIBLE``: a
                  C3D whose POINT:UNITS or scale is wrong, a scan log whose ranges are
                  all negative or beyond its limits, an ultrasonic log stamped in whole
                  seconds) loaded without an error or a warning         (a failure);
                  the summary counts those mutants (``plaus``) and how many were refused
                  or warned about (``caught``)
``unsafe``        a trial sheet loaded with a study, subject or trial id that cannot name
                  a folder or stay one shell word (``..``, ``a b``, ``$(id)``)  (a failure)
``error``         a GaitvalError naming the mutant's file
``unnamed``       a GaitvalError that does not name the file          (a failure)
``foreign``       any other exception, or a GaitvalError marked ``unexpected`` by
                  ``gaitval.io.guard.loader`` (an exception nobody foresaw)  (a failure)
``crash``         the child died from a signal (segmentation fault ...)   (a failure)
``hang``          the child did not finish within the time-out            (a failure)

A native crash or stall that gaitval itself contained (ezc3d in its child process,
``gaitval.io.isolate``) is an ``error`` whose detail starts with ``contained``; the summary
counts those too.  Why no hypothesis/atheris: the inputs are mutants of real binary files
whose interesting structure (C3D parameter records, Parquet metadata) the mutators below
target directly; what must hold is about a *process* (it may not die or hang), which needs
a fork per input, and reproducibility comes from (kind, seed, index) alone.
"""
from __future__ import annotations

import json
import os
import resource
import select
import signal
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_mutators as M  # noqa: E402
import fuzz_seeds as S  # noqa: E402

KINDS = ("c3d", "bag", "scanlog", "ultrasonic", "annotations", "sheet")
FAILURES = ("short", "nonfinite", "unsafe", "implausible", "unnamed", "foreign", "crash",
            "hang")
#: the numbers a load must give finitely, per kind (bags: per LaserScan topic)
FINITE_KEYS = {"c3d": ("rate_hz", "n_frames", "n_markers", "t_start_s", "t_end_s",
                       "duration_s"),
               "bag": ("n_scans", "rate_hz", "duration_s", "t_start_s"),
               "scanlog": ("n_scans", "rate_hz", "duration_s", "t_start_s", "range_min_m",
                           "range_max_m"),
               "ultrasonic": ("n_samples", "rate_hz", "duration_s", "t_start_s")}
#: the counts a load may not lose silently against its seed
COUNT_KEYS = {"c3d": ("n_frames", "n_markers"), "bag": ("n_scans",),
              "scanlog": ("n_scans",), "ultrasonic": ("n_samples",)}
#: the wall-clock time-out (s) and the address-space limit (bytes) of a mutant's child
#: process: the issue's 20 s and 3 GiB (run_fuzz.py --timeout/--mem-gib)
LIMITS = {"timeout_s": 20.0, "memory_bytes": 3 * 2 ** 30}
_BASELINES: dict[tuple[str, str], dict] = {}


def make_mutant(kind: str, seed: int, index: int, work: Path) -> tuple[Path, str]:
    """Write mutant ``index`` of ``kind`` under ``work``; (path to read, description)."""
    rng = np.random.default_rng([seed, KINDS.index(kind), index])
    d = work / f"{kind}_{index}"
    d.mkdir(parents=True, exist_ok=True)
    if kind in ("c3d", "bag"):
        seeds = M.C3D_SEEDS if kind == "c3d" else M.BAG_SEEDS
        name = seeds[index % len(seeds)]
        src = M.REALDATA / ("c3d" if kind == "c3d" else "lrs") / name
        out = d / (f"m.{kind}")
        if kind == "c3d" and rng.random() < 0.1:
            return out, f"{name}: {M.c3d_implausible(src, out, rng)}"
        data = src.read_bytes()
        data, what = (M.c3d_mutation if kind == "c3d" else M.bag_mutation)(data, rng)
        out.write_bytes(data)
        return out, f"{name}: {what}"
    if kind in ("scanlog", "ultrasonic"):
        out = d / ("m.scan.parquet" if kind == "scanlog" else "m.us.parquet")
        if rng.random() < 0.1:
            return out, M.parquet_implausible(kind, out, rng)
        return out, M.parquet_mutation(kind, out, rng)
    if kind == "annotations":
        out = d / "m.annotations.csv"
        data, what = M.text_mutation(S.annotations_text(), rng)
        out.write_bytes(data)
        return out, f"annotations: {what}"
    sheet, subjects = S.sheet_texts()
    for rel in ("m/a.c3d", "l/a.scan.parquet", "l/a.bag", "a.annotations.csv"):
        (d / rel).parent.mkdir(parents=True, exist_ok=True)
        (d / rel).write_bytes(b"")
    which = "trials.csv" if rng.random() < 0.7 else "subjects.csv"
    text = sheet if which == "trials.csv" else subjects
    if which == "trials.csv" and rng.random() < 0.3:
        data, what = M.sheet_id_mutation(text, rng)
    else:
        data, what = M.text_mutation(text, rng)
    (d / "trials.csv").write_text(sheet)
    (d / "subjects.csv").write_text(subjects)
    (d / which).write_bytes(data)
    return d / "trials.csv", f"{which}: {what}"


def read_target(kind: str, path: Path) -> dict | None:
    """What ``gaitval inspect`` and the loaders do with a file of this kind; the
    description (None for a trial sheet)."""
    if kind == "sheet":
        from gaitval.io.trialsheet import load_trial_sheet
        df = load_trial_sheet(path)
        return {"ids": [str(v) for c in ("study", "subject", "trial") for v in df[c]]}
    from gaitval.io.inspect import describe
    d = describe(path)
    if kind == "bag" and len(d.get("scans") or {}) == 1:     # the topic left implicit
        from gaitval.io.rosbag import read_rosbag_scans
        read_rosbag_scans(path, None)
    return d


def _numbers(kind: str, d: dict) -> dict[str, object]:
    """The key numbers of a description: name -> value (bags: ``topic:name``)."""
    if kind == "bag":
        return {f"{t}:{k}": s.get(k) for t, s in (d.get("scans") or {}).items()
                for k in FINITE_KEYS["bag"]}
    out = {k: d.get(k) for k in FINITE_KEYS.get(kind, ())}
    if kind == "ultrasonic":
        out.update({f"temperature_c.{k}": (d.get("temperature_c") or {}).get(k)
                    for k in ("min", "max")})
    return out


def _counts(kind: str, d: dict) -> dict[str, int]:
    if kind == "bag":
        return {f"{t}:n_scans": s.get("n_scans") for t, s in (d.get("scans") or {}).items()}
    return {k: d.get(k) for k in COUNT_KEYS.get(kind, ())}


def judge_load(kind: str, d: dict | None, base: dict | None) -> dict:
    """The outcome of a load: ``nonfinite``, ``short``, ``warned`` or ``load``."""
    import math
    if d is None:
        return {"outcome": "load", "detail": ""}
    if kind == "sheet":                       # a loaded sheet: every id a safe folder name
        from gaitval.configcheck import id_problem
        bad = [v for v in d.get("ids", []) if id_problem(v)]
        return ({"outcome": "unsafe", "detail": f"unsafe id accepted: {bad[0][:40]!r}"}
                if bad else {"outcome": "load", "detail": ""})
    bad = [k for k, v in _numbers(kind, d).items()
           if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v)]
    if bad:
        return {"outcome": "nonfinite", "detail": "not finite: " + ", ".join(
            f"{k}={_numbers(kind, d)[k]!r}" for k in bad)[:300]}
    seen = set((base or {}).get("warnings") or [])             # the seed's own warnings
    warnings = [w for w in d.get("warnings") or [] if w not in seen]
    lost = []
    for k, v in (_counts(kind, base) if base else {}).items():
        got = _counts(kind, d).get(k)
        if got is None or got < v:
            lost.append(f"{k} {got} of {v}")
    if warnings:
        return {"outcome": "warned", "detail": "; ".join(lost + warnings)[:300]}
    if lost:
        return {"outcome": "short", "detail": "silently short: " + ", ".join(lost)}
    return {"outcome": "load", "detail": ""}


def baseline(kind: str, seed_name: str) -> dict | None:
    """The description of the unmutated seed (cached; None for sheets and annotations)."""
    if kind not in COUNT_KEYS:
        return None
    key = (kind, seed_name)
    if key not in _BASELINES:
        if kind in ("c3d", "bag"):
            src = M.REALDATA / ("c3d" if kind == "c3d" else "lrs") / seed_name
            _BASELINES[key] = read_target(kind, src)
        else:
            cols, _key, _meta = S.parquet_parts(kind)
            n = len(cols["t_s"])
            _BASELINES[key] = {"n_scans" if kind == "scanlog" else "n_samples": n}
    return _BASELINES[key]


def _child(kind: str, path: Path, name_part: str, wfd: int, cpu_s: int,
           base: dict | None = None, memory_bytes: int | None = None) -> None:
    code = 0
    try:
        import logging
        logging.getLogger("gaitval").setLevel(logging.ERROR)     # no duplicate-label notes
        resource.setrlimit(resource.RLIMIT_CPU, (cpu_s, cpu_s + 5))
        mem = memory_bytes or LIMITS["memory_bytes"]
        resource.setrlimit(resource.RLIMIT_AS, (mem, mem))
        try:
            d = read_target(kind, path)
            out = judge_load(kind, d, base)
        except Exception as exc:  # noqa: BLE001 - classified here
            out = classify(exc, name_part)
        os.write(wfd, json.dumps(out).encode()[:60000])
    except BaseException:  # noqa: BLE001
        code = 3
    finally:
        os._exit(code)


def classify(exc: Exception, name_part: str) -> dict:
    from gaitval.errors import GaitvalError
    msg = f"{type(exc).__name__}: {exc}"[:300]
    if not isinstance(exc, GaitvalError):
        return {"outcome": "foreign", "detail": msg}
    if getattr(exc, "unexpected", False):
        return {"outcome": "foreign", "detail": "wrapped " + msg}
    if name_part not in str(exc):
        return {"outcome": "unnamed", "detail": msg}
    contained = "crashed reading it" in str(exc) or "did not finish" in str(exc)
    return {"outcome": "error", "detail": ("contained " if contained else "") + msg}


def run_mutant(kind: str, path: Path, timeout_s: float | None = None,
               base: dict | None = None, memory_bytes: int | None = None) -> dict:
    """Read ``path`` in a forked child (rlimits on CPU time and address space; wall-clock
    time-out; defaults :data:`LIMITS`); ``base``: the seed's description."""
    timeout_s = timeout_s or LIMITS["timeout_s"]
    name_part = str(path.parent if kind == "sheet" else path)
    rfd, wfd = os.pipe()
    t0 = time.monotonic()
    pid = os.fork()
    if pid == 0:
        os.close(rfd)
        _child(kind, path, name_part, wfd, int(timeout_s) + 1, base, memory_bytes)
    os.close(wfd)
    ready, _, _ = select.select([rfd], [], [], timeout_s)   # (the child writes once)
    data = b""
    if ready:
        while chunk := os.read(rfd, 65536):
            data += chunk
    os.close(rfd)
    if not ready:
        os.kill(pid, signal.SIGKILL)
    _, status = os.waitpid(pid, 0)
    dt = time.monotonic() - t0
    if not ready:
        return {"outcome": "hang", "detail": f"no answer within {timeout_s:.0f} s", "s": dt}
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        return {"outcome": "hang" if sig == signal.SIGXCPU else "crash",
                "detail": f"signal {signal.Signals(sig).name}", "s": dt}
    try:
        return {**json.loads(data), "s": dt}
    except ValueError:
        return {"outcome": "crash", "detail": f"exit {os.waitstatus_to_exitcode(status)}, "
                                              "no answer", "s": dt}


def warm_up() -> None:
    """Import every reader and load the schemas once, before the children are forked (a
    child that imports ezc3d, rosbags or jsonschema itself spends most of its time so)."""
    import ezc3d  # noqa: F401
    import jsonschema  # noqa: F401
    import pyarrow.parquet  # noqa: F401
    import rosbags.highlevel  # noqa: F401
    import rosbags.typesys  # noqa: F401

    import gaitval.io.annotations  # noqa: F401
    import gaitval.io.c3d  # noqa: F401
    import gaitval.io.inspect  # noqa: F401
    import gaitval.io.rosbag  # noqa: F401
    import gaitval.io.scanlog  # noqa: F401
    import gaitval.io.ultrasonic  # noqa: F401
    from gaitval.io.sheettable import load_schema
    load_schema("trials")
    load_schema("subjects")


def fuzz_one(task: tuple[str, int, int, str]) -> dict:
    """One (kind, seed, index, work folder) task: make the mutant, read it, clean up."""
    import shutil
    kind, seed, index, work = task
    path, what = make_mutant(kind, seed, index, Path(work))
    seed_name = what.split(":", 1)[0] if kind in ("c3d", "bag") else kind
    res = run_mutant(kind, path, base=baseline(kind, seed_name))
    if M.IMPLAUSIBLE in what and res["outcome"] == "load":    # loaded quietly: wrong
        res = {**res, "outcome": "implausible",
               "detail": "an implausible file loaded without an error or a warning"}
    shutil.rmtree(Path(work) / f"{kind}_{index}", ignore_errors=True)
    return {"kind": kind, "index": index, "what": what, **res}


def summarise(results: list[dict]) -> dict[str, dict[str, int]]:
    """Counts per kind: mutants, loads, errors (contained), and each failure."""
    table: dict[str, dict[str, int]] = {}
    for r in results:
        row = table.setdefault(r["kind"], {"mutants": 0, "load": 0, "warned": 0,
                                           "error": 0, "contained": 0, "plaus": 0,
                                           "caught": 0, **{f: 0 for f in FAILURES}})
        row["mutants"] += 1
        row[r["outcome"]] += 1
        if M.IMPLAUSIBLE in r.get("what", ""):     # the plausibility classes
            row["plaus"] += 1
            row["caught"] += r["outcome"] in ("error", "warned")
        row["contained"] += r["detail"].startswith("contained")
    return table


def format_table(table: dict[str, dict[str, int]]) -> str:
    cols = ["mutants", "load", "warned", "error", "contained", "crash", "hang", "foreign",
            "unnamed", "short", "nonfinite", "unsafe", "plaus", "caught", "implausible"]
    lines = [f"{'file type':<12}" + "".join(f"{c:>12}" for c in cols)]
    total = {c: 0 for c in cols}
    for kind in KINDS:
        if kind in table:
            lines.append(f"{kind:<12}" + "".join(f"{table[kind][c]:>12}" for c in cols))
            for c in cols:
                total[c] += table[kind][c]
    lines.append(f"{'all':<12}" + "".join(f"{total[c]:>12}" for c in cols))
    return "\n".join(lines)
