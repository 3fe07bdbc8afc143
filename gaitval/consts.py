"""Column names, units and shared constants.

gaitval works in SI units inside: metres, seconds, radians, degrees Celsius for air
temperature.  Column names carry their unit as a suffix (``_m``, ``_s``, ``_rad``,
``_mps``) so a tidy table is self-describing.
"""
from __future__ import annotations

# -- protocols and sensor kinds (trial sheet vocabulary) ---------------------------------
PROTOCOLS = ("tug", "mtst", "rollator", "treadmill", "pendulum")
SENSOR_KINDS = ("lrs", "ultrasonic")
SIDES = ("L", "R")

# -- trial sheet / subject table columns ---------------------------------------------------
TRIAL_COLUMNS_REQUIRED = ("study", "protocol", "subject", "trial", "sensor_kind",
                          "mocap_file", "sensor_file")
TRIAL_COLUMNS_OPTIONAL = ("annotation_file", "sensor_topic", "sensor_height_m",
                          "clock_offset_s", "speed", "speed_mps", "stick", "scenario",
                          "repetition", "notes")
SUBJECT_COLUMNS_REQUIRED = ("subject", "leg_width_m")
SUBJECT_COLUMNS_OPTIONAL = ("group", "age_y", "sex", "height_m", "mass_kg",
                            "leg_length_m", "knee_width_m", "ankle_width_m",
                            "shank_length_m", "stick")

# -- tidy per-trial tables --------------------------------------------------------------
T = "t_s"               # time in seconds on the file's own clock
X, Y, Z = "x_m", "y_m", "z_m"
VX, VY = "vx_mps", "vy_mps"
MARKER = "marker"
FRAME = "frame"
TRIAL = "trial"
SUBJECT = "subject"
SIDE = "side"
METHOD = "method"
RANGE = "range_m"
ANGLE = "angle_rad"

# -- ground truth and evaluation frames (one row per sensor sample and side) -------------
T_SENSOR = "t_sensor_s"  # a sensor sample's time on the sensor clock
T_MOCAP = "t_mocap_s"    # the same instant on the mocap clock
SCAN = "scan"            # index of the scan in the sensor log
XS, YS = "xs_m", "ys_m"  # position in the sensor frame (X, Y: in the field)
VALID = "valid"          # bool: the row has a usable value

# -- trial-sheet cells read by more than one stage ----------------------------------------
SENSOR_HEIGHT = "sensor_height_m"
CLOCK_OFFSET = "clock_offset_s"

# -- "no return" in laser data ------------------------------------------------------------
#: Every loader maps inf, NaN, zero, below-range-min and above-range-max returns to NaN in
#: float metres.  NaN is the one documented "no return" value inside gaitval.
NO_RETURN = float("nan")

# -- physics -------------------------------------------------------------------------------
#: Speed of sound in dry air at 0 degC (m/s) in the physical law c = 331.3 sqrt(1 + T/273.15),
#: which the simulator uses as the true physics.  The pipeline converts time of flight with
#: seed 003's linear approximation, eq. (2): v_s = 331.5 + 0.6 T_c
#: (:func:`gaitval.io.ultrasonic.speed_of_sound`); the two differ by ~0.1 % at room
#: temperature.  Both laws go through the one eq. (1) conversion of :mod:`gaitval.io.ultrasonic`.
SPEED_OF_SOUND_0C = 331.3
KELVIN_0C = 273.15
