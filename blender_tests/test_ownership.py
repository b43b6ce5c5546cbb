"""Nothing leaks between files or scenes: the plane assistant's candidates are
the file's and scene's they were made for. Each file here has the same scene name ("Scene") and the
same slicing planes ("Slice A".."Slice E", the hinged globe of helpers.hinge_scene), so a result
keyed by names alone would be listed and applied in the other file.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- ownership
"""
import os
import tempfile

import bpy

from wiresculpt import native
from wiresculpt.blend import ownership
from wiresculpt.blend import results as scene_results
from wiresculpt.core import session
from wiresculpt.fab import streaming
from wiresculpt.operators import plane_search as ops
from wiresculpt.ui import plane_search as panel

from helpers import BlenderCase as Case
from helpers import draw, hinge_scene, placements


def panel_texts():
    return [kw.get("text", "") for _name, _a, kw in draw(panel.VIEW3D_PT_wiresculpt_planes, bpy.context)]


def listed(texts):
    """The candidates the panel offers to apply."""
    return [t for t in texts if t.startswith("Apply candidate")]


class NothingLeaks(Case):
    def setUp(self):
        super().setUp()
        if not native.available():
            self.skipTest(native.LOAD_ERROR)
        ops.RESULT = None
        ops.PREVIEW = None
        self.folder = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.folder.cleanup()
        super().tearDown()

    def search(self):
        """The hinged globe searched in the open file: its candidates listed and previewable."""
        hinge_scene()
        self.assertEqual(bpy.ops.wiresculpt.find_planes(), {'FINISHED'})
        self.assertIsNotNone(ops.current(bpy.context))
        self.assertTrue(listed(panel_texts()))
        self.assertTrue(ops.preview_candidate(bpy.context, 0))
        self.assertEqual(ops.previewed(bpy.context), 0)

    def assert_nothing_to_show_or_apply(self):
        scene = bpy.context.scene
        self.assertEqual(scene.name, "Scene")  # the same name as the searched file's scene
        self.assertIsNone(ops.current(bpy.context))
        self.assertEqual(listed(panel_texts()), [])
        self.assertIsNone(ops.previewed(bpy.context))
        self.assertFalse(ops.WIRESCULPT_OT_preview_planes.poll(bpy.context))
        before = placements()
        with self.assertRaises(ops.Refused) as ctx:
            ops.apply_candidate(bpy.context, 0)
        self.assertIn(ctx.exception.code, (ops.NO_RESULT, ops.NOT_THIS_SCENE))
        # the button's operator: cancelled with the refusal's sentence (an ERROR report, which
        # bpy.ops raises), and the scene as it was
        with self.assertRaises(RuntimeError) as op:
            bpy.ops.wiresculpt.apply_planes(index=0)
        self.assertIn("Cannot apply: " + ops.refusal(ctx.exception.code), str(op.exception))
        self.assertEqual(placements(), before)
        self.assertNotIn(scene_results.DESIGN_TEXT, bpy.data.texts)

    def test_file_new_forgets_the_candidates(self):
        self.search()
        bpy.ops.wm.read_homefile(use_empty=True)
        hinge_scene()  # the same planes in the new file: Apply could write the old file's design
        self.assert_nothing_to_show_or_apply()

    def test_opening_a_file_forgets_the_candidates(self):
        path = os.path.join(self.folder.name, "other.blend")
        hinge_scene()
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.read_homefile(use_empty=True)
        self.search()
        bpy.ops.wm.open_mainfile(filepath=path)
        self.assert_nothing_to_show_or_apply()

    def test_reopening_the_searched_file_forgets_them_too(self):
        """The token is saved with the file, but the result was the closed session's."""
        path = os.path.join(self.folder.name, "searched.blend")
        self.search()
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        self.assertIsNone(ops.RESULT)
        self.assert_nothing_to_show_or_apply()

    def test_a_search_that_ends_after_a_load_is_dropped(self):
        hinge_scene()
        job = ops.SearchJob("nearby", *ops.gather(bpy.context), 5)
        job.scene_name = bpy.context.scene.name
        job.run()
        self.assertTrue(job.found)
        bpy.ops.wm.read_homefile(use_empty=True)  # the file closes while the worker still runs
        hinge_scene()
        self.assertIsNone(ops._store(job))
        self.assert_nothing_to_show_or_apply()

    def test_another_scene_named_like_the_searched_one_sees_nothing(self):
        self.search()
        searched = bpy.context.scene
        searched.name = "Searched"
        other = bpy.data.scenes.new("Scene")
        bpy.context.window.scene = other
        hinge_scene()
        self.assert_nothing_to_show_or_apply()
        bpy.context.window.scene = searched  # and the searched scene still has its candidates
        self.assertIsNone(ops.current(bpy.context))  # renamed: another scene now
        searched.name = "Scene.searched"
        self.assertEqual(other.name, "Scene")

    def test_a_full_copy_of_the_scene_sees_nothing(self):
        self.search()
        searched = bpy.context.scene
        self.assertEqual(bpy.ops.scene.new(type='FULL_COPY'), {'FINISHED'})
        copy = bpy.context.scene
        self.assertNotEqual(copy, searched)
        self.assertEqual(copy.get(ownership.TOKEN_PREFIX + ops.OWNER_KIND),
                         searched.get(ownership.TOKEN_PREFIX + ops.OWNER_KIND))  # the token came along
        self.assertIsNone(ops.current(bpy.context))
        self.assertEqual(listed(panel_texts()), [])
        bpy.context.window.scene = searched
        self.assertIsNotNone(ops.current(bpy.context))
        self.assertTrue(listed(panel_texts()))

    def test_the_stream_stops_are_forgotten_on_load(self):
        streaming.PENDING["Slice A/0"] = "a stop of the closed file"
        streaming.LAST["Slice A/0"] = ({'ERROR'}, "the closed file's last run")
        generation = session.generation()
        bpy.ops.wm.read_homefile(use_empty=True)
        self.assertEqual(streaming.PENDING, {})
        self.assertEqual(streaming.LAST, {})
        self.assertGreater(session.generation(), generation)

    def test_a_stream_that_ends_after_a_load_records_nothing(self):
        import numpy as np

        square = np.array([[0, 0], [0.05, 0], [0.05, 0.05], [0, 0.05]], dtype=float)
        lines = native.stream_lines(native.write_gcode(None, square, {}, "Slice A/0", "steel"))
        profile = native.validate_machine_profile({})

        def dry_run():
            return streaming.StreamJob("Slice A/0", "/dev/null-port", lines, profile, {}, dry_run=True)

        job = dry_run()
        job.run()
        streaming.finish(job)  # in the file it started from: its last run is shown
        self.assertIn("Slice A/0", streaming.LAST)
        job = dry_run()
        bpy.ops.wm.read_homefile(use_empty=True)  # the file closes while the stream runs
        job.run()
        self.assertEqual(streaming.finish(job)[0], {'INFO'})
        self.assertEqual(streaming.LAST, {})
        self.assertEqual(streaming.PENDING, {})
