# SPDX-License-Identifier: GPL-3.0-or-later
"""wiresculpt: stable wire sculptures from planar slices of a mesh.

Blender-facing modules are imported inside register() so that the pure-Python parts
(wiresculpt.core) stay importable outside Blender, by the batch script and by tests.
"""

bl_info = {
    "name": "wiresculpt",
    "author": "wiresculpt developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Wire",
    "description": "Design self-supporting wire sculptures from planar slices of a mesh",
    "doc_url": "",
    "category": "Object",
}

_modules = []


def register():
    from . import props, operators, ui

    _modules[:] = [props, operators, ui]
    for m in _modules:
        m.register()


def unregister():
    for m in reversed(_modules):
        m.unregister()
    _modules.clear()
