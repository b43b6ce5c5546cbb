"""blend.compat on the running Blender: the mesh importers it picks read each format, and a saved
design reopens with the sidebar on the Wire tab where the API allows setting it (4.x)."""
import os
import tempfile
import unittest

import bpy

from wiresculpt.blend import compat
from wiresculpt.blend.mesh import import_mesh

from helpers import BlenderCase, box_faces, box_vertices, write_obj, write_ply, write_stl


def sidebar_tabs():
    """The active tab of every 3D view's sidebar in the open file."""
    return [region.active_panel_category for screen in bpy.data.screens for area in screen.areas
            if area.type == 'VIEW_3D' for region in area.regions if region.type == 'UI']


class Importers(BlenderCase):
    def test_each_format_reads_the_box_as_written(self):
        V = box_vertices((0.0, 0.0, 0.0), (1.0, 2.0, 3.0))
        for ext, writer in ((".obj", write_obj), (".stl", write_stl), (".ply", write_ply)):
            with self.subTest(format=ext), tempfile.TemporaryDirectory() as folder:
                path = os.path.join(folder, "box" + ext)
                writer(path, V, box_faces())
                Vs, Fs, _objects = import_mesh(path)
                self.assertEqual(len(Fs), 12, f"{ext}: {len(Fs)} triangles read")
                self.assertEqual(tuple(Vs.max(axis=0)), (1.0, 2.0, 3.0), f"{ext}: axes converted")


class SidebarTab(BlenderCase):
    def test_a_saved_design_reopens_on_the_wire_tab(self):
        if not compat.can_set_sidebar_tab():
            self.skipTest(f"Blender {bpy.app.version_string}: the sidebar's active tab cannot be set "
                          "from Python (Region.active_panel_category)")
        bpy.ops.mesh.primitive_cube_add()
        bpy.context.scene.wiresculpt.model = bpy.context.view_layer.objects.active
        self.assertTrue(sidebar_tabs(), "the file has no 3D view sidebar")
        if set(sidebar_tabs()) == {"UNSUPPORTED"}:
            self.skipTest("a sidebar has tabs only once drawn, and a background Blender draws none "
                          "(Region.active_panel_category is 'UNSUPPORTED'): needs a 4.x Blender "
                          "with a window")
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "sculpture.blend")
            bpy.ops.wm.save_as_mainfile(filepath=path)
            bpy.ops.wm.read_homefile(use_empty=True)
            bpy.ops.wm.open_mainfile(filepath=path)
            self.assertEqual(set(sidebar_tabs()), {compat.SIDEBAR_TAB})

    def test_a_file_without_a_design_keeps_its_tab(self):
        if not compat.can_set_sidebar_tab():
            self.skipTest(f"Blender {bpy.app.version_string}: the sidebar's active tab cannot be set "
                          "from Python (Region.active_panel_category)")
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "plain.blend")
            bpy.ops.wm.save_as_mainfile(filepath=path)
            bpy.ops.wm.open_mainfile(filepath=path)
            self.assertNotIn(compat.SIDEBAR_TAB, sidebar_tabs())


if __name__ == "__main__":
    unittest.main()


class OldModelProperty(BlenderCase):
    """A .blend saved while the model's property was named `target` opens with it as `model`."""

    def save_with_old_pointer(self, folder, obj, model=None):
        """Saves the scene with the pointer written by hand under the old name (an ID IDProperty,
        what a PointerProperty named `target` stored) and returns the file's path."""
        settings = bpy.context.scene.wiresculpt
        settings.model = model
        settings["target"] = obj
        path = os.path.join(folder, "old.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        return path

    def test_the_old_target_pointer_becomes_the_model_once(self):
        bpy.ops.mesh.primitive_uv_sphere_add()
        name = bpy.context.view_layer.objects.active.name
        with tempfile.TemporaryDirectory() as folder:
            path = self.save_with_old_pointer(folder, bpy.context.view_layer.objects.active)
            bpy.ops.wm.read_homefile(use_empty=True)
            bpy.ops.wm.open_mainfile(filepath=path)
        settings = bpy.context.scene.wiresculpt
        self.assertIsNotNone(settings.model)
        self.assertEqual(settings.model.name, name)
        self.assertNotIn("target", settings.keys())
        settings.model = None  # read once: clearing the model afterwards is not undone
        from wiresculpt import props
        props.adopt_old_models()
        self.assertIsNone(settings.model)

    def test_a_model_already_picked_wins(self):
        bpy.ops.mesh.primitive_uv_sphere_add()
        old = bpy.context.view_layer.objects.active
        bpy.ops.mesh.primitive_cube_add()
        new = bpy.context.view_layer.objects.active
        names = old.name, new.name
        with tempfile.TemporaryDirectory() as folder:
            path = self.save_with_old_pointer(folder, old, model=new)
            bpy.ops.wm.open_mainfile(filepath=path)
        settings = bpy.context.scene.wiresculpt
        self.assertEqual(settings.model.name, names[1])
        self.assertNotIn("target", settings.keys())

    def test_enabling_the_add_on_reads_the_old_pointer_of_the_open_file(self):
        bpy.ops.mesh.primitive_uv_sphere_add()
        obj = bpy.context.view_layer.objects.active
        from wiresculpt import props
        settings = bpy.context.scene.wiresculpt
        settings.model = None
        settings["target"] = obj
        props.adopt_old_models()  # what register does for the file already open
        self.assertEqual(settings.model, obj)
        self.assertNotIn("target", settings.keys())
