"""The scene file reader: every bad input gets one message naming the key at fault."""
import json
import os
import tempfile
import unittest

from wiresculpt.core import contours
from wiresculpt.core.scene import load_scene, parse_scene

GOOD = {"mesh": "m.obj", "planes": [{"name": "A", "origin": [0, 0, 0], "normal": [0, 0, 2]}]}


class SceneTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "scene.json")
        open(os.path.join(self.dir.name, "m.obj"), "w").close()

    def tearDown(self):
        self.dir.cleanup()

    def parse(self, **changes):
        data = json.loads(json.dumps(GOOD))
        data.update(changes)
        return parse_scene(data, self.path)

    def assertRefused(self, fragment, **changes):
        with self.assertRaises(ValueError) as ctx:
            self.parse(**changes)
        self.assertIn(fragment, str(ctx.exception))

    def test_defaults(self):
        s = self.parse()
        self.assertEqual(s.mesh, os.path.join(self.dir.name, "m.obj"))
        self.assertIsNone(s.size)
        self.assertEqual(s.material["name"], "steel")
        self.assertEqual(s.material["bending_stiffness"], 0.73)
        self.assertEqual(s.planes[0].contours, "largest")
        self.assertEqual(s.settings["min_segment"], 0.015)

    def test_unknown_keys_are_named(self):
        self.assertRefused('"colour"', colour=1)
        self.assertRefused('"nromal"', planes=[{"origin": [0, 0, 0], "normal": [0, 0, 1], "nromal": 1}])
        self.assertRefused('"tolerance"', settings={"tolerance": 1})
        self.assertRefused('"k_b"', material={"wire_diameter": 0.003, "k_b": 1})

    def test_planes(self):
        self.assertRefused('planes[0].normal', planes=[{"origin": [0, 0, 0], "normal": [0, 0, 0]}])
        self.assertRefused('planes[1].origin', planes=[GOOD["planes"][0], {"normal": [1, 0, 0]}])
        self.assertRefused('planes[0].origin[2]', planes=[{"origin": [0, 0, "x"], "normal": [0, 0, 1]}])
        self.assertRefused('"planes"', planes=[])
        self.assertRefused('used by two planes', planes=[GOOD["planes"][0], GOOD["planes"][0]])
        self.assertRefused('planes[0].contours', planes=[{"origin": [0, 0, 0], "normal": [0, 0, 1], "contours": "most"}])
        self.assertRefused('planes[0].contours[1]', planes=[{"origin": [0, 0, 0], "normal": [0, 0, 1], "contours": [0, -1]}])

    def test_numbers(self):
        self.assertRefused('planes[0].origin[0]', planes=[{"origin": [float("nan"), 0, 0], "normal": [0, 0, 1]}])
        self.assertRefused('"size"', size=-1)
        self.assertRefused('"size"', size=True)
        self.assertRefused('"size"', size=1e300)
        self.assertRefused('planes[0].normal[1]', planes=[{"origin": [0, 0, 0], "normal": [0, 1e308 * 10, 1]}])
        self.assertRefused('settings.min_segment', settings={"min_segment": 0})

    def test_load_factor_and_torque_fraction(self):
        s = self.parse()
        self.assertEqual(s.settings["load_factor"], 3.0)
        self.assertIsNone(s.settings["torque_fraction"])  # chosen by the load factor
        s = self.parse(settings={"torque_fraction": 0.3, "load_factor": 5})
        self.assertEqual((s.settings["torque_fraction"], s.settings["load_factor"]), (0.3, 5.0))
        self.assertRefused('settings.load_factor', settings={"load_factor": 0})
        self.assertRefused('settings.load_factor', settings={"load_factor": "3"})
        self.assertRefused('settings.torque_fraction', settings={"torque_fraction": 1.5})

    def test_search_knobs(self):
        # beyond the FORMATS contract (docs/formats.md): in_plane_tiebreak (bool), max_nodes and relayer_rounds (integers).
        s = self.parse()
        self.assertEqual((s.settings["in_plane_tiebreak"], s.settings["max_nodes"], s.settings["relayer_rounds"]),
                         (False, 200000, 8))
        s = self.parse(settings={"in_plane_tiebreak": True, "max_nodes": 0, "relayer_rounds": 3})
        self.assertEqual((s.settings["in_plane_tiebreak"], s.settings["max_nodes"], s.settings["relayer_rounds"]),
                         (True, 0, 3))
        self.assertIs(type(s.settings["max_nodes"]), int)
        self.assertRefused('"settings.in_plane_tiebreak" must be true or false', settings={"in_plane_tiebreak": 1})
        self.assertRefused('"settings.max_nodes" must be a whole number', settings={"max_nodes": 1.5})
        self.assertRefused('"settings.max_nodes" must be a whole number', settings={"max_nodes": True})
        self.assertRefused('"settings.max_nodes" must be at least 0', settings={"max_nodes": -1})
        self.assertRefused('"settings.relayer_rounds" must be at most 100', settings={"relayer_rounds": 101})

    def test_material(self):
        self.assertEqual(self.parse(material="brass").material["max_torque"], 1.30)
        self.assertRefused('preset "gold"', material="gold")
        self.assertRefused('material.friction', material={"wire_diameter": 0.003, "bending_stiffness": 1, "max_torque": 1})
        custom = self.parse(material={"name": "piano", "wire_diameter": 0.002, "bending_stiffness": 0.2,
                                      "max_torque": 0.5, "friction": 0.3})
        self.assertEqual(custom.material["name"], "piano")

    def test_mesh(self):
        self.assertRefused('file not found', mesh="missing.obj")
        data = dict(GOOD)
        del data["mesh"]
        with self.assertRaises(ValueError) as ctx:
            parse_scene(data, self.path)
        self.assertIn('"mesh" is missing', str(ctx.exception))

    def test_json_syntax_error_names_the_line(self):
        with open(self.path, "w") as f:
            f.write('{\n "mesh": "m.obj",\n "planes": [\n}\n')
        with self.assertRaises(ValueError) as ctx:
            load_scene(self.path)
        self.assertIn("line 4", str(ctx.exception))


class PickTest(unittest.TestCase):
    def test_rules(self):
        found = ["a", "b", "c"]
        self.assertEqual(contours.pick(found, "largest"), [0])
        self.assertEqual(contours.pick(found, "all"), [0, 1, 2])
        self.assertEqual(contours.pick(found, [2, 0, 2]), [2, 0])
        self.assertEqual(contours.pick([], "largest"), [])
        with self.assertRaises(ValueError) as ctx:
            contours.pick(found, [3], "B")
        self.assertIn("plane B: contour index 3 does not exist", str(ctx.exception))
        with self.assertRaises(ValueError) as ctx:  # the plane moved off the mesh: said as such
            contours.pick([], [0], "B")
        self.assertEqual(str(ctx.exception), "plane B cuts no contour of the mesh now (contour index 0 does not exist)")


if __name__ == "__main__":
    unittest.main()
