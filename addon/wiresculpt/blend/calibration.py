"""Calibration data kept in Blender: the user's config folder (calibrated materials, plots), the
last fits stored on the scene, the plots as images, and a material put into the panel."""
import json
import os

import bpy

from ..core import calibration as cal
from ..core import materials

RESULTS_KEY = "wiresculpt_calibration_results"  # scene custom property: JSON of the last fits
MATERIAL_NAME_KEY = "wiresculpt_material_name"  # scene custom property: name of the material in use
PLOT_IMAGE = {"CANTILEVER": "wiresculpt cantilever fit", "TILT": "wiresculpt tilt fit",
              "SPRINGBACK": "wiresculpt spring-back fit"}


def config_folder():
    """The user's wiresculpt config folder (materials/, plots/); WIRESCULPT_CONFIG overrides it."""
    folder = os.environ.get("WIRESCULPT_CONFIG")
    if folder:
        os.makedirs(folder, exist_ok=True)
        return folder
    return bpy.utils.user_resource('CONFIG', path="wiresculpt", create=True)


def results(scene):
    """The stored fits: {"cantilever", "tilt", "springback"} (each may be absent)."""
    try:
        return json.loads(scene.get(RESULTS_KEY, "{}"))
    except (TypeError, ValueError):
        return {}


def store(scene, key, value):
    r = results(scene)
    r[key] = value
    scene[RESULTS_KEY] = json.dumps(r)


def load_plot(kind, png):
    """Writes the plot into the config folder and (re)loads it as a Blender image."""
    path = cal.write_plot(os.path.join(config_folder(), "plots", kind.lower() + ".png"), png)
    name = PLOT_IMAGE[kind]
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.load(path, check_existing=False)
        image.name = name
    else:
        image.filepath = path
        image.reload()
    return image


def use_material(scene, m):
    """Sets the Material & Machine panel to material `m` (a preset by key, else Custom)."""
    ws = scene.wiresculpt
    if m["name"] in materials.PRESETS:
        ws.material_preset = m["name"]
        ws.wire_diameter = m["wire_diameter"]
    else:
        ws.material_preset = 'CUSTOM'
        ws.wire_diameter = m["wire_diameter"]
        for key in ("bending_stiffness", "max_torque", "friction", "density", "shear_modulus"):
            if key in m:
                setattr(ws, key, m[key])
    scene[MATERIAL_NAME_KEY] = m["name"]


def set_springback_rows(scene, commanded_deg):
    """The Calibration panel's spring-back rows: one per commanded angle, measured 0 (not yet)."""
    rows = scene.wiresculpt_calibration.springback_rows
    rows.clear()
    for angle in commanded_deg:
        row = rows.add()
        row.commanded_deg = angle
        row.measured_deg = 0.0


def springback_table(scene):
    """{"commanded_deg", "measured_deg", "lines"} of the rows whose measured angle is typed (not 0),
    as core.calibration.read_springback gives a CSV's ("lines": the row numbers, from 1)."""
    rows = [(k + 1, r.commanded_deg, r.measured_deg)
            for k, r in enumerate(scene.wiresculpt_calibration.springback_rows) if r.measured_deg != 0.0]
    return {"lines": [k for k, _c, _m in rows], "commanded_deg": [c for _k, c, _m in rows],
            "measured_deg": [m for _k, _c, m in rows]}
