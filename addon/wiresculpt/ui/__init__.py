"""User interface, one module per concern, each with its own register/unregister."""
from . import panel

_modules = (panel,)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
