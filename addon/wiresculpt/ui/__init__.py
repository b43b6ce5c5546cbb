"""User interface, one module per concern, each with its own register/unregister."""
from .. import overlay
from . import calibration, fabrication, panel, results

_modules = (panel, results, fabrication, calibration, overlay)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
