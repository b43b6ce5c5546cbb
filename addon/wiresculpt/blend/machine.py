"""The machine profile the Fabrication panel names, and its stock: what Export, Send, the
assembly guide, Optimize and Live use."""
import os

import bpy

from ..core import calibration as cal
from ..core import sizes


def chosen_profile(scene):
    """The machine profile of the panel's file (None: the default). ValueError naming the file."""
    path = scene.wiresculpt.machine_profile.strip()
    if not path:
        return None
    full = os.path.normpath(bpy.path.abspath(path))
    try:
        return cal.load_profile(full)
    except FileNotFoundError:
        raise ValueError(f"machine profile {full} does not exist (Calibration > Save Machine Profile "
                         "writes one; leave the field empty for the default)") from None
    except OSError as exc:
        raise ValueError(f"machine profile {full}: {exc.strerror or exc}") from None


def chosen_stock(scene):
    """(m, profile name): the stock of the Fabrication panel's machine profile, which the size
    warnings and limits name; the default profile's when none is chosen or it cannot be read (the
    Export then says what is wrong with it)."""
    try:
        return sizes.stock(chosen_profile(scene))
    except ValueError:
        return sizes.stock(None)
