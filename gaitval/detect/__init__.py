"""Scan → leg observations: static background removal and leg-pattern detectors."""
from gaitval.detect.background import BACKGROUNDS  # noqa: F401
from gaitval.detect.base import DETECTORS, OBS_COLUMNS, split_observations  # noqa: F401
from gaitval.detect import legpatterns  # noqa: F401  (registers "leg_patterns")
from gaitval.detect import window  # noqa: F401  (registers "rollator_window", seed 002 §II)
