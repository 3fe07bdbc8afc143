"""Published values of the leg_tracker benchmark (Leigh et al., ICRA 2015, Tables II–III).

Transcribed from the paper's Table III (valid = matched).  ``n/a``: the paper does not count false positives on the following
sets (only the followed person is annotated).

Reference: A. Leigh, J. Pineau, N. Olmedo, H. Zhang, "Person Tracking and Following with 2D
Laser Scanners", IEEE ICRA 2015.
"""
from __future__ import annotations

SOURCE = "Leigh et al. ICRA 2015, Table III"

#: set -> how its authors score it (spec "Scoring rules")
BENCHMARK_SETS = {
    "general_stationary": {"mode": "general", "sector_deg": (-80.0, 12.0)},
    "general_moving": {"mode": "general", "sector_deg": (-80.0, 12.0)},
    "following_indoor": {"mode": "following", "sector_deg": None},
    "following_outdoor": {"mode": "following", "sector_deg": None},
}

#: set -> [(tracker, matched, ID switches, misses, FP or None, MOTA % or None, MOTP m)]
TABLE3 = {
    "general_stationary": [("ROS leg_detector", 427, 51, 1605, 28, 19.2, 0.28),
                           ("leg_tracker Individual Leg", 569, 10, 1504, 61, 24.4, 0.23),
                           ("leg_tracker Joint Leg", 703, 8, 1372, 11, 33.2, 0.16)],
    "general_moving": [("ROS leg_detector", 149, 15, 481, 294, -22.5, 0.27),
                       ("leg_tracker Individual Leg", 160, 2, 483, 88, 11.2, 0.17),
                       ("leg_tracker Joint Leg", 163, 2, 480, 97, 10.2, 0.15)],
    "following_indoor": [("ROS leg_detector", 15425, 196, 3425, None, None, 0.15),
                         ("leg_tracker Individual Leg", 17295, 73, 1678, None, None, 0.13),
                         ("leg_tracker Joint Leg", 18554, 7, 485, None, None, 0.09)],
    "following_outdoor": [("ROS leg_detector", 4835, 1721, 1172, None, None, 0.09),
                          ("leg_tracker Individual Leg", 5348, 121, 819, None, None, 0.11),
                          ("leg_tracker Joint Leg", 6073, 21, 104, None, None, 0.09)],
}
