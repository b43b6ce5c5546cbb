"""Open and many-part meshes closed for slicing (blend/mesh.close_for_slicing): a sphere with a hole
punched at its pole slices to the contours of the whole sphere within the remesh's voxel (the
Hausdorff distance of the polylines, measured here); two overlapping boxes slice to one contour per
plane, the outline of their union; the figures said are the mesh's, counted by construction; the
user's mesh object is never changed; the batch says what it did and records it.
    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- mesh_closing"""
import json
import os
import re
import tempfile
import unittest

import bpy
import numpy as np

from helpers import BATCH, BlenderCase, add_handle, box_faces, box_vertices, draw, mesh_model, run_blender, sphere, write_obj
from wiresculpt import native
from wiresculpt.blend import mesh
from wiresculpt.blend import results as scene_results
from wiresculpt.ui import results as ui_results
from wiresculpt.core import mesh_faults

RADIUS, SEGMENTS = 0.2, 48
MIN_SEGMENT = 0.015  # the settings' default l_min
# the closing voxel by the rule of core/mesh_faults.py, worked by hand: the smaller of 1 % of the
# model's size and a quarter of l_min (3.75 mm), never under 1/256 of the size
SPHERE_VOXEL = min(0.01 * 2 * RADIUS, 0.25 * MIN_SEGMENT)  # 3.75 mm at 0.4 m
BOXES_VOXEL = min(0.01 * 0.3, 0.25 * MIN_SEGMENT)         # 3 mm at 0.3 m


def punched_sphere():
    """(closed V, F, punched F): helpers.sphere whose first SEGMENTS triangles (the fan round the
    north pole) are taken out: one hole of SEGMENTS boundary edges, the pole vertex left unused."""
    V, F = sphere(RADIUS, SEGMENTS, 24)
    return V, F, F[SEGMENTS:]


def overlapping_boxes():
    """Box A [0, 0.2]^3 and box B [0.1, 0.3] x [0.05, 0.25] x [0.05, 0.25], one mesh of two parts."""
    a = box_vertices((0.0, 0.0, 0.0), (0.2, 0.2, 0.2))
    b = box_vertices((0.1, 0.05, 0.05), (0.3, 0.25, 0.25))
    F = np.array(box_faces())
    return np.array(a + b, dtype=float), np.concatenate([F, F + 8])


# the outline of the union in the plane z = 0.15 (x, y), by hand
UNION_XY = np.array([(0, 0), (0.2, 0), (0.2, 0.05), (0.3, 0.05), (0.3, 0.25), (0.1, 0.25), (0.1, 0.2), (0, 0.2)])


def samples(points, closed, step=0.0005):
    """Points along the polyline every `step` m or closer (its vertices included)."""
    P = np.asarray(points, dtype=float)
    if closed:
        P = np.vstack([P, P[:1]])
    out = [P[:1]]
    for a, b in zip(P[:-1], P[1:]):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        out.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    return np.vstack(out)


def to_polyline(points, P, closed):
    """m: the largest distance from `points` to the segments of the polyline P."""
    P = np.asarray(P, dtype=float)
    if closed:
        P = np.vstack([P, P[:1]])
    a, b = P[:-1], P[1:]
    d = b - a
    worst = 0.0
    for chunk in np.array_split(points, max(1, len(points) // 500)):
        t = np.clip(np.einsum("psk,sk->ps", chunk[:, None, :] - a[None], d) / np.maximum((d * d).sum(1), 1e-300),
                    0.0, 1.0)
        nearest = a[None] + t[..., None] * d[None]
        worst = max(worst, float(np.sqrt(((chunk[:, None, :] - nearest) ** 2).sum(-1)).min(1).max()))
    return worst


def hausdorff(A, closed_a, B, closed_b):
    """m: the Hausdorff distance of two polylines, both ways, over dense samples."""
    return max(to_polyline(samples(A, closed_a), B, closed_b), to_polyline(samples(B, closed_b), A, closed_a))


def area_2d(P):
    x, y = np.asarray(P, dtype=float).T
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


SPHERE_PLANES = [("X", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),     # through the hole
                 ("Y", (0.0, 0.01, 0.0), (0.0, 1.0, 0.0)),    # through the hole
                 ("Z", (0.0, 0.0, 0.1), (0.0, 0.0, 1.0))]     # below it
BOX_PLANES = [("Z", (0.0, 0.0, 0.15), (0.0, 0.0, 1.0)), ("X", (0.15, 0.0, 0.0), (1.0, 0.0, 0.0)),
              ("Y", (0.0, 0.15, 0.0), (0.0, 1.0, 0.0))]


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Closing(BlenderCase):
    def setUp(self):
        super().setUp()
        mesh._closings.clear()
        mesh_faults._memo.clear()

    def test_a_punched_sphere_slices_like_the_whole_one(self):
        V, F, punched = punched_sphere()
        whole = native.slice_mesh(V, F, SPHERE_PLANES)["contours"]
        Vc, Fc, record = mesh.close_for_slicing(V, punched, MIN_SEGMENT)
        self.assertEqual((record["boundary_edges"], record["holes"]), (SEGMENTS, 1))
        self.assertEqual((record["shells"], record["shells_after"], record["nonmanifold_edges"]), (1, 1, 0))
        self.assertAlmostEqual(record["voxel"], SPHERE_VOXEL, places=12)
        self.assertEqual(record["triangles"], len(Fc))
        self.assertEqual(mesh_faults.check(Vc, Fc), [])  # one closed part
        closed = native.slice_mesh(Vc, Fc, SPHERE_PLANES)["contours"]
        opened = native.slice_mesh(V, punched, SPHERE_PLANES)["contours"]
        for (name, _o, _n), a, b, o in zip(SPHERE_PLANES, whole, closed, opened):
            with self.subTest(name):
                self.assertEqual(len(a), 1)
                self.assertEqual(len(b), 1)
                self.assertTrue(b[0]["closed"])
                self.assertLessEqual(hausdorff(a[0]["points"], True, b[0]["points"], True), SPHERE_VOXEL)
                if name != "Z":  # the test can tell: the open mesh's contour misses the hole's arc
                    worst = max(hausdorff(a[0]["points"], True, c["points"], c["closed"]) for c in o)
                    self.assertGreater(worst, 3 * SPHERE_VOXEL)

    def test_two_overlapping_boxes_slice_to_one_contour_per_plane(self):
        V, F = overlapping_boxes()
        apart = native.slice_mesh(V, F, BOX_PLANES)["contours"]
        self.assertEqual([len(c) for c in apart], [2, 2, 2])  # each box its own contour
        Vc, Fc, record = mesh.close_for_slicing(V, F, MIN_SEGMENT)
        self.assertEqual((record["shells"], record["shells_after"], record["boundary_edges"]), (2, 1, 0))
        self.assertEqual((record["lost"], record["lost_at"]), (0.0, None))  # the corners inside the other box are not lost
        self.assertAlmostEqual(record["voxel"], BOXES_VOXEL, places=12)
        closed = native.slice_mesh(Vc, Fc, BOX_PLANES)["contours"]
        self.assertEqual([len(c) for c in closed], [1, 1, 1])
        outline = np.asarray(closed[0][0]["points"])[:, :2]
        self.assertLessEqual(hausdorff(outline, True, UNION_XY, True), BOXES_VOXEL)
        perimeter = 2 * (0.3 + 0.25)
        self.assertLess(abs(area_2d(outline) - 0.065), perimeter * BOXES_VOXEL / 2)  # 0.04 + 0.04 - 0.1 x 0.15

    def test_a_rod_thinner_than_the_voxel_stays_and_is_not_lost(self):
        """Blender's remesh keeps a part thinner than its voxel as a tube about a voxel thick (a
        limb is not dropped): the rod's tip is still within a voxel of the closed surface."""
        V, F = overlapping_boxes()
        box = V[:8] * 1.5  # [0, 0.3]^3
        rod = np.array(box_vertices((0.1, 0.1, 0.3), (0.101, 0.101, 0.4)))  # 1 mm thick, 100 mm up from the top
        V, F = np.concatenate([box, rod]), np.concatenate([F[:12], F[:12] + 8])
        Vc, Fc, record = mesh.close_for_slicing(V, F, MIN_SEGMENT)
        self.assertAlmostEqual(record["voxel"], min(0.01 * 0.4, 0.25 * MIN_SEGMENT), places=12)
        self.assertEqual((record["shells"], record["shells_after"], record["lost"]), (2, 1, 0.0))
        self.assertGreater(Vc[:, 2].max(), 0.4 - record["voxel"])
        cut = native.slice_mesh(Vc, Fc, [("Z", (0.0, 0.0, 0.35), (0.0, 0.0, 1.0))])["contours"][0]
        self.assertEqual(len(cut), 1)  # the rod's own small contour
        centre = np.asarray(cut[0]["points"]).mean(axis=0)
        np.testing.assert_allclose(centre[:2], (0.1005, 0.1005), atol=record["voxel"])

    def test_a_closed_mesh_is_sliced_as_it_is(self):
        V, F = sphere(RADIUS)
        Vc, Fc, record = mesh.close_for_slicing(V, F, MIN_SEGMENT)
        self.assertIsNone(record)
        self.assertIs(Vc, V)
        self.assertIs(Fc, F)

    def test_slice_says_what_it_did_and_leaves_the_mesh_object_alone(self):
        V, _F, punched = punched_sphere()
        obj = mesh_model("punched", V, punched)
        me = obj.data
        for rotation in ((0, 0, 0), (0, np.pi / 2, 0)):
            add_handle(rotation, location=(0.0, 0.0, 0.1))
        before = np.empty(3 * len(me.vertices))
        me.vertices.foreach_get("co", before)
        meshes = set(bpy.data.meshes)
        mesh_objects = {o for o in bpy.data.objects if o.type == 'MESH'}
        reports = []
        from wiresculpt.blend.contours import slice_scene
        kind, text = slice_scene(bpy.context)
        reports.append(text)
        self.assertEqual(kind, {'INFO'}, text)
        said = re.search(r"closed (\d+) boundary edges \((\d+) hole\) by a (\d+) mm voxel remesh", text)
        self.assertIsNotNone(said, text)
        self.assertEqual((int(said[1]), int(said[2]), int(said[3])), (SEGMENTS, 1, round(SPHERE_VOXEL * 1000)))
        after = np.empty(3 * len(me.vertices))
        me.vertices.foreach_get("co", after)
        self.assertTrue(np.array_equal(before, after))
        self.assertEqual((len(me.vertices), len(me.polygons)), (len(V), len(punched)))
        self.assertIs(obj.data, me)
        self.assertEqual(len(obj.modifiers), 0)
        self.assertEqual(set(bpy.data.meshes), meshes)  # the temporary mesh is gone
        self.assertEqual({o for o in bpy.data.objects if o.type == 'MESH'}, mesh_objects)
        contours = bpy.context.scene.wiresculpt.contours
        self.assertTrue(all(item.closed for item in contours))
        # Optimize slices the closed mesh too, records it, and the Stability box says it
        assert bpy.ops.wiresculpt.optimize() in ({'FINISHED'}, {'CANCELLED'})
        design = scene_results.stored_design()
        self.assertIsNotNone(design)
        self.assertEqual((design["mesh_closing"]["boundary_edges"], design["mesh_closing"]["holes"]), (SEGMENTS, 1))
        lines = [" ".join(str(a) for a in args) + str(kwargs.get("text", ""))
                 for _m, args, kwargs in draw(ui_results.VIEW3D_PT_wiresculpt_report, bpy.context)]
        shown = " ".join(lines)  # the box wraps its lines
        self.assertRegex(shown, rf"Mesh: closed {SEGMENTS} boundary edges \(1 hole\) by a 4 mm voxel remesh")
        after = np.empty(3 * len(me.vertices))
        me.vertices.foreach_get("co", after)
        self.assertTrue(np.array_equal(before, after))
        # the results' own meshes (crossing markers) are used by their objects; a left-over
        # temporary mesh would have no user
        self.assertTrue(all(m.users > 0 for m in set(bpy.data.meshes) - meshes))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class BatchSaysIt(unittest.TestCase):
    def test_the_batch_closes_an_open_mesh_and_records_it(self):
        V, _F, punched = punched_sphere()
        with tempfile.TemporaryDirectory() as tmp:
            write_obj(os.path.join(tmp, "punched.obj"), V.tolist(), punched.tolist())
            planes = [{"name": n, "origin": list(o), "normal": list(v)} for n, o, v in SPHERE_PLANES]
            scene = os.path.join(tmp, "scene.json")
            with open(scene, "w") as f:
                json.dump({"mesh": "punched.obj", "planes": planes}, f)
            out = os.path.join(tmp, "out")
            r = run_blender(BATCH, scene, "--out", out)
            self.assertIn(r.returncode, (0, 2), r.stdout + r.stderr)
            said = re.search(r"wiresculpt: mesh: closed (\d+) boundary edges \((\d+) hole\) by a (\d+) mm voxel", r.stdout)
            self.assertIsNotNone(said, r.stdout)
            self.assertEqual((int(said[1]), int(said[2]), int(said[3])), (SEGMENTS, 1, round(SPHERE_VOXEL * 1000)))
            with open(os.path.join(out, "design.json")) as f:
                design = json.load(f)
        record = design["mesh_closing"]
        self.assertEqual(record["cause"], mesh_faults.CLOSED)
        self.assertEqual((record["boundary_edges"], record["holes"], record["shells"]), (SEGMENTS, 1, 1))
        self.assertAlmostEqual(record["voxel"], SPHERE_VOXEL, places=12)
        self.assertEqual(design["mesh_faults"], [])  # the closed mesh's: one closed part
        self.assertTrue(all(w["closed"] for w in design["wires"]))

    def test_the_batch_records_it_for_a_design_the_plane_search_proposes(self):
        V, _F, punched = punched_sphere()
        with tempfile.TemporaryDirectory() as tmp:
            write_obj(os.path.join(tmp, "punched.obj"), V.tolist(), punched.tolist())
            scene = os.path.join(tmp, "scene.json")
            with open(scene, "w") as f:
                json.dump({"mesh": "punched.obj", "planes": [], "settings": {"plane_search": "auto", "plane_count": 3}}, f)
            out = os.path.join(tmp, "out")
            r = run_blender(BATCH, scene, "--out", out)
            self.assertIn(r.returncode, (0, 2), r.stdout + r.stderr)
            with open(os.path.join(out, "design.json")) as f:
                design = json.load(f)
        self.assertEqual((design["mesh_closing"]["boundary_edges"], design["mesh_closing"]["holes"]), (SEGMENTS, 1))


if __name__ == "__main__":
    unittest.main()
