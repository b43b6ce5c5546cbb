"""User interface, one module per concern, each with its own register/unregister."""
from ..blend.registration import modules_factory
from . import calibration, fabrication, overlay, panel, plane_search, results, sidebar

register, unregister = modules_factory((panel, results, plane_search, fabrication, calibration, overlay, sidebar))
