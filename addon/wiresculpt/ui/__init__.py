"""User interface, one module per concern, each with its own register/unregister."""
from ..blend import model_watch
from ..blend.registration import modules_factory
from . import calibration, fabrication, machine, overlay, panel, plane_search, results, sidebar

# model_watch: the depsgraph's changes of the model, for the Stability box (ui/stale.py)
register, unregister = modules_factory((panel, results, plane_search, fabrication, machine, calibration, overlay, sidebar,
                                        model_watch))
