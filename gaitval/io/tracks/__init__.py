"""Leg tracks as an exchange format: ``*.tracks.csv`` and ``*.tracks.parquet`` (version 1).

Any tracker's output — gaitval's own (``gaitval export-tracks``), a vendor's export, a
ROS node's topics converted — enters gaitval's tables through this one format
(issue 37; docs/formats_external.md, section *Leg tracks*).  One row per time stamp and leg
(``side`` ``L``/``R``) or, for a tracker that gives only people, per time stamp and
person (``person``).  Positions ``x``, ``y`` (velocities ``vx``, ``vy``) are in the
header's ``units`` (``m`` or ``mm``; per second for velocities) and ``frame`` (``sensor``:
the laser frame; ``mocap``: the field frame), times ``t_s`` in seconds on the header's
``clock`` (``sensor`` or ``mocap``).

:func:`~gaitval.io.tracks.read.read_tracks` returns the rows in metres with the header as
a dict; :func:`~gaitval.io.tracks.sensor.tracks_to_sensor` turns them into gaitval's
per-scan track table (:func:`gaitval.methods.track_trial`'s columns) on the sensor clock
and in the sensor frame, given the trial's registration;
:func:`~gaitval.io.tracks.write.track_to_exchange` and
:func:`~gaitval.io.tracks.write.write_tracks` do the reverse for gaitval's own tracks, so
that export and re-import give back the same table, value for value.  By concern:

- :mod:`~gaitval.io.tracks.exchange`: the header and the columns, parsed (shared with
  detections and :mod:`gaitval.io.foot`);
- :mod:`~gaitval.io.tracks.read`, :mod:`~gaitval.io.tracks.write`: track files;
- :mod:`~gaitval.io.tracks.sensor`: into the per-scan track on the sensor clock and frame;
- :mod:`~gaitval.io.tracks.units`: positions the laser cannot have seen (wrong units or
  frame);
- :mod:`~gaitval.io.tracks.bag`: ROS bag topics of leg_tracker and people_msgs;
- :mod:`~gaitval.io.tracks.detections`: leg detections without identity as a file.

Names with a leading underscore are private to this package (and :mod:`gaitval.io.foot`,
which shares the header and the file writing).
"""
