"""A lab's own study built from real motion capture, for the registration plausibility
tests: the ``replay`` preset renders the laser logs a shin-height laser would have recorded
of three real C3D walks (``../shared/realdata/c3d/``); this module copies them into a study
whose C3Ds carry no calibration poles and whose sheet gives the sensor pose by hand, as a
lab without poles types it, correctly or with one of the usual mistakes.

Variants (:data:`VARIANTS`) change one trial's row (:data:`TARGET`) only:
``mm`` the position in millimetres, ``rad`` the yaw in radians in ``sensor_yaw_deg``,
``swap`` x and y exchanged, ``yaw180`` the yaw off by 180 degrees, ``other`` another
trial's pose copied into its row, ``clock`` the clock offset given 5 s off.

The mocap field is turned by :data:`ROTATE_DEG` about the vertical (the replay's lasers
face along the field's x axis, a yaw near 0 that a yaw in radians would hardly change; a
lab's mocap axes are arbitrary), markers and true poses alike.
"""
from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
REALDATA = ROOT.parent / "shared" / "realdata" / "c3d"
TARGET = "replay_functionalwalk"
OTHER = "replay_pig_flatfoot"
VARIANTS = ("mm", "rad", "swap", "yaw180", "other", "clock")
STUDY = "own"
ROTATE_DEG = 90.0


def replay_study(out: Path) -> Path:
    """The replay preset generated into ``out`` (once)."""
    from gaitval.simulate import generate_study

    if not (out / "trials.csv").is_file():
        preset = yaml.safe_load((ROOT / "config" / "studies" / "replay.yaml").read_text())
        for t in preset["replay"]["trials"]:       # paths in the preset are repo-relative
            t["file"] = str((ROOT / t["file"]).resolve())
        generate_study(out, preset)
    return out


def true_poses(sim: Path) -> pd.DataFrame:
    return pd.read_csv(sim / "truth" / "sensor_pose.csv").set_index("trial")


def build(sim: Path, out: Path, variant: str | None = None) -> Path:
    """The own study in ``out`` (trials.csv, subjects.csv, mocap/ without poles, lrs/),
    its sheet's pose measured by hand and ``variant`` applied to :data:`TARGET`."""
    from gaitval.io.c3d_read import read_c3d
    from gaitval.io.c3d_write import write_c3d

    sheet = pd.read_csv(sim / "trials.csv", dtype=str, keep_default_na=False)
    pose = true_poses(sim)
    sheet["study"] = STUDY
    th = math.radians(ROTATE_DEG)
    R = np.array([[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0],
                  [0, 0, 1]])
    x = {t: R[0, 0] * pose.loc[t, "x_m"] + R[0, 1] * pose.loc[t, "y_m"]
         for t in sheet["trial"]}
    y = {t: R[1, 0] * pose.loc[t, "x_m"] + R[1, 1] * pose.loc[t, "y_m"]
         for t in sheet["trial"]}
    yaw = {t: math.degrees(pose.loc[t, "yaw_rad"]) + ROTATE_DEG for t in sheet["trial"]}
    t = TARGET
    if variant == "mm":
        x[t], y[t] = x[t] * 1000.0, y[t] * 1000.0
    elif variant == "rad":
        yaw = {k: math.radians(v) for k, v in yaw.items()}     # the whole column, as typed
    elif variant == "swap":
        x[t], y[t] = y[t], x[t]
    elif variant == "yaw180":
        yaw[t] = yaw[t] + 180.0
    elif variant == "other":
        x[t], y[t], yaw[t] = x[OTHER], y[OTHER], yaw[OTHER]
    elif variant not in (None, "clock"):
        raise ValueError(variant)
    sheet["sensor_x_m"] = [f"{x[k]:.3f}" for k in sheet["trial"]]
    sheet["sensor_y_m"] = [f"{y[k]:.3f}" for k in sheet["trial"]]
    sheet["sensor_yaw_deg"] = [f"{yaw[k]:.3f}" if variant == "rad" else f"{yaw[k]:.2f}"
                               for k in sheet["trial"]]
    if variant == "clock":
        sheet["clock_offset_s"] = [f"{pose.loc[k, 'clock_offset_s'] + 5.0:.3f}" if k == t
                                   else "" for k in sheet["trial"]]
    for rel in sheet["sensor_file"]:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(sim / rel, out / rel)
    for rel in sheet["mocap_file"]:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        m = read_c3d(sim / rel)
        keep = [i for i, lb in enumerate(m.labels) if not lb.startswith("POLE")]
        write_c3d(out / rel, [m.labels[i] for i in keep], m.xyz[:, keep, :] @ R.T, m.rate_hz,
                  events=m.events, first_frame=m.first_frame)
    shutil.copy(sim / "subjects.csv", out / "subjects.csv")
    sheet.to_csv(out / "trials.csv", index=False)
    return out / "trials.csv"


def build_mixed(sim: Path, out: Path) -> Path:
    """One study holding the three correct trials and, per mistake of :data:`VARIANTS`, a
    copy of :data:`TARGET` (``<TARGET>_<variant>``, its own files) whose row carries that
    mistake alone (``rad``: this row's yaw in radians).  One workflow run then shows every
    refusal beside the trials that pass."""
    correct = pd.read_csv(build(sim, out, None), dtype=str, keep_default_na=False)
    rows = [correct]
    base = correct[correct["trial"] == TARGET].iloc[0]
    for v in VARIANTS:
        one = pd.read_csv(build(sim, out / f"_{v}", v), dtype=str, keep_default_na=False)
        row = one[one["trial"] == TARGET].copy()
        tid = f"{TARGET}_{v}"
        row["trial"] = tid
        if v == "rad":
            row["sensor_yaw_deg"] = f"{math.radians(float(base['sensor_yaw_deg'])):.3f}"
        for col in ("mocap_file", "sensor_file"):
            src = out / f"_{v}" / row[col].iloc[0]
            rel = row[col].iloc[0].replace(TARGET, tid)
            shutil.copy(src, out / rel)
            row[col] = rel
        rows.append(row)
        shutil.rmtree(out / f"_{v}")
    sheet = pd.concat(rows, ignore_index=True)
    sheet.to_csv(out / "trials.csv", index=False)
    return out / "trials.csv"
