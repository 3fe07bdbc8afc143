"""Ground truth from motion capture: joint centres, leg point at sensor height, tibia
cylinder, gap filling, filtering, resampling to the sensor timestamps.

Entry point for the pipeline: :func:`ground_truth` (one trial -> tidy DataFrame).
"""
from gaitval.groundtruth.build import (GT_COLUMNS, LegPoints, ground_truth, leg_points,
                                       to_mocap_time, ultrasonic_ground_truth)
from gaitval.groundtruth.gaps import fill_short_gaps
from gaitval.groundtruth.shank import cylinder_at_height, fit_cylinder, point_at_height

__all__ = ["GT_COLUMNS", "LegPoints", "ground_truth", "leg_points", "to_mocap_time",
           "ultrasonic_ground_truth", "fill_short_gaps", "cylinder_at_height", "fit_cylinder",
           "point_at_height"]
