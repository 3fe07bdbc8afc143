"""Ground truth from motion capture: joint centres, leg point at sensor height, tibia
cylinder, gap filling, filtering, resampling to the sensor timestamps.

Entry points for the pipeline: :func:`sensor_leg_points` (one LRS trial's leg points,
computed once and handed to the registration and then to :func:`ground_truth`) and
:func:`ground_truth` (one trial -> tidy DataFrame).
"""
from gaitval.groundtruth.build import GT_COLUMNS, ground_truth, ultrasonic_ground_truth
from gaitval.groundtruth.gaps import fill_short_gaps
from gaitval.groundtruth.legs import LegPoints, leg_points, sensor_height, sensor_leg_points
from gaitval.groundtruth.shank import cylinder_at_height, fit_cylinder, point_at_height
from gaitval.registration.clock import to_mocap_time

__all__ = ["GT_COLUMNS", "LegPoints", "ground_truth", "leg_points", "sensor_height",
           "sensor_leg_points", "to_mocap_time", "ultrasonic_ground_truth", "fill_short_gaps",
           "cylinder_at_height", "fit_cylinder", "point_at_height"]
