"""Inside the Windows bpy (PyPI's win_amd64 wheel) under Wine: installs the Windows extension zip
with Install from Disk into a repository made for the test, checks it is enabled with the solver
from its wheel, slices and optimizes the globe, exports the fabrication files, and writes what it
saw to REPORT (JSON).

    python.exe bpy_install.py ZIP REPO GLOBE_OBJ RADIUS OUT REPORT

Run by test_windows_bpy.py (BLENDER_USER_RESOURCES names a fresh folder).
"""
import importlib
import json
import math
import os
import sys

import bpy

zip_path, repo_dir, globe_obj, radius, out_dir, report_path = sys.argv[1:7]
report = {"bpy": bpy.app.version_string, "platform": sys.platform}


def finish(**more):
    report.update(more)
    with open(report_path, "w", encoding="utf-8") as f:
        json.dump(report, f)
    sys.stdout.flush()
    os._exit(0)  # the bpy module crashes in Python's teardown (docs/testing.md); all is written


repo = bpy.context.preferences.extensions.repos.new(name="wiresculpt test", module="wiresculpt_test",
                                                   custom_directory=repo_dir, source='USER')
try:
    report["install"] = sorted(bpy.ops.extensions.package_install_files(filepath=zip_path, repo=repo.module,
                                                                        enable_on_install=True))
except RuntimeError as exc:
    finish(install_error=str(exc))
name = "bl_ext.wiresculpt_test.wiresculpt"
report["enabled"] = name in bpy.context.preferences.addons
native = importlib.import_module(name + ".native")
report["load_error"] = native.LOAD_ERROR
if native.module is None:
    finish()
report["module"] = native.module.__file__
mesh = importlib.import_module(name + ".blend.mesh")
results = importlib.import_module(name + ".blend.results")
_V, _F, objects = mesh.import_mesh(globe_obj)
target = objects[0]
target.scale = (float(radius),) * 3
bpy.context.view_layer.update()
bpy.context.scene.wiresculpt.model = target
for rotation in ((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0)):
    bpy.ops.wiresculpt.add_plane()
    bpy.context.view_layer.objects.active.rotation_euler = rotation
report["slice"] = sorted(bpy.ops.wiresculpt.slice())
report["optimize"] = sorted(bpy.ops.wiresculpt.optimize())
design = results.stored_design()
if design is None:
    finish()
report["stable"] = design["stable"]
report["reason"] = design.get("reason")
report["wires"] = [w["name"] for w in design["wires"]]
report["hooks"] = [c["hook"] for c in design["crossings"]]
report["assembly_order"] = design.get("assembly_order")
report["export"] = sorted(bpy.ops.wiresculpt.export_fabrication(directory=out_dir))
report["exported"] = {d: sorted(os.listdir(os.path.join(out_dir, d))) for d in sorted(os.listdir(out_dir))
                      if os.path.isdir(os.path.join(out_dir, d))}
finish()
