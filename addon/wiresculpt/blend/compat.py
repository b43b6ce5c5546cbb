"""Every place where Blender's API differs between the versions we test (3.4 Debian, 4.2 LTS, the
newest release for Python 3.11), chosen by feature (does the operator, shader or property exist),
never by version number. The rest of the add-on asks here instead of testing `bpy.app.version`.
"""
import bpy

SIDEBAR_TAB = "Wire"  # bl_category of every wiresculpt panel


def has_operator(group, name):
    """True when bpy.ops.<group>.<name> exists: bpy.ops resolves names lazily (hasattr is always
    true); dir() lists the real ones."""
    return name in dir(getattr(bpy.ops, group))


# --- mesh importers: the C++ ones (wm.*_import) replaced the Python add-ons (OBJ 3.x, PLY 4.0,
# STL 4.2) and the old ones are gone from newer versions. Coordinates as written in the file. ---

def import_obj(path):
    if has_operator("wm", "obj_import"):
        return bpy.ops.wm.obj_import(filepath=path, forward_axis="Y", up_axis="Z")
    return bpy.ops.import_scene.obj(filepath=path, axis_forward="Y", axis_up="Z", split_mode="OFF")


def import_stl(path):
    if has_operator("wm", "stl_import"):
        return bpy.ops.wm.stl_import(filepath=path, global_scale=1.0, use_scene_unit=False,
                                     forward_axis="Y", up_axis="Z")
    return bpy.ops.import_mesh.stl(filepath=path, axis_forward="Y", axis_up="Z", global_scale=1.0,
                                   use_scene_unit=False)


def import_ply(path):
    if has_operator("wm", "ply_import"):
        return bpy.ops.wm.ply_import(filepath=path, global_scale=1.0, use_scene_unit=False,
                                     forward_axis="Y", up_axis="Z")
    return bpy.ops.import_mesh.ply(filepath=path)


IMPORTERS = {".obj": import_obj, ".stl": import_stl, ".ply": import_ply}


# --- GPU: the flat-colour built-in shader is 'UNIFORM_COLOR' from 3.4 on; the '3D_' names were
# deprecated (a printed warning) and then removed in 4.0. ---

def uniform_colour_shader():
    import gpu

    try:
        return gpu.shader.from_builtin('UNIFORM_COLOR')
    except (ValueError, TypeError):  # a Blender that knows only the 3D_ name
        return gpu.shader.from_builtin('3D_UNIFORM_COLOR')


def smooth_colour_shader():
    """The built-in per-vertex colour shader ('SMOOTH_COLOR'; '3D_SMOOTH_COLOR' where only that
    name is known), as uniform_colour_shader."""
    import gpu

    try:
        return gpu.shader.from_builtin('SMOOTH_COLOR')
    except (ValueError, TypeError):
        return gpu.shader.from_builtin('3D_SMOOTH_COLOR')


def font_size(font, size):
    """blf.size of `font` in pixels: without the dpi argument where Blender dropped it (4.0 on),
    with 72 dpi where it is still asked for."""
    import blf

    try:
        blf.size(font, size)
    except TypeError:
        blf.size(font, size, 72)


# --- the sidebar's active tab: Region.active_panel_category is writable from 4.x on (read-only
# or missing before). ---

def can_set_sidebar_tab():
    prop = bpy.types.Region.bl_rna.properties.get("active_panel_category")
    return prop is not None and not prop.is_readonly


def show_wire_tab(screens=None):
    """Makes the Wire tab the active one in the sidebar of every 3D view of `screens` (default:
    every screen of the file) and shows the sidebar there; returns how many sidebars it set, 0
    where the API cannot set the tab."""
    if not can_set_sidebar_tab():
        return 0
    count = 0
    for screen in (bpy.data.screens if screens is None else screens):
        for area in screen.areas:
            if area.type != 'VIEW_3D':
                continue
            for region in area.regions:
                if region.type != 'UI':
                    continue
                try:
                    region.active_panel_category = SIDEBAR_TAB
                except (TypeError, ValueError, AttributeError):
                    continue
                area.spaces.active.show_region_ui = True
                count += 1
    return count
