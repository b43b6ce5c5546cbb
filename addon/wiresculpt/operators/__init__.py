"""Operators, one module per concern, each with its own register/unregister."""
from ..blend.registration import modules_factory
from . import calibration, fabrication, live, machine, optimize, plane_search, results, slicing

register, unregister = modules_factory((slicing, optimize, plane_search, results, calibration, fabrication, machine, live))
