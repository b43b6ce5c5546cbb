"""Sanity before work: the scene, the mesh file and the output folder are checked before
anything is solved, each problem one sentence naming the file, line, vertex or key
(core/meshcheck.py, core/scene.py). Expected messages are written out by hand."""
import json
import os
import tempfile
import unittest

import numpy as np

from wiresculpt.core import meshcheck, scene as scene_file

CUBE_V = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"


class MeshChecks(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def file(self, name, data):
        path = os.path.join(self.tmp.name, name)
        with open(path, "wb") as f:
            f.write(data if isinstance(data, bytes) else data.encode())
        return path

    def test_obj_faces_naming_missing_vertices_are_counted(self):
        path = self.file("m.obj", CUBE_V + "f 1 2 3\nf 1 2 9\nf 1 -7 3\nf 2/1 3/1 4/1\nf 0 1 2\n")
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_obj(path)
        self.assertEqual(str(ctx.exception), f"mesh file {path}: 3 faces name vertices that do not exist "
                                             "(the first at line 6); fix the file's face indices")
        # relative (negative) indices and v/vt/vn tokens that exist are fine
        meshcheck.check_obj(self.file("ok.obj", CUBE_V + "f 1 2 3\nf -1 -2 -3\nf 2/1/1 3//2 4/1\n"))

    def test_ply_with_a_lying_header_is_one_sentence(self):
        header = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n" \
                 "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
        path = self.file("m.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_ply(path)
        self.assertEqual(str(ctx.exception), f"mesh file {path}: its PLY header declares 10 rows "
                                             "(8 vertex, 2 face) but the file holds 4")
        binary = header.replace("ascii", "binary_little_endian").encode() + b"\0" * 20
        path = self.file("b.ply", binary)
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_ply(path)
        self.assertEqual(str(ctx.exception), f"mesh file {path}: its PLY header declares at least 98 bytes of data "
                                             "but the file holds 20")  # 8 x 12 + 2 list lengths
        meshcheck.check_ply(self.file("ok.ply", header.replace("vertex 8", "vertex 3").replace("face 2", "face 1")
                                      + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"))

    def test_vertices_named_by_index_and_millimetres(self):
        V = np.array([[0, 0, 0], [1, 0, 0], [np.nan, 0, 0], [0, np.inf, 0]])
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_vertices(V, "m.obj", 0.2)  # with size too: not blamed on a plane
        self.assertEqual(str(ctx.exception), "mesh vertex 2 has a non-finite coordinate (NaN or Inf)")
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_vertices(np.array([[0, 0, 0], [0, 0, -3e9]]), "m.obj", 0.2)
        self.assertEqual(str(ctx.exception), "mesh vertex 1 is at 3e+09 from the origin, beyond 1e+09: mesh file "
                                             "m.obj does not hold a model's coordinates")
        mm = np.array([[0, 0, 0], [250, 120, 80]])
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_vertices(mm, "duck.obj", None)
        self.assertEqual(str(ctx.exception), 'your mesh looks like millimetres: mesh file duck.obj is 250 units '
                                             'across, read as metres that is over 10 m; set "size" to the '
                                             "sculpture's size in metres")
        self.assertTrue(meshcheck.check_vertices(mm, "duck.obj", 0.25))  # with size it is scaled
        self.assertTrue(meshcheck.check_vertices(mm / 1000, "duck.obj", None))

    def test_output_folder_before_any_work(self):
        base = self.tmp.name
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_output_folder(os.fsdecode(os.path.join(base, "out\xff").encode("latin-1")))
        self.assertEqual(str(ctx.exception), f"--out {base}/out\\xff: the folder name is not UTF-8; choose a name "
                                             "in UTF-8")
        a_file = self.file("taken", "x")
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_output_folder(a_file)
        self.assertEqual(str(ctx.exception), f"--out {a_file}: exists and is not a folder")
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_output_folder(os.path.join(a_file, "out"))
        self.assertEqual(str(ctx.exception), f"--out {a_file}/out: cannot be created, {a_file} is not a folder")
        meshcheck.check_output_folder(os.path.join(base, "new", "deeper"))
        self.assertEqual(sorted(os.listdir(base)), ["taken"])  # nothing was created


class SceneChecks(unittest.TestCase):
    def test_a_latin1_scene_names_its_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "scène.json")
            with open(path, "wb") as f:
                f.write('{"mesh": "café.obj", "planes": []}'.encode("latin-1"))
            with self.assertRaises(ValueError) as ctx:
                scene_file.load_scene(path)
            self.assertEqual(str(ctx.exception), f"scene file {path} is not UTF-8 text (byte 0xe9 at offset 13); "
                                                 "save it as UTF-8")

    def test_plane_count_is_capped(self):
        with tempfile.TemporaryDirectory() as tmp:
            with open(os.path.join(tmp, "m.obj"), "w") as f:
                f.write(CUBE_V + "f 1 2 3\n")
            planes = [{"origin": [0, 0, 0], "normal": [0, 0, 1], "name": f"P{i}"} for i in range(65)]
            with self.assertRaises(ValueError) as ctx:
                scene_file.parse_scene({"mesh": "m.obj", "planes": planes}, os.path.join(tmp, "scene.json"))
            self.assertEqual(str(ctx.exception), 'scene key "planes" has 65 planes; at most 64 are allowed')
            scene_file.parse_scene({"mesh": "m.obj", "planes": planes[:64]}, os.path.join(tmp, "scene.json"))


if __name__ == "__main__":
    unittest.main()
