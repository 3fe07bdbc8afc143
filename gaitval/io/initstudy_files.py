"""The recordings of a folder as ``gaitval init-study`` finds them (:mod:`gaitval.io.initstudy`):
each file's kind, each sensor file paired with its C3D (by name, then by time), what the
C3D, a bag and a scan log say, and the trial's protocol, subject, speed, scenario,
repetition and stick from the words of its file name; and what init-study reports
(:class:`InitResult`, cells left as :data:`FILL_IN`).
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path


#: what a cell the user must fill in holds (refused by ``gaitval validate``)
FILL_IN = "FILL_IN"


PROTOCOL_WORDS = {"tug": "tug", "mtst": "mtst", "rollator": "rollator",
                  "treadmill": "treadmill", "pendulum": "pendulum", "legbench": "legbench"}
#: words of a file name that name the sensor or the kind of file, not the trial
NOISE_WORDS = {"us", "ultrasonic", "lrs", "laser", "scan", "mocap", "vicon", "trial"}
SPEEDS = ("slow", "normal", "fast")
STICK_WORDS = {"stick": True, "cane": True, "nostick": False, "no-stick": False}
_REPETITION = re.compile(r"^(?:t|r|rep|trial)?(\d{1,6})$")
_ID_BAD = re.compile(r"[^A-Za-z0-9_.-]")


def as_id(text: str, fallback: str) -> str:
    """``text`` as an id (gaitval.configcheck.id_problem): other characters as ``_``, no
    leading ``-`` or ``.`` (a command line would read ``-rf`` as options)."""
    return _ID_BAD.sub("_", text).lstrip("-.")[:100] or fallback


def unique_id(candidates: list[str], taken: set[str]) -> str:
    """The first of ``candidates`` (ids) no id in ``taken`` (lower case) equals up to
    case, else the last one with ``_2``, ``_3``, ...: ids that differ only in case name
    one folder on macOS and Windows.  Adds the id to ``taken``."""
    for c in candidates:
        if c.lower() not in taken:
            taken.add(c.lower())
            return c
    n = 2
    while f"{candidates[-1]}_{n}".lower() in taken:
        n += 1
    taken.add(f"{candidates[-1]}_{n}".lower())
    return f"{candidates[-1]}_{n}"


#: folders never scanned: what gaitval or a simulator writes, and hidden folders
SKIP_DIRS = {"truth", "results", "reports", "logs", ".snakemake"}
SUFFIXES = (("c3d", (".c3d",)), ("scanlog", (".scan.parquet",)),
            ("ultrasonic", (".us.parquet",)), ("annotations", (".annotations.csv",)),
            ("positions", (".positions.csv",)), ("targets", (".targets.csv",)),
            ("tracks", (".tracks.csv", ".tracks.parquet")),
            ("foot", (".foot.csv", ".foot.parquet")), ("bag", (".bag",)))


@dataclass
class Found:
    """One recording file: its kind, path relative to the folder, and name stem."""

    kind: str
    rel: str
    stem: str
    mtime: float


@dataclass
class InitResult:
    """What :func:`~gaitval.io.initstudy.init_study` wrote and what the user must still
    do."""

    folder: Path
    written: list[Path] = field(default_factory=list)
    kept: list[Path] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)       # what was filled from where
    todo: list[str] = field(default_factory=list)        # cells and settings to fill in
    unpaired: list[str] = field(default_factory=list)    # files that became no trial
    problems: list[str] = field(default_factory=list)    # gaitval validate's list

    def text(self) -> str:
        out = [f"init-study {self.folder}:"]
        out += [f"  wrote {p}" for p in self.written]
        out += [f"  kept  {p} (exists; --force replaces it)" for p in self.kept]
        if self.notes:
            out.append("from the files:")
            out += [f"  {n}" for n in self.notes]
        if self.unpaired:
            out.append("files that are no trial:")
            out += [f"  {n}" for n in self.unpaired]
        if self.todo:
            out.append(f"to fill in (cells marked {FILL_IN}):")
            out += [f"  {n}" for n in self.todo]
        if self.problems:
            out.append(f"gaitval validate: {len(self.problems)} problem"
                       f"{'s' * (len(self.problems) > 1)}:")
            out += [f"  {p}" for p in self.problems]
        else:
            out.append("gaitval validate: OK")
        return "\n".join(out)


def _kind(name: str) -> tuple[str, str] | None:
    low = name.lower()
    for kind, sufs in SUFFIXES:
        for s in sufs:
            if low.endswith(s) and len(name) > len(s):
                return kind, name[:-len(s)]
    return None


def scan_folder(folder: Path) -> list[Found]:
    """Every recording file under ``folder`` (sorted by path), ROS 2 bag folders included;
    symbolic links that lead outside the folder are skipped (the sheet could not use them)."""
    folder = Path(folder)
    root = folder.resolve()
    found: list[Found] = []
    for dirpath, dirnames, filenames in os.walk(folder):
        d = Path(dirpath)
        if (d / "metadata.yaml").is_file() and d != folder:        # a ROS 2 bag folder
            found.append(Found("bag", d.relative_to(folder).as_posix(), d.name,
                               (d / "metadata.yaml").stat().st_mtime))
            dirnames[:] = []
            continue
        dirnames[:] = sorted(n for n in dirnames if n not in SKIP_DIRS and not n.startswith("."))
        for name in sorted(filenames):
            k = _kind(name)
            p = d / name
            if k is None or not p.resolve().is_relative_to(root):
                continue
            found.append(Found(k[0], p.relative_to(folder).as_posix(), k[1],
                               p.stat().st_mtime))
    return sorted(found, key=lambda f: f.rel)


def _words(stem: str) -> list[str]:
    return [w for w in re.split(r"[_\-. ]+", stem) if w]


def c3d_facts(path: Path) -> dict:
    """Labels, Vicon subject name and Plug-in-Gait anthropometrics (m, kg) of a C3D."""
    from gaitval.io.c3d import read_c3d
    from gaitval.io.c3d_params import Parameters, decode_text, parse_parameters

    tr = read_c3d(path)
    out: dict = {"labels": list(tr.labels)}
    with open(path, "rb") as fh:
        head = fh.read(512)
        ps = (max(head[0], 1) - 1) * 512
        ds = (int.from_bytes(head[16:18], "little") - 1) * 512
        fh.seek(0)
        section = fh.read(ds)
    try:
        proc = section[ps + 3]
        params = Parameters(parse_parameters(section, ps, ds), dec=proc == 85)
    except Exception:                                  # noqa: BLE001 - read_c3d read it
        return out
    names = params.params.get(("SUBJECTS", "NAMES"))
    if names is not None and names.type == -1:
        text = decode_text(names.data).strip()
        width = names.dims[0] if names.dims else len(text)
        first = text[:width].strip() if width else ""
        if first and not _ID_BAD.search(first):
            out["subject"] = first
    pig = {}
    for key, col, scale in (("Height", "height_m", 1e-3), ("Bodymass", "mass_kg", 1.0),
                            ("KneeWidth", "knee_width_m", 1e-3),
                            ("AnkleWidth", "ankle_width_m", 1e-3),
                            ("LegLength", "leg_length_m", 1e-3),
                            ("TibiaLength", "shank_length_m", 1e-3)):
        vals = [params.first("PROCESSING", n.upper()) for n in (key, f"L{key}", f"R{key}")]
        vals = [v for v in vals if v is not None and v > 0]
        if vals:
            pig[col] = round(sum(vals) / len(vals) * scale, 4)
    out["pig"] = pig
    return out


def bag_topics(path: Path) -> tuple[str | None, list[str], list[str]]:
    """The bag's LaserScan topic (None unless exactly one), its tracker topics
    (:data:`gaitval.io.tracks.bag.BAG_PEOPLE_TYPES`: a tracker recorded with the scans) and its
    leg-detection topics (:data:`gaitval.io.tracks.bag.BAG_LEG_DETECTIONS`)."""
    from gaitval.io.rosbag import LASERSCAN, _open
    from gaitval.io.tracks.bag import BAG_LEG_DETECTIONS, BAG_PEOPLE_TYPES

    reader = _open(path, None)
    try:
        scans = sorted({c.topic for c in reader.connections if c.msgtype == LASERSCAN})
        trackers = sorted({c.topic for c in reader.connections
                           if c.msgtype in BAG_PEOPLE_TYPES})
        detectors = sorted({c.topic for c in reader.connections
                            if c.msgtype == BAG_LEG_DETECTIONS})
    finally:
        reader.close()
    return (scans[0] if len(scans) == 1 else None), trackers, detectors


def scanlog_height(path: Path) -> float | None:
    import json

    import pyarrow.parquet as pq
    meta = (pq.read_schema(path).metadata or {}).get(b"gaitval:scanlog")
    if not meta:
        return None
    h = json.loads(meta).get("mounting_height_m")
    return float(h) if isinstance(h, (int, float)) and h > 0 else None


def pair_recordings(sensors: list[Found], c3ds: list[Found], max_gap: float
          ) -> tuple[dict[str, Found], list[str]]:
    """sensor rel -> C3D: by stem first, then by modification time (one to one)."""
    by_stem: dict[str, list[Found]] = {}
    for c in c3ds:
        by_stem.setdefault(c.stem, []).append(c)
    pairs: dict[str, Found] = {}
    used: set[str] = set()
    notes: list[str] = []
    for s in sensors:
        hits = [c for c in by_stem.get(s.stem, []) if c.rel not in used]
        if len(hits) == 1:
            pairs[s.rel] = hits[0]
            used.add(hits[0].rel)
    left_s = [s for s in sensors if s.rel not in pairs]
    left_c = [c for c in c3ds if c.rel not in used]
    cand = sorted((abs(s.mtime - c.mtime), s.rel, c.rel) for s in left_s for c in left_c
                  if abs(s.mtime - c.mtime) <= max_gap)
    taken_s: set[str] = set()
    for gap, srel, crel in cand:
        if srel in taken_s or crel in used:
            continue
        pairs[srel] = next(c for c in left_c if c.rel == crel)
        used.add(crel)
        taken_s.add(srel)
        notes.append(f"{srel} paired with {crel} by time (files written {gap:.0f} s apart; "
                     "check)")
    return pairs, notes


def trial_from_name(stem: str, kind: str, labels: list[str]) -> dict:
    words = _words(stem)
    low = [w.lower() for w in words]
    out: dict = {}
    protos = [PROTOCOL_WORDS[w] for w in low if w in PROTOCOL_WORDS]
    if protos:
        out["protocol"] = protos[0]
    elif kind == "ultrasonic":
        out["protocol"] = "treadmill"
    elif any(lab.startswith("RLT_") for lab in labels):
        out["protocol"] = "rollator"
    rest = []
    for w, lw in zip(words, low):
        if lw in PROTOCOL_WORDS or lw in NOISE_WORDS:
            continue
        if lw in SPEEDS:
            out["speed"] = lw
        elif lw in STICK_WORDS:
            out["stick"] = STICK_WORDS[lw]
        elif _REPETITION.match(lw):
            out.setdefault("repetition", int(_REPETITION.match(lw).group(1)))
        else:
            rest.append(w)
    rest = [w for w in (as_id(w, "") for w in rest) if w]  # ids: letters, digits, _ . -
    if out.get("protocol") == "pendulum":
        out["subject"] = "pendulum"
        rest = [w for w in rest if w.lower() != "pendulum"]
    elif rest:
        out["subject"] = rest.pop(0)
    if rest:
        out["scenario"] = "_".join(rest)
    return out
