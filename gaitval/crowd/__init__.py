"""Multi-person laser scenes rendered by the twin's laser model, and their benchmark.

:mod:`gaitval.crowd.scenes` draws a scene (room, furniture, clutter, sensor path, walkers)
from a seed and renders its scans with :mod:`gaitval.simulate.laser`;
:mod:`gaitval.crowd.bench` tracks every scene with the people methods and a port of
leg_tracker's rules and scores them as the leg_tracker benchmark scores its bags
(docs/crowd.md).
"""
