"""Solves the bundled globe (scripts/examples/globe/scene.json) through the add-on's bpy-free
pipeline, as a batch run loads it, and writes what the Windows check compares to OUT (JSON).

    PYTHON globe_design.py OUT ADDONS [PORTS]

ADDONS is the folder holding the `wiresculpt` package to use (with its compiled module). PORTS, a
JSON object {case: port}, names serial ports with a GRBL emulator behind each (test_windows.py's,
on a pty: under Wine a COM port mapped to it): SERIAL_PROGRAM is streamed to each and the results
recorded under "streams", with what a second stream to the "ok" port says while the first holds
it; on Windows also the ports listed beside the registry's own list (SERIALCOMM, read with winreg).

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
SERIAL_PROGRAM = ["G21", "G91", "G1 X1 F100", "G4 P0", "G1 Y-2 F100", "G4 P0", "M2"]
ABSENT_PORT = "COM199"  # no Windows here has it (test_windows.py maps from COM20 up, Wine makes COM1-4)


def stream_held(native, port):
    """Streams SERIAL_PROGRAM to `port` in a thread (its result first) while, 0.3 s into the
    stream's 1 s settle, this thread streams to the same port (what that says second)."""
    import threading
    import time

    held = {}

    def first():
        try:
            held["result"] = native.stream_program(port, SERIAL_PROGRAM, settle=1.0, response_timeout=5.0)
        except Exception as exc:
            held["result"] = f"{type(exc).__name__}: {exc}"

    thread = threading.Thread(target=first)
    thread.start()
    time.sleep(0.3)
    try:
        native.stream_program(port, SERIAL_PROGRAM, settle=0.0, response_timeout=2.0)
        second = "opened"
    except Exception as exc:
        second = f"{type(exc).__name__}: {exc}"
    thread.join()
    return held["result"], second


def listed_against_registry(native):
    """list_ports() with two entries added to HKLM\\HARDWARE\\DEVICEMAP\\SERIALCOMM (volatile: gone
    when Wine's server stops; removed here anyway), and the registry's own list read with winreg."""
    import winreg

    added = {"\\Device\\WiresculptTestA": "COM249", "\\Device\\WiresculptTestB": "COM31"}
    path = r"HARDWARE\DEVICEMAP\SERIALCOMM"
    key = winreg.CreateKeyEx(winreg.HKEY_LOCAL_MACHINE, path, 0, winreg.KEY_ALL_ACCESS)
    try:
        for device, name in added.items():
            winreg.SetValueEx(key, device, 0, winreg.REG_SZ, name)
        listed = native.list_ports()
        registry, i = [], 0
        while True:
            try:
                device, name, kind = winreg.EnumValue(key, i)
            except OSError:
                break
            i += 1
            if kind == winreg.REG_SZ:
                registry.append({"name": name, "description": device})
    finally:
        for device in added:
            try:
                winreg.DeleteValue(key, device)
            except OSError:
                pass
        winreg.CloseKey(key)
    return {"listed": listed, "registry": registry}


def streams(native, ports):
    """{case: stream result (or the exception's text)}; the "ok" port is streamed while a second
    stream tries it too ("held": what that one says)."""
    out = {}
    for case, port in ports.items():
        if case == "ok":
            out[case], out["held"] = stream_held(native, port)
            continue
        try:
            out[case] = native.stream_program(port, SERIAL_PROGRAM, settle=0.2, response_timeout=5.0)
        except Exception as exc:
            out[case] = f"{type(exc).__name__}: {exc}"
    return out


def main(out, ports):
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
        native.stream_program(ABSENT_PORT, ["G0 X1"], settle=0.0)
        report["serial"] = "opened"
    except Exception as exc:  # no such port: the message says so
        report["serial"] = f"{type(exc).__name__}: {exc}"
    report["ports"] = native.list_ports()
    report["streams"] = streams(native, ports)
    if sys.platform == "win32" and ports:
        report["port_list"] = listed_against_registry(native)

    with open(out, "w", encoding="utf-8") as f:
        json.dump(report, f, default=lambda v: v.tolist() if hasattr(v, "tolist") else str(v))
    print("globe_design: written", out)


if __name__ == "__main__":
    sys.path[:0] = [sys.argv[2], os.path.join(ROOT, "scripts")]
    main(sys.argv[1], json.loads(sys.argv[3]) if len(sys.argv) > 3 else {})
