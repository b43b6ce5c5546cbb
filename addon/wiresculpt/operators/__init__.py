"""Operators, one module per concern, each with its own register/unregister."""
from ..blend.registration import modules_factory
from . import calibration, fabrication, optimize, results, slicing

register, unregister = modules_factory((slicing, optimize, results, calibration, fabrication))
