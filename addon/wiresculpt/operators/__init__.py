"""Operators, one module per concern, each with its own register/unregister."""
from . import calibration, optimize, results, slicing

_modules = (slicing, optimize, results, calibration)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
