"""Registration of a sensor to the mocap field: calibration poles, 2-D rigid fit, moving
(rollator) sensor poses, the ultrasonic anchor frame, and clock synchronisation.

Entry points for the pipeline: :func:`register_trial` (one trial -> one
:class:`RegistrationRecord`, a row of ``registration.csv``) and
:func:`registration_table`.  An LRS trial is registered with the subject's leg points
handed in by the ground truth (:class:`LegMotion`); registration never imports the ground
truth.  Conventions (sensor pose, clock model) are those of the common brief, repeated in
:mod:`gaitval.registration.rigid` and :mod:`gaitval.registration.clock`.
"""
from gaitval.registration.anchors import AnchorFit, fit_anchor_frame
from gaitval.registration.clock import (ClockEstimate, estimate_clock, estimate_clock_offset,
                                        to_mocap_time)
from gaitval.registration.legmotion import LegMotion
from gaitval.registration.poles import PoleFit, find_pole_candidates, register_poles
from gaitval.registration.rigid import field_to_sensor, fit_rigid_2d, sensor_to_field
from gaitval.registration.trial import (RECORD_FIELDS, RegistrationRecord, register_anchors,
                                        register_trial, registration_table)

__all__ = ["AnchorFit", "fit_anchor_frame", "ClockEstimate", "estimate_clock",
           "estimate_clock_offset", "to_mocap_time", "LegMotion", "PoleFit",
           "find_pole_candidates", "register_poles", "field_to_sensor", "fit_rigid_2d",
           "sensor_to_field", "RECORD_FIELDS", "RegistrationRecord", "register_anchors",
           "register_trial", "registration_table"]
