"""The headless wiresculpt run (FORMATS.md):

    blender --background --factory-startup --python scripts/wiresculpt_batch.py -- SCENE.json --out DIR

Reads and validates the scene file, imports the mesh, runs the pipeline and writes DIR/design.json
(atomically). One progress line per stage on stdout. Exit status: 0 a stable design was written;
2 the input was valid but no stable design exists (design.json still written, with the reason);
1 bad input or failure, with one clear message on stderr.
"""
import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ADDON = os.path.join(os.path.dirname(HERE), "addon")
if os.path.isdir(os.path.join(ADDON, "wiresculpt")) and ADDON not in sys.path:
    sys.path.insert(0, ADDON)

EXIT_STABLE, EXIT_FAILURE, EXIT_UNSTABLE = 0, 1, 2


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise ValueError(f"usage: wiresculpt_batch.py -- SCENE.json --out DIR ({message})")


def parse_args(argv):
    parser = _Parser(prog="wiresculpt_batch.py", add_help=False)
    parser.add_argument("scene")
    parser.add_argument("--out", required=True)
    return parser.parse_args(argv)


def scaled_planes(planes, factor):
    from wiresculpt.core.scene import PlaneSpec

    return [PlaneSpec(p.name, tuple(factor * c for c in p.origin), p.normal, p.contours) for p in planes]


def run(argv):
    import bpy
    import numpy as np

    from wiresculpt import native, pipeline
    from wiresculpt.core.design import write_design
    from wiresculpt.core.scene import load_scene
    from wiresculpt.mesh_import import import_mesh

    def say(stage, message):
        print(f"wiresculpt: {stage}: {message}", flush=True)

    args = parse_args(argv)
    scene = load_scene(args.scene)
    native.require()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    start = time.perf_counter()
    V, F, _objects = import_mesh(scene.mesh)
    factor = 1.0
    if scene.size is not None:
        extent = float(np.max(V.max(axis=0) - V.min(axis=0)))
        if extent <= 0:
            raise ValueError(f"mesh file {scene.mesh} has no extent to scale to size {scene.size} m")
        factor = scene.size / extent
        V = V * factor
    say("mesh", f"{len(V)} vertices, {len(F)} triangles, scale x{factor:g} "
                f"({time.perf_counter() - start:.3f} s)")
    design = pipeline.run(V, F, scaled_planes(scene.planes, factor), scene.material, scene.settings, say)
    path = os.path.join(args.out, "design.json")
    write_design(path, design)
    say("written", path)
    if design["stable"]:
        return EXIT_STABLE
    print(f"wiresculpt: not stable: {design['reason']}", file=sys.stderr, flush=True)
    return EXIT_UNSTABLE


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        code = run(argv)
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"wiresculpt: error: {exc}", file=sys.stderr, flush=True)
        code = EXIT_FAILURE
    except Exception as exc:  # a bug of ours: still one line, the traceback only on request
        print(f"wiresculpt: error: internal error ({type(exc).__name__}: {exc}); please report it "
              "with the scene file (set WIRESCULPT_DEBUG=1 for details)", file=sys.stderr, flush=True)
        if os.environ.get("WIRESCULPT_DEBUG"):
            import traceback

            traceback.print_exc()
        code = EXIT_FAILURE
    sys.stdout.flush()
    sys.stderr.flush()
    sys.exit(code)  # Blender passes the status through


if __name__ == "__main__":
    main()
