"""User interface, one module per concern, each with its own register/unregister."""
from ..blend.registration import modules_factory
from . import calibration, fabrication, overlay, panel, results, sidebar

register, unregister = modules_factory((panel, results, fabrication, calibration, overlay, sidebar))
