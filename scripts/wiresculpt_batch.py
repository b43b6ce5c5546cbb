"""The headless wiresculpt run (docs/formats.md):

    blender --background --factory-startup --python scripts/wiresculpt_batch.py -- SCENE.json --out DIR [--profile P.json]

Reads and validates the scene file, imports the mesh, runs the pipeline and writes DIR/design.json
with the fabrication files beside it (svg/, dxf/, templates/, gcode/, bends/, bendlist/), then the results as
a Blender user sees them: DIR/sculpture.blend (wires, crossing markers and the design in a scene;
it opens with the 3D view framed on the sculpture, the sidebar on the Wire tab, the first wire
selected),
DIR/render.png (a Workbench still) and the assembly guide DIR/assembly/index.html with a picture
per step. The outputs replace an earlier run's as one set, only once all are written (the folders
svg/ dxf/ templates/ gcode/ bends/ bendlist/ assembly/ belong to the run; other files in DIR are left alone). One
progress line per stage on stdout. Exit status: 0 a stable design was written;
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
# What a run writes into DIR, replaced as one set (files, or folders that belong to the run).
OUTPUT_FILES = ("design.json", "sculpture.blend", "sculpture.blend1", "render.png")
OUTPUT_FOLDERS = ("assembly", "svg", "dxf", "templates", "gcode", "bends", "bendlist")
OUTPUTS = OUTPUT_FILES + OUTPUT_FOLDERS


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise ValueError(f"usage: wiresculpt_batch.py -- SCENE.json --out DIR [--profile PROFILE.json] "
                         f"[--machine-model PROFILE.json] ({message})")


def parse_args(argv):
    parser = _Parser(prog="wiresculpt_batch.py", add_help=False)
    parser.add_argument("scene")
    parser.add_argument("--out", required=True)
    parser.add_argument("--profile", default=None)
    parser.add_argument("--machine-model", default=None)
    return parser.parse_args(argv)


def scaled_planes(planes, factor):
    from wiresculpt.core.scene import PlaneSpec

    return [PlaneSpec(p.name, tuple(factor * c for c in p.origin), p.normal, p.contours) for p in planes]


def add_handles(scene, planes, design):
    """The scene file's planes as the add-on's slicing handles, sliced, with the design's wires
    ticked: the saved .blend can be edited and optimized again in Blender."""
    import bpy
    from mathutils import Vector

    from wiresculpt.blend.handles import contour_plane_name

    picked = {w["name"] for w in design["wires"]}
    for plane in planes:
        bpy.ops.wiresculpt.add_plane()
        handle = bpy.context.view_layer.objects.active
        handle.name = plane.name
        handle.location = plane.origin
        handle.rotation_euler = Vector(plane.normal).normalized().to_track_quat('Z', 'Y').to_euler()
    bpy.context.view_layer.update()
    bpy.ops.wiresculpt.slice()
    for item in scene.wiresculpt.contours:
        item.use = f"{contour_plane_name(item)}/{item.index}" in picked


def write_scene_outputs(design, objects, planes, factor, out, say, overlap=0.0):
    """sculpture.blend, render.png and assembly/ in `out`, from the design (progress lines name
    them relative to `out`, which is the run's staging folder)."""
    import bpy
    from mathutils import Matrix

    import wiresculpt
    from wiresculpt.blend import compat
    from wiresculpt.blend import guide as assembly_guide
    from wiresculpt.blend import results as scene_results
    from wiresculpt.blend import view as scene_view
    from wiresculpt.core import blendfile

    if not wiresculpt._modules:
        wiresculpt.register()
    scene = bpy.context.scene
    for obj in objects:  # the mesh as the solver saw it: scaled about the world origin
        obj.matrix_world = Matrix.Scale(factor, 4) @ obj.matrix_world
        obj.display_type = 'WIRE'
        obj.hide_render = True
    start = time.perf_counter()
    if len(objects) == 1 and design["wires"]:
        scene.wiresculpt.model = objects[0]
        add_handles(scene, planes, design)
    scene_results.write_results(scene, design)
    say("scene", f"{len(design['wires'])} wire curves, {len(design.get('crossings', []))} crossing markers "
                 f"({time.perf_counter() - start:.3f} s)")
    if design["wires"]:
        start = time.perf_counter()
        path = os.path.join(out, "render.png")
        assembly_guide.render_still(scene, design, path)
        say("render", f"render.png ({time.perf_counter() - start:.3f} s)")
    if design.get("assembly_steps"):
        start = time.perf_counter()
        path = assembly_guide.write_guide(scene, design, os.path.join(out, "assembly"), overlap=overlap)
        say("guide", f"{os.path.relpath(path, out)}, {len(design['assembly_steps'])} steps "
                     f"({time.perf_counter() - start:.3f} s)")
    # the file opens ready: the 3D views framed on the sculpture, the sidebar on the Wire tab,
    # the first wire selected
    ready = scene_view.open_ready(scene)
    path = os.path.abspath(os.path.join(out, "sculpture.blend"))
    # Blender writes the .blend to a temporary name and renames it: atomic like the rest. Saved
    # uncompressed, so that the set's verification (core/staging.py) can see its end block, and so
    # that on Blender 3.4, which cannot set the sidebar's tab from Python, the tab can be written
    # into the saved file.
    try:  # a failed write (a full disk) is a RuntimeError with Blender's errno text, or a CANCELLED
        saved = bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False, compress=False)
        why = "" if saved == {'FINISHED'} else f"the save ended {', '.join(sorted(saved))}"
    except RuntimeError as exc:
        why = str(exc).strip().removeprefix("Error:").strip() or "no reason given"
    if why:
        raise OSError(f"Blender could not save {os.path.basename(path)} ({why}; is the disk full?); "
                      "the earlier outputs are kept")
    tab = f"{compat.SIDEBAR_TAB} tab"
    if not ready["tab_set"]:
        try:
            blendfile.set_sidebar_tab(path, compat.SIDEBAR_TAB)
        except (ValueError, KeyError) as exc:  # a file layout this reader does not know: the file stays as saved
            tab = f"last used tab (the {compat.SIDEBAR_TAB} tab could not be set: {exc})"
    say("blend", f"sculpture.blend (opens on the {tab}, {ready['selected'] or 'no wire'} "
                 f"selected, the view {ready['size'] * scene_view.DISTANCE_IN_SIZES:.3g} m from the centre)")


def machine_profile(scene, args, say):
    """The machine profile of the run: --profile, else the scene's "machine_profile", else None
    (the default profile); ValueError naming the file when it cannot be used."""
    from wiresculpt.core.calibration import load_profile

    path = args.profile or scene.machine_profile
    if path is None:
        return None
    if not os.path.isfile(path):
        raise ValueError(f"machine profile {path} does not exist (--profile or the scene's \"machine_profile\")")
    profile = load_profile(path)
    say("profile", f"{profile.get('name') or os.path.basename(path)} ({path})")
    return profile


def machine_model(args, say):
    """The profile whose spring-back line models the machine for the preview (--machine-model),
    or None (the run's profile itself); ValueError naming the file when it cannot be used."""
    from wiresculpt.core.calibration import load_profile

    if not args.machine_model:
        return None
    if not os.path.isfile(args.machine_model):
        raise ValueError(f"machine model {args.machine_model} does not exist (--machine-model: a machine profile "
                         "JSON whose spring-back line the preview uses)")
    model = load_profile(args.machine_model)
    say("machine model", f"{model.get('name') or os.path.basename(args.machine_model)} ({args.machine_model})")
    return model


def write_fabrication(design, out, say, profile=None, machine=None):
    """svg/, dxf/, templates/, gcode/, bends/ and bendlist/ in `out` for every wire with a rest shape; the programs'
    summary goes into the design as `fabrication`."""
    from wiresculpt.core import sizes
    from wiresculpt.core.calibration import closed_overlap
    from wiresculpt.fab import export, pieces

    if not any("rest" in w for w in design["wires"]):
        return  # no folders: the earlier run's are removed with the rest of its set
    start = time.perf_counter()
    # wires longer than the profile's stock: the pieces the files are made of (fab/pieces.py)
    pieces.apply(design, sizes.stock(profile or {})[0], closed_overlap(profile), export.machine_profile(design, profile)[0])
    result = export.export(design, out, profile, machine=machine)
    # the predicted polylines stay in the templates; the design keeps each wire's preview distance (m)
    design["fabrication"] = {"wires": [{k: v for k, v in w.items() if k != "predicted"} for w in result["wires"]],
                             "errors": result["errors"], "preview_model": result["preview_model"]}
    minutes = sum(w["machine_seconds"] for w in result["wires"]) / 60
    say("fabrication", f"{len(result['wires'])} bend programs ({sum(w['bend_count'] for w in result['wires'])} "
                       f"bends, about {minutes:.0f} min on the machine), {len(result['files'])} files in svg/, dxf/, templates/, "
                       f"gcode/, bends/, bendlist/ ({time.perf_counter() - start:.3f} s)")
    if result["wires"]:
        worst = max(result["wires"], key=lambda w: w["preview_distance"])
        say("fabrication", f"predicted wires within {worst['preview_distance'] * 1000:.1f} mm of the rest shapes "
                           f"(largest: {worst['name']}; spring-back {result['preview_model']})")
    for error in result["errors"]:
        say("fabrication", error)


def run(argv):
    from wiresculpt.core import staging
    from wiresculpt.core.meshcheck import check_output_folder

    def say(stage, message):
        print(f"wiresculpt: {stage}: {message}", flush=True)

    args = parse_args(argv)
    check_output_folder(args.out)  # before any work: a full solve must not end in "cannot write"
    # One writer per folder, from before the solve to the end (a second run is refused at once);
    # a folder made for a run that is refused is removed again.
    with staging.claim(args.out):
        staging.check_kinds(args.out, OUTPUT_FILES, OUTPUT_FOLDERS)
        return _run(args, say)


def _run(args, say):
    import bpy

    from wiresculpt import native, plane_search
    from wiresculpt.core.calibration import closed_overlap
    from wiresculpt.core.design import write_design
    from wiresculpt.core.meshcheck import check_vertices
    from wiresculpt.core.staging import staged
    from wiresculpt.core.scene import load_scene
    from wiresculpt.core import sizes
    from wiresculpt.blend.mesh import close_for_slicing, import_mesh
    from wiresculpt.core import mesh_faults

    scene = load_scene(args.scene)
    native.require()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    start = time.perf_counter()
    V, F, objects = import_mesh(scene.mesh)
    check_vertices(V, scene.mesh, scene.size)  # NaN/inf, magnitudes, millimetres, before scaling
    factor = 1.0
    if scene.size is not None:
        extent = sizes.mesh_size(V)
        if extent <= 0:
            raise ValueError(f"mesh file {scene.mesh} has no extent to scale to size {scene.size} m")
        factor = scene.size / extent
        V = V * factor
    say("mesh", f"{len(V)} vertices, {len(F)} triangles, scale x{factor:g} "
                f"({time.perf_counter() - start:.3f} s)")
    start = time.perf_counter()  # an open or many-part mesh is closed for slicing (design.json: mesh_closing)
    V, F, closing = close_for_slicing(V, F, scene.settings["min_segment"])
    if closing is not None:
        say("mesh", f"{mesh_faults.closing_sentence(closing)} ({time.perf_counter() - start:.3f} s)")
    planes = scaled_planes(scene.planes, factor)
    profile = machine_profile(scene, args, say)  # refused before the long work when it is wrong
    model = machine_model(args, say)
    stock = None if profile is None else sizes.stock(profile)
    # settings.plane_search "off" is pipeline.run; "nearby"/"auto" return the planes actually used
    design, planes = plane_search.run(V, F, planes, scene.material, scene.settings, say, stock=stock)
    if closing is not None:  # the plane search's own designs do not go through pipeline.slice_and_pick
        design.setdefault("mesh_closing", closing)
    # Everything is written into a hidden folder first and replaces the earlier run's outputs
    # only when all of it is there: a failure half-way leaves the earlier set as it was.
    with staged(args.out, OUTPUTS) as folder:
        write_fabrication(design, folder, say, profile, model)
        write_design(os.path.join(folder, "design.json"), design)
        write_scene_outputs(design, objects, planes, factor, folder, say,
                            closed_overlap(profile))  # the guide says how the loops close
    say("written", os.path.join(args.out, "design.json"))
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
