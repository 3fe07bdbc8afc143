"""File formats: the only code in gaitval that knows them.

Everything returned is in metres and seconds.  See ``docs/formats.md``.

========================  ===========================================  =====================
what                      reader                                       module
========================  ===========================================  =====================
VICON / any C3D           :func:`gaitval.io.c3d.read_c3d`              ``io/c3d.py``
gaitval scan log          :func:`gaitval.io.scanlog.read_scanlog`      ``io/scanlog.py``
ROS 1 / ROS 2 bag         :func:`gaitval.io.rosbag.read_rosbag_scans`  ``io/rosbag.py``
ultrasonic TOF log        :func:`gaitval.io.ultrasonic.read_ultrasonic` ``io/ultrasonic.py``
rater annotations         :func:`gaitval.io.annotations.read_annotations` ``io/annotations.py``
trial sheet, subjects     :func:`gaitval.io.trialsheet.load_trial_sheet` ``io/trialsheet.py``
any of the above          :func:`gaitval.io.inspect.describe`          ``io/inspect.py``
========================  ===========================================  =====================

:mod:`gaitval.io.ingest` turns one trial's raw files into the tidy per-trial files the
rest of the pipeline reads; :mod:`gaitval.io.atomic` is how every output is written.
"""
