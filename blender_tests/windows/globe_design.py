"""Solves the bundled globe (scripts/examples/globe/scene.json) through the add-on's bpy-free
pipeline, as a batch run loads it, and writes what the Windows check compares to OUT (JSON).

    PYTHON globe_design.py OUT ADDONS

ADDONS is the folder holding the `wiresculpt` package to use (with its compiled module).

Run by blender_tests/windows/test_windows.py twice: with the Windows CPython under Wine (the
add-on staged with the win_amd64 module, sys.path from the embeddable build's ._pth) and with the
Linux Python and the Linux module. Also records, in the same process (a Wine start costs seconds),
what the module's platform-specific parts do: an atomic write that replaces a file, the serial
port's answer, and the sizes of the interpreter's own types.
"""
import json
import os
import platform
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
GLOBE = os.path.join(ROOT, "scripts", "examples", "globe", "scene.json")


def main(out):
    import numpy as np

    from wiresculpt import native, pipeline  # the ADDONS package, before bench_scenes puts addon/ first

    import bench_scenes  # scripts/: the scene loaded as the batch run loads it

    if not native.available():
        raise SystemExit("the solver did not load: " + native.LOAD_ERROR)
    module = native.require()
    report = {"python": platform.python_version(), "platform": sys.platform, "numpy": np.__version__,
              "module": os.path.basename(module.__file__), "addon": os.path.dirname(native.__file__)}

    scene, _V, _F, _planes, sliced = bench_scenes.load_and_slice(GLOBE)
    design = pipeline.solve(sliced, scene.material, scene.settings)
    report["design"] = {
        "stable": design["stable"], "reason": design.get("reason"),
        "wires": [{"name": w["name"], "closed": w["closed"], "contour": np.asarray(w["contour"]).tolist(),
                   "target": np.asarray(w["target"]).tolist(), "rest": np.asarray(w["rest"]).tolist()}
                  for w in design["wires"]],
        "crossings": [{"wires": c["wires"], "hook": c["hook"], "normal_force": c.get("normal_force")}
                      for c in design["crossings"]],
        "assembly_order": design.get("assembly_order"),
        "load_capacity": design.get("load_capacity"),
    }

    with tempfile.TemporaryDirectory() as tmp:  # replacing a file that exists (MoveFileExW on Windows)
        path = os.path.join(tmp, "design.json")
        native.write_file_atomic(path, "first")
        native.write_file_atomic(path, "second, longer")
        with open(path, encoding="utf-8") as f:
            report["atomic_write"] = {"text": f.read(), "left": sorted(os.listdir(tmp))}

    try:
        native.stream_program("COM7", ["G0 X1"], settle=0.0)
        report["serial"] = "opened"
    except Exception as exc:  # the Windows build has no serial ports: the message says so
        report["serial"] = f"{type(exc).__name__}: {exc}"
    report["ports"] = native.list_ports()

    with open(out, "w", encoding="utf-8") as f:
        json.dump(report, f, default=lambda v: v.tolist() if hasattr(v, "tolist") else str(v))
    print("globe_design: written", out)


if __name__ == "__main__":
    sys.path[:0] = [sys.argv[2], os.path.join(ROOT, "scripts")]
    main(sys.argv[1])
