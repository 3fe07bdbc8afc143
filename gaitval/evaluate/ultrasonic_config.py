"""Configuration of seed 003's ultrasonic study: the ``ultrasonic:`` section and its defaults.

Every stage of the study reads its keys from here: the camera reference
(:mod:`gaitval.groundtruth.reference`: ``transmitter_marker``, ``anchor_markers``,
``reference.max_gap_s``), the tracker role (``ukf``: the parameters of
:class:`gaitval.track.ukf.ToaUkf`, built by :func:`build_tracker`), alignment and gait
parameters (:mod:`gaitval.evaluate.ultrasonic`: ``resample_hz``, ``lowpass``, ``align``,
``strides``, ``symmetry``), the pendulum noise identification
(:mod:`gaitval.stats.noise`: ``noise_id``) and the strides the tables use
(:mod:`gaitval.tables.ultrasonic`: ``tables``).  ``workflow/schemas/config.schema.yaml``
documents each key; its defaults are these.
"""
from __future__ import annotations

from dataclasses import asdict

from gaitval.config import deep_merge
from gaitval.track.ukf import UKF_TRACKERS, ToaUkf

#: The tracker role of the ultrasonic track step (in :data:`~gaitval.track.ukf.UKF_TRACKERS`).
TRACKER = "toa_ukf"

DEFAULT_CFG: dict = {
    "transmitter_marker": "TX",
    "anchor_markers": ["ANC1", "ANC2", "ANC3", "ANC4"],
    "ukf": {k: v for k, v in asdict(ToaUkf()).items() if k != "mirror_guard"},
    "resample_hz": 50.0,
    "lowpass": {"order": 2, "cutoff_hz": 10.0},
    "reference": {"max_gap_s": 0.2},
    "align": {"min_overlap": 0.8, "max_lag_s": None, "subsample": True},
    "strides": {"min_period_s": 0.6, "max_period_s": 2.5, "subsample_peaks": False,
                "match_tolerance": 0.25},
    "symmetry": {"window_strides": 5},
    "noise_id": {"W_grid_mps2": [1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 50.0, 100.0, 200.0],
                 "outlier_mad": 5.0, "skip_start_s": 0.5},
    # Tables 2-8, C1 on the paper's sample size (gaitval.tables.ultrasonic_params)
    "tables": {"strides_per_subject": 10, "sample_seed": 2014},
}


def resolve_cfg(cfg: dict | None) -> dict:
    """The ultrasonic configuration with every default filled in.

    ``cfg`` is the ``ultrasonic`` section, or a config holding one under that key.
    """
    cfg = dict(cfg or {})
    if isinstance(cfg.get("ultrasonic"), dict):
        cfg = cfg["ultrasonic"]
    return deep_merge(DEFAULT_CFG, cfg)


def build_tracker(cfg: dict | None) -> ToaUkf:
    """The tracker role :data:`TRACKER` with the ``ukf`` parameters of ``cfg``."""
    return UKF_TRACKERS.build({"name": TRACKER, **resolve_cfg(cfg)["ukf"]})


def reference_kwargs(c: dict) -> dict:
    """Keyword arguments of :func:`gaitval.groundtruth.reference.reference_trajectory`
    from a resolved configuration."""
    return {"tx_marker": c["transmitter_marker"], "anchor_markers": c["anchor_markers"],
            "max_gap_s": float(c["reference"]["max_gap_s"])}
