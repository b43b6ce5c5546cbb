"""The add-on's slicing stage inside Blender: handles, the Slice operator, the panel.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- addon_slicing
"""
import contextlib
import math
import types
import unittest

import bmesh
import bpy
from mathutils import Matrix, Vector

import wiresculpt
from wiresculpt import native
from wiresculpt.blend import contours as blend_contours
from wiresculpt.blend import handles as blend_handles
from wiresculpt.live import engine as live
from wiresculpt.operators import slicing
from wiresculpt.ui import panel

from helpers import BlenderCase, FakeLayout, clear_scene, draw, register_addon, save_and_reload


def uv_sphere(radius=1.0, location=(0, 0, 0)):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=radius,
                                         location=location)
    return bpy.context.object


def run(operator_class, context=None):
    """(result, reports) of the operator's execute, reports as [(type, message)]."""
    reports = []
    fake = types.SimpleNamespace(report=lambda kind, message: reports.append((kind, message)))
    result = operator_class.execute(fake, context or bpy.context)
    return result, reports


def add_handle(location, rotation=(0, 0, 0)):
    assert bpy.ops.wiresculpt.add_plane() == {'FINISHED'}
    handle = bpy.context.view_layer.objects.active
    handle.location = location
    handle.rotation_euler = rotation
    return handle


def slice_scene():
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}
    bpy.context.view_layer.update()


def plane_distance(handle, centre):
    """Distance from `centre` to the handle's plane (world location, world Z axis)."""
    bpy.context.view_layer.update()
    M = handle.matrix_world
    return M.col[2].xyz.normalized().dot(M.translation - Vector(centre))


def circle_length(radius, distance):
    return 2 * math.pi * math.sqrt(radius * radius - distance * distance)


def items_of(plane):
    return [item for item in bpy.context.scene.wiresculpt.contours if item.plane == plane]


def contour_objects():
    return [o for o in bpy.data.objects if blend_contours.CONTOUR_KEY in o]


class AddonCase(BlenderCase):
    def assertLengthNear(self, actual, expected, rel=0.01):
        self.assertLess(abs(actual - expected), rel * expected,
                        f"length {actual:.6f} differs from {expected:.6f} by more than {rel:.0%}")


@unittest.skipUnless(native.available(), "the native module is not built")
class SliceSphere(AddonCase):
    R = 1.0
    CENTRE = (0.3, -0.2, 0.5)

    def three_planes(self):
        sphere = uv_sphere(self.R, self.CENTRE)
        bpy.context.scene.wiresculpt.model = sphere
        c = Vector(self.CENTRE)
        a = add_handle(c)
        b = add_handle(c + Vector((0, 0, 0.5)))
        tilt = Matrix.Rotation(0.4, 3, 'X') @ Matrix.Rotation(-0.7, 3, 'Y')
        n = tilt.col[2]
        d = add_handle(c + 0.6 * n + 0.2 * tilt.col[0], tilt.to_euler())
        return sphere, (a, b, d)

    def test_three_planes_three_circles(self):
        _sphere, handles = self.three_planes()
        self.assertEqual([h.name for h in handles], ["Slice A", "Slice B", "Slice C"])
        slice_scene()
        contours = bpy.context.scene.wiresculpt.contours
        self.assertEqual(len(contours), 3)
        for handle in handles:
            (item,) = items_of(handle.name)
            d = plane_distance(handle, self.CENTRE)
            self.assertLengthNear(item.length, circle_length(self.R, d))
            self.assertTrue(item.closed)
            self.assertTrue(item.use)
            curve = item.curve
            self.assertIsNotNone(curve)
            self.assertEqual(curve.type, 'CURVE')
            self.assertIn(curve.name, bpy.data.collections[blend_contours.CONTOURS_COLLECTION].objects)
            (spline,) = curve.data.splines
            self.assertEqual(spline.type, 'POLY')
            self.assertTrue(spline.use_cyclic_u)
            n = handle.matrix_world.col[2].xyz.normalized()
            for point in list(spline.points)[::17]:
                p = curve.matrix_world @ point.co.xyz
                self.assertAlmostEqual(n.dot(p - handle.matrix_world.translation), 0, places=4)
                self.assertAlmostEqual((p - Vector(self.CENTRE)).length, self.R, delta=2e-3)
        self.assertEqual(len(contour_objects()), 3)
        for handle in handles:  # handles are never sliced themselves
            self.assertNotIn(blend_contours.CONTOUR_KEY, handle)

    def test_reslice_updates_same_objects(self):
        _sphere, (a, b, c) = self.three_planes()
        slice_scene()
        before = {o.name: o.as_pointer() for o in contour_objects()}
        b.location.z = self.CENTRE[2] - 0.8
        slice_scene()
        after = {o.name: o.as_pointer() for o in contour_objects()}
        self.assertEqual(before, after)
        self.assertEqual(len([o for o in bpy.data.objects if o.type == 'CURVE']), 3)
        (item,) = items_of(b.name)
        self.assertLengthNear(item.length, circle_length(self.R, 0.8))
        self.assertEqual(item.curve.as_pointer(), before[item.curve.name])
        length = sum((q.co.xyz - p.co.xyz).length for p, q in
                     zip(item.curve.data.splines[0].points,
                         list(item.curve.data.splines[0].points[1:]) +
                         [item.curve.data.splines[0].points[0]]))
        self.assertAlmostEqual(length, item.length, delta=1e-4)

    def test_handle_off_mesh_removes_its_curve(self):
        _sphere, (a, b, c) = self.three_planes()
        slice_scene()
        (old,) = items_of(b.name)
        old_name = old.curve.name
        b.location.z = self.CENTRE[2] + 5
        result, reports = run(slicing.WIRESCULPT_OT_slice)
        self.assertEqual(result, {'FINISHED'})
        self.assertIn(b.name, reports[-1][1])
        self.assertEqual(items_of(b.name), [])
        self.assertNotIn(old_name, bpy.data.objects)
        self.assertEqual(len(contour_objects()), 2)
        self.assertEqual(len(items_of(a.name)), 1)

    def test_modified_scaled_model_sliced_in_world_space(self):
        sphere = uv_sphere(self.R, (1.0, 2.0, -1.0))
        sphere.scale = (2, 2, 2)
        displace = sphere.modifiers.new("Grow", 'DISPLACE')
        displace.strength = 0.4  # no texture: every vertex moves 0.5 * strength along its normal
        radius = 2 * (self.R + 0.2)
        bpy.context.scene.wiresculpt.model = sphere
        self.assertEqual(bpy.ops.wiresculpt.add_plane(), {'FINISHED'})
        handle = bpy.context.view_layer.objects.active
        self.assertLess((handle.location - Vector((1, 2, -1))).length, 1e-4)  # world centre
        self.assertGreaterEqual(handle.dimensions.x, 2 * radius)  # covers the evaluated mesh
        handle.location.z = -1.0 + 1.5
        slice_scene()
        (item,) = items_of(handle.name)
        self.assertLengthNear(item.length, circle_length(radius, 1.5))

    def test_add_plane_at_model_centre(self):
        sphere = uv_sphere(0.5, (1, 2, 3))
        bpy.context.scene.wiresculpt.model = sphere
        result, _reports = run(slicing.WIRESCULPT_OT_add_plane)
        self.assertEqual(result, {'FINISHED'})
        handle = bpy.data.objects["Slice A"]
        self.assertTrue(handle[blend_handles.HANDLE_KEY])
        self.assertIn(handle.name, bpy.data.collections[blend_handles.PLANES_COLLECTION].objects)
        self.assertLess((handle.location - Vector((1, 2, 3))).length, 1e-5)
        self.assertEqual(handle.display_type, 'WIRE')
        self.assertEqual(handle.type, 'MESH')
        self.assertGreaterEqual(min(handle.dimensions.x, handle.dimensions.y), 1.0)
        self.assertEqual(bpy.context.view_layer.objects.active, handle)
        run(slicing.WIRESCULPT_OT_add_plane)
        self.assertIn("Slice B", bpy.data.objects)
        self.assertFalse(wiresculpt.props._poll_model(None, handle))
        self.assertTrue(wiresculpt.props._poll_model(None, sphere))


@unittest.skipUnless(native.available(), "the native module is not built")
class Ticks(AddonCase):
    def two_spheres(self):
        """One mesh of two spheres, radii 1 and 0.5, centres (0,0,0) and (3,0,0)."""
        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=128, v_segments=64, radius=1.0)
        bmesh.ops.create_uvsphere(bm, u_segments=128, v_segments=64, radius=0.5,
                                  matrix=Matrix.Translation((3, 0, 0)))
        mesh = bpy.data.meshes.new("Pair")
        bm.to_mesh(mesh)
        bm.free()
        obj = bpy.data.objects.new("Pair", mesh)
        bpy.context.scene.collection.objects.link(obj)
        bpy.context.scene.wiresculpt.model = obj
        return obj

    def test_longest_ticked_by_default(self):
        self.two_spheres()
        handle = add_handle((1.5, 0, 0))
        slice_scene()
        items = items_of(handle.name)
        self.assertEqual([i.index for i in items], [0, 1])
        self.assertLengthNear(items[0].length, 2 * math.pi)
        self.assertLengthNear(items[1].length, math.pi)
        self.assertEqual([i.use for i in items], [True, False])

    def test_user_ticks_survive_reslice(self):
        self.two_spheres()
        handle = add_handle((1.5, 0, 0))
        slice_scene()
        items = items_of(handle.name)
        items[0].use, items[1].use = False, True
        handle.location.z = 0.2
        slice_scene()
        items = items_of(handle.name)
        self.assertEqual([i.use for i in items], [False, True])
        self.assertLengthNear(items[1].length, circle_length(0.5, 0.2))
        self.assertEqual(len(contour_objects()), 2)

    def two_planes(self):
        """The pair sliced by Slice A (z = 0) and Slice B (y = 0), each cutting both spheres;
        Slice A's ticks set to its smaller contour only (not the default)."""
        self.two_spheres()
        a = add_handle((1.5, 0, 0))
        b = add_handle((1.5, 0, 0), rotation=(math.pi / 2, 0, 0))
        slice_scene()
        self.assertEqual((a.name, b.name), ("Slice A", "Slice B"))
        items = items_of("Slice A")
        self.assertEqual(len(items), 2)
        items[0].use, items[1].use = False, True
        return a, b

    def ticked(self):
        """{plane name: ticked indices} of ticked_planes."""
        depsgraph = bpy.context.evaluated_depsgraph_get()
        return {p.name: p.contours for p in blend_handles.ticked_planes(bpy.context.scene, depsgraph)}

    def test_ticks_follow_a_renamed_plane(self):
        a, _b = self.two_planes()
        before = live.snapshot(bpy.context.scene)
        a.name = "Front"  # as in the Outliner
        self.assertEqual(self.ticked(), {"Front": [1], "Slice B": [0]})
        self.assertNotEqual(live.snapshot(bpy.context.scene), before)  # Live solves again
        self.assertEqual([panel.contour_name(i) for i in bpy.context.scene.wiresculpt.contours][:2],
                         ["Front #0", "Front #1"])
        slice_scene()
        self.assertEqual(items_of("Slice A"), [])
        self.assertEqual([i.use for i in items_of("Front")], [False, True])
        self.assertEqual(self.ticked(), {"Front": [1], "Slice B": [0]})

    def test_a_new_plane_does_not_take_a_deleted_planes_ticks(self):
        a, _b = self.two_planes()
        bpy.data.objects.remove(a)
        with self.assertRaisesRegex(ValueError, "slicing plane Slice A of a ticked contour is gone"):
            self.ticked()
        c = add_handle((1.5, 0, 0))
        self.assertEqual(c.name, "Slice A")  # the first unused name
        with self.assertRaisesRegex(ValueError, "slicing plane Slice A of a ticked contour is gone"):
            self.ticked()
        slice_scene()
        self.assertEqual([i.use for i in items_of("Slice A")], [True, False])  # the default, not the old ticks
        self.assertEqual(self.ticked(), {"Slice A": [0], "Slice B": [0]})

    def test_a_plane_deleted_in_the_viewport_is_gone(self):
        a, b = self.two_planes()
        for obj in bpy.context.selected_objects:
            obj.select_set(False)
        a.select_set(True)
        self.assertEqual(bpy.ops.object.delete(), {'FINISHED'})  # it may linger outside the scene
        with self.assertRaisesRegex(ValueError, "slicing plane Slice A of a ticked contour is gone"):
            self.ticked()
        c = add_handle((1.5, 0, 0))
        slice_scene()
        self.assertEqual([i.use for i in items_of(c.name)], [True, False])
        self.assertEqual(self.ticked(), {b.name: [0], c.name: [0]})

    @contextlib.contextmanager
    def not_released_at_once(self):
        """Without the depsgraph handler that lets a deleted object go (operators/slicing.py)."""
        bpy.app.handlers.depsgraph_update_post.remove(slicing._release_deleted)
        try:
            yield
        finally:
            bpy.app.handlers.depsgraph_update_post.append(slicing._release_deleted)

    def delete_in_viewport(self, obj):
        for other in bpy.context.selected_objects:
            other.select_set(False)
        obj.select_set(True)
        self.assertEqual(bpy.ops.object.delete(), {'FINISHED'})

    def test_a_plane_deleted_in_the_viewport_does_not_stay_in_the_file(self):
        a, _b = self.two_planes()
        a.name = "Front"
        curve = items_of("Slice A")[1].curve
        curve_name = curve.name
        self.delete_in_viewport(a)
        self.delete_in_viewport(curve)
        items = items_of("Front")  # a deleted plane's items keep its last name, for the messages
        self.assertEqual(len(items), 2)
        self.assertTrue(all(i.plane_object is None and i.has_plane_object for i in items))
        self.assertIsNone(items[1].curve)
        self.assertEqual(bpy.data.objects["Front"].users, 0)  # nothing holds it: not saved
        with self.assertRaisesRegex(ValueError, "slicing plane Front of a ticked contour is gone"):
            self.ticked()
        save_and_reload()
        self.assertNotIn("Front", bpy.data.objects)
        self.assertNotIn(curve_name, bpy.data.objects)
        self.assertEqual([i.use for i in items_of("Front")], [False, True])
        with self.assertRaisesRegex(ValueError, "slicing plane Front of a ticked contour is gone"):
            self.ticked()

    def test_a_file_saved_with_a_deleted_plane_lets_it_go_on_loading(self):
        a, _b = self.two_planes()
        with self.not_released_at_once():  # as an earlier add-on
            self.delete_in_viewport(a)
            self.assertTrue(all(i.plane_object == a for i in items_of("Slice A")))
        save_and_reload()  # the file held it; loading lets it go
        self.assertEqual(bpy.data.objects["Slice A"].users, 0)
        self.assertTrue(all(i.plane_object is None for i in items_of("Slice A")))
        save_and_reload()
        self.assertNotIn("Slice A", bpy.data.objects)

    def test_undo_brings_a_deleted_plane_back_with_its_ticks(self):
        a, _b = self.two_planes()
        bpy.ops.ed.undo_push(message="two planes")
        with self.not_released_at_once():  # as in the viewport: the Delete's undo step comes first
            self.delete_in_viewport(a)
            bpy.ops.ed.undo_push(message="Delete")
        self.assertEqual(bpy.ops.ed.undo(), {'FINISHED'})
        a = bpy.data.objects["Slice A"]  # undo made the objects anew
        self.assertEqual(bpy.context.scene.objects.get("Slice A"), a)
        self.assertTrue(all(i.plane_object == a for i in items_of("Slice A")))
        self.assertEqual(self.ticked(), {"Slice A": [1], "Slice B": [0]})
        self.assertEqual(bpy.ops.ed.redo(), {'FINISHED'})
        self.assertNotIn("Slice A", bpy.context.scene.objects)
        self.assertTrue(all(i.plane_object is None for i in items_of("Slice A")))  # let go again
        self.assertEqual(bpy.data.objects["Slice A"].users, 0)

    def test_a_plane_linked_elsewhere_or_kept_is_not_released(self):
        a, _b = self.two_planes()
        a.use_fake_user = True  # the maker keeps it on purpose
        self.delete_in_viewport(a)
        self.assertTrue(all(i.plane_object == a for i in items_of("Slice A")))
        self.assertEqual(blend_contours.release_deleted(bpy.data.scenes), 0)

    def test_items_of_older_files_go_by_the_plane_name(self):
        a, _b = self.two_planes()
        for item in bpy.context.scene.wiresculpt.contours:  # as a file saved before the pointer
            item.property_unset("plane_object")
            item.property_unset("has_plane_object")
            self.assertIsNone(item.plane_object)  # (this read adds an empty property: harmless)
        self.assertEqual(self.ticked(), {"Slice A": [1], "Slice B": [0]})
        a.location.z = 0.2
        slice_scene()
        self.assertEqual([i.use for i in items_of("Slice A")], [False, True])
        self.assertTrue(all(i.plane_object == a and i.has_plane_object for i in items_of("Slice A")))


class Refusals(AddonCase):
    def test_no_model(self):
        for operator in (slicing.WIRESCULPT_OT_slice, slicing.WIRESCULPT_OT_add_plane):
            result, reports = run(operator)
            self.assertEqual(result, {'CANCELLED'})
            self.assertEqual(reports[-1][0], {'ERROR'})
            self.assertIn("model", reports[-1][1].lower())
        with self.assertRaisesRegex(RuntimeError, "model"):  # errors reach scripts, too
            bpy.ops.wiresculpt.slice()

    def test_no_handles(self):
        bpy.context.scene.wiresculpt.model = uv_sphere()
        result, reports = run(slicing.WIRESCULPT_OT_slice)
        self.assertEqual(result, {'CANCELLED'})
        self.assertIn("slicing plane", reports[-1][1].lower())

    @unittest.skipUnless(native.available(), "the native module is not built")
    def test_flat_handle_named(self):
        bpy.context.scene.wiresculpt.model = uv_sphere()
        add_handle((0, 0, 0))
        flat = add_handle((0, 0, 0.3))
        flat.scale.z = 0
        result, reports = run(slicing.WIRESCULPT_OT_slice)
        self.assertEqual(result, {'CANCELLED'})
        self.assertIn(flat.name, reports[-1][1])
        self.assertEqual(contour_objects(), [])

    def test_solver_error_reported(self):
        bpy.context.scene.wiresculpt.model = uv_sphere()
        add_handle((0, 0, 0))
        saved_module, saved_slice = native.module, native.slice_mesh

        def failing(*_args, **_kwargs):
            raise ValueError("plane Slice A: something the solver rejects")

        native.module, native.slice_mesh = native.module or object(), failing
        try:
            result, reports = run(slicing.WIRESCULPT_OT_slice)
        finally:
            native.module, native.slice_mesh = saved_module, saved_slice
        self.assertEqual(result, {'CANCELLED'})
        self.assertIn("Slice A", reports[-1][1])


def draw_panel():
    return draw(panel.VIEW3D_PT_wiresculpt, bpy.context)


class Registration(AddonCase):
    def test_classes_and_settings(self):
        for name in ("WIRESCULPT_OT_add_plane", "WIRESCULPT_OT_slice", "VIEW3D_PT_wiresculpt",
                     "WIRESCULPT_UL_contours"):
            self.assertTrue(hasattr(bpy.types, name), name)
        self.assertTrue(hasattr(bpy.context.scene, "wiresculpt"))
        self.assertEqual(panel.VIEW3D_PT_wiresculpt.bl_category, "Wire")
        for cls in (slicing.WIRESCULPT_OT_add_plane, slicing.WIRESCULPT_OT_slice):
            self.assertEqual(cls.bl_options, {'REGISTER', 'UNDO'})

    def test_every_property_has_a_tooltip(self):
        for cls in (wiresculpt.props.WiresculptSettings, wiresculpt.props.WiresculptContour):
            for prop in cls.bl_rna.properties:
                if prop.identifier in ("rna_type", "name"):
                    continue
                self.assertTrue(prop.description, f"{cls.__name__}.{prop.identifier}")
        length = wiresculpt.props.WiresculptContour.bl_rna.properties["length"]
        self.assertEqual((length.unit, length.subtype), ('LENGTH', 'DISTANCE'))

    def test_panel_and_list_draw(self):
        log = draw_panel()
        operators = [args[0] for name, args, _kw in log if name == "operator"]
        self.assertEqual(operators, ["wiresculpt.add_plane", "wiresculpt.slice"])
        self.assertIn("template_list", [name for name, _a, _k in log])
        settings = bpy.context.scene.wiresculpt
        item = settings.contours.add()
        item.plane, item.index, item.length, item.closed = "Slice A", 0, 1.25, True
        log = []
        panel.WIRESCULPT_UL_contours.draw_item(None, bpy.context, FakeLayout(log), settings,
                                                item, 0, settings, "active_contour")
        labels = [kw.get("text") for name, _a, kw in log if name == "label"]
        self.assertEqual(labels[0], "Slice A #0")
        self.assertIn("1.25", labels[1])
        self.assertIn("m", labels[1])

    def test_long_plane_names_show_in_full(self):
        """A plane name the sidebar would cut ("Meri…") is shown whole in the details box of the
        active contour, wrapped to lines that fit the region."""
        settings = bpy.context.scene.wiresculpt
        settings.contours.clear()
        name = "Meridian through both poles at ninety degrees"
        for k in range(2):
            item = settings.contours.add()
            item.plane, item.index, item.length, item.closed, item.use = name, k, 0.785, True, k == 1
        settings.active_contour = 1
        log = draw_panel()
        boxed = [kw.get("text") for method, _a, kw in log if method == "label"]
        text = " ".join(t for t in boxed if t)
        self.assertIn(f'Plane "{name}", contour 1', text)
        self.assertIn("ticked: it becomes a wire", text)
        width = panel.line_chars(bpy.context)
        for line in boxed:
            self.assertLessEqual(len(line or ""), max(20, int(width)), line)
        settings.active_contour = 0
        self.assertIn("not ticked", " ".join(kw.get("text") or "" for m, _a, kw in draw_panel() if m == "label"))
        # a row in Blender's default (narrow) sidebar: the name alone, the length is in the box
        import types
        for width, expected in ((200, 1), (400, 2)):
            log = []
            narrow = types.SimpleNamespace(region=types.SimpleNamespace(width=width), scene=bpy.context.scene)
            panel.WIRESCULPT_UL_contours.draw_item(None, narrow, FakeLayout(log), settings,
                                                    settings.contours[0], 0, settings, "active_contour")
            labels = [kw.get("text") for method, _a, kw in log if method == "label"]
            self.assertEqual(len(labels), expected, labels)
            self.assertEqual(labels[0], f"{name} #0")


class WithoutNative(AddonCase):
    """The add-on registers and explains itself when the compiled module is missing."""

    REASON = "the solver was removed for this test (no _wiresculpt here)"

    def setUp(self):
        self.saved = native.module, native.LOAD_ERROR
        native.module, native.LOAD_ERROR = None, self.REASON
        register_addon()
        clear_scene()

    def tearDown(self):
        native.module, native.LOAD_ERROR = self.saved

    def test_registers_and_slice_cancels_with_reason(self):
        self.assertTrue(hasattr(bpy.types, "WIRESCULPT_OT_slice"))
        bpy.context.scene.wiresculpt.model = uv_sphere()
        add_handle((0, 0, 0))
        result, reports = run(slicing.WIRESCULPT_OT_slice)
        self.assertEqual(result, {'CANCELLED'})
        self.assertEqual(reports[-1], ({'ERROR'}, self.REASON))
        with self.assertRaisesRegex(RuntimeError, "solver was removed"):
            bpy.ops.wiresculpt.slice()
        self.assertEqual(contour_objects(), [])

    def test_panel_explains(self):
        log = draw_panel()
        texts = " ".join(kw.get("text", "") for name, _a, kw in log if name == "label")
        self.assertIn("not loaded", texts)
        self.assertIn("no _wiresculpt here", texts)
        self.assertIn("box", [name for name, _a, _k in log])


if __name__ == "__main__":
    unittest.main()
