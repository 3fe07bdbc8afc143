"""Small valid files of the kinds gaitval generates, the seeds the fuzz harness mutates."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd

from gaitval.io.annotations import COLUMNS as ANN_COLUMNS
from gaitval.io.annotations import MAGIC

SHEET_HEADER = ("study,protocol,subject,trial,sensor_kind,mocap_file,sensor_file,sensor_topic,"
                "annotation_file,sensor_height_m,clock_offset_s,speed,speed_mps,stick,scenario,"
                "repetition")


def parquet_parts(kind: str) -> tuple[dict, bytes, dict]:
    """Columns, metadata key and metadata of a small valid scan log or ultrasonic log."""
    rng = np.random.default_rng(0)
    n = 20
    t = 1000.0 + 0.025 * np.arange(n)
    if kind == "scanlog":
        nb = 31
        ranges = rng.uniform(0.2, 5.0, (n, nb)).astype(np.float32)
        import pyarrow as pa
        cols = {"t_s": t,
                "ranges": pa.FixedSizeListArray.from_arrays(pa.array(ranges.ravel()), nb)}
        meta = {"format": "gaitval-scanlog", "version": 1, "angle_min_rad": -1.0,
                "angle_increment_rad": 2.0 / (nb - 1), "n_beams": nb, "range_unit": "m",
                "range_min_m": 0.1, "range_max_m": 30.0, "sensor_model": "fuzz",
                "mounting_height_m": 0.27, "scan_time_s": 0.025}
        return cols, b"gaitval:scanlog", meta
    anchors = [{"anchor": f"R{k}", "x_m": float(k), "y_m": 0.5 * k, "z_m": 0.1}
               for k in range(1, 4)]
    cols = {"t_s": t, "temperature_c": np.full(n, 21.5)}
    for a in anchors:
        cols[f"tof_{a['anchor']}_s"] = rng.uniform(1e-3, 8e-3, n)
    meta = {"format": "gaitval-ultrasonic", "version": 1, "quantity": "tof",
            "anchors": anchors, "transmitter": "heel", "sensor_model": "fuzz"}
    return cols, b"gaitval:ultrasonic", meta


def annotations_text() -> str:
    rows = pd.DataFrame({"t_s": [1.25, 2.4, 3.1], "event": ["target_step", "cross_step",
                                                           "foot_contact"],
                         "side": ["R", "L", ""], "target": ["T3", "", ""],
                         "value": ["hit", "yes", ""], "rater": ["R2", "R2", ""]})
    head = [MAGIC, "# time_base: video", "# time_offset_s: -0.5", "# rater: R2"]
    return "\n".join(head) + "\n" + rows[ANN_COLUMNS].to_csv(index=False,
                                                              lineterminator="\n")


def sheet_texts() -> tuple[str, str]:
    """A two-trial sheet and its subject table (files: m/a.c3d, l/a.scan.parquet, ...)."""
    sheet = "\n".join([
        SHEET_HEADER,
        "s,tug,S01,tug_S01_1,lrs,m/a.c3d,l/a.scan.parquet,,,0.27,,fast,1.1,false,,1",
        "s,mtst,S02,mtst_S02_1,lrs,m/a.c3d,l/a.bag,/scan,a.annotations.csv,0.27,0.5,,,true,"
        "red,2"]) + "\n"
    subjects = "\n".join(["subject,group,age_y,sex,height_m,leg_width_m",
                          "S01,young,24,F,1.70,0.10", "S02,elderly,71,M,1.80,0.12"]) + "\n"
    return sheet, subjects


def json_dumps(obj) -> str:
    return json.dumps(obj)
