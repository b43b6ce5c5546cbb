"""Operators, one module per concern, each with its own register/unregister."""
from . import calibration, fabrication, optimize, results, slicing

_modules = (slicing, optimize, results, calibration, fabrication)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
