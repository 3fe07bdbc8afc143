"""Gait events and parameters: gait phases of seed 000 (:mod:`gaitval.gait.phases`) and
strides, autocorrelation and symmetry of seed 003 (:mod:`gaitval.gait.strides`)."""
