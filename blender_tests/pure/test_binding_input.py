"""Every binding reads its dicts and lists through one converter (native/python/convert.hpp): a
value of the wrong type or shape is a ValueError naming its path (key and index), an unknown key
is named with the keys that exist. One exact message per case, for each binding."""
import unittest

import numpy as np
from helpers import circle

from wiresculpt import native


def wire(name, normal, key="points"):
    return {"name": name, "origin": [0, 0, 0], "normal": normal, key: circle(normal)}


LINE = np.array([[0.0, 0.0], [0.05, 0.0], [0.1, 0.02]])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class BindingInput(unittest.TestCase):
    def check(self, call, message):
        with self.assertRaises(ValueError) as ctx:
            call()
        self.assertEqual(str(ctx.exception), message)

    def check_all(self, cases):
        for call, message in cases:
            with self.subTest(message):
                self.check(call, message)

    def test_layering(self):
        m = native.module
        x, y = wire("X", [1, 0, 0]), wire("Y", [0, 1, 0])
        cases = [
            (lambda: m.layering("X"), "wires: expected a list, got str"),
            (lambda: m.layering([x, 5]), "wires[1]: expected a dict, got int"),
            (lambda: m.layering([x, dict(y, origin=[0, 0])]), "wires[1]['origin']: expected 3 numbers, got list of 2"),
            (lambda: m.layering([x, dict(y, normal=[0, "1", 0])]), "wires[1]['normal'][1]: expected a number, got str"),
            (lambda: m.layering([x, dict(y, points=[["a", "b", "c"]])]),
             "wires[1]['points']: expected an (n, 3) array of numbers, got an array of <U1"),
            (lambda: m.layering([x, dict(y, closed=1)]), "wires[1]['closed']: expected True or False, got int"),
            (lambda: m.layering([x, dict(y, name="Y\ud800")]),
             "wires[1]['name']: expected a string of Unicode characters, got a str with a lone surrogate"),
            (lambda: m.layering([x, {k: v for k, v in y.items() if k != "points"}]),
             "wires[1]: the key 'points' is missing"),
            (lambda: m.layering([x, dict(y, colour="red")]),
             "wires[1]: unknown key 'colour' (expected name, origin, normal, closed, points)"),
            (lambda: m.layering([x, y], {"min_segment": "abc"}), "settings['min_segment']: expected a number, got str"),
            (lambda: m.layering([x, y], {1: 0.3}), "settings: keys must be strings, got int 1"),
            (lambda: m.layering([x, y], {"max_nodes": 10 ** 20}),
             "settings['max_nodes']: expected an integer from -9223372036854775808 to 9223372036854775807, "
             "got 100000000000000000000"),
            (lambda: m.check_assembly([x, y], [1, "-1"], [[0, 1]]), "hooks[1]: expected an integer, got str"),
        ]
        self.check_all(cases)

    def test_forces(self):
        m = native.module
        wires = [wire("X", [1, 0, 0], "target"), wire("Y", [0, 1, 0], "target")]
        cases = [
            (lambda: m.forces_and_rest(wires, [], [], {"friction": "0.3"}),
             "material['friction']: expected a number, got str"),
            (lambda: m.forces_and_rest(wires, [], [], {"colour": 1}),
             "material: unknown key 'colour' (expected bending_stiffness, max_torque, friction, wire_diameter, "
             "density, shear_modulus, name)"),
            (lambda: m.forces_and_rest(wires, [], [], {}, {"algorithm": "newton"}),
             "settings['algorithm']: expected one of 'lp_then_slsqp', 'lp', 'slsqp', got 'newton'"),
            (lambda: m.forces_and_rest(wires, [], [], {}, {"max_iterations": 2.5}),
             "settings['max_iterations']: expected an integer, got float"),
            (lambda: m.forces_and_rest([wires[0], dict(wires[1], cut="3")], [], [], {}),
             "wires[1]['cut']: expected an integer, got str"),
            (lambda: m.forces_and_rest(wires, [{"wires": [0], "vertices": [0, 0]}], [], {}),
             "crossings[0]['wires']: expected two wire ids, got 1"),
            (lambda: m.forces_and_rest(wires, [{"wires": [0, 1], "vertices": [0, 0], "hook": None}], [], {}),
             "crossings[0]['hook']: expected an integer, got None"),
            (lambda: m.forces_and_rest(wires, [], [[0, 1], 2], {}), "steps[1]: expected a list, got int"),
        ]
        self.check_all(cases)

    def test_target_shape(self):
        m = native.module
        cases = [
            (lambda: m.optimize_target_shape(LINE[:, :1], False, []),
             "points: expected an (n, 2) array of numbers, got shape (3, 1)"),
            (lambda: m.optimize_target_shape(LINE, "no", []), "closed: expected True or False, got str"),
            (lambda: m.optimize_target_shape(LINE, False, [{"vertex": 1, "bisector": [0, 1, 0]}]),
             "crossings[0]['bisector']: expected 2 numbers, got list of 3"),
            (lambda: m.optimize_target_shape(LINE, False, [{"bisector": [0, 1]}]),
             "crossings[0]: the key 'vertex' is missing"),
            (lambda: m.optimize_target_shape(LINE, False, [], {"max_sweeps": "many"}),
             "options['max_sweeps']: expected an integer, got str"),
            (lambda: m.optimize_target_shape(LINE, False, [], {"min_segment": float("inf")}),
             "options['min_segment']: expected a finite number, got inf"),
            (lambda: m.optimize_target_shapes([{"points": LINE, "closed": False}, {"points": LINE}]),
             "problems[1]: the key 'closed' is missing"),
            (lambda: m.optimize_target_shapes([{"points": LINE, "closed": False, "crossings": [{"bisector": [0, 1]}]}]),
             "problems[0]['crossings'][0]: the key 'vertex' is missing"),
            (lambda: m.optimize_target_shapes([{"points": LINE, "closed": False, "options": {"window": "8"}}]),
             "problems[0]['options']['window']: expected an integer, got str"),
            (lambda: m.optimize_target_shapes([{"points": LINE, "closed": False, "start": []}]),
             "problems[0]: unknown key 'start' (expected points, closed, crossings, options, plane)"),
            (lambda: m.optimize_target_shapes([], None, 3), "target shapes: threads must be 1 or 2"),
        ]
        self.check_all(cases)

    def test_fabrication(self):
        m = native.module
        template = {"name": "A", "points": LINE, "bend_points": [1], "crossing_points": []}
        cases = [
            (lambda: m.make_bend_program("abc", {}), "points: expected an (n, 2) array of numbers, got an array of <U3"),
            (lambda: m.make_bend_program(LINE, [1]), "profile: expected a dict, got list"),
            (lambda: m.make_bend_program(LINE, {"stop_bits": "2"}), "profile['stop_bits']: expected an integer, got str"),
            (lambda: m.write_svg(None, [dict(template, bend_points=[-1])]),
             "wires[0]['bend_points'][0]: expected an integer from 0 to 9223372036854775807, got -1"),
            (lambda: m.write_dxf(None, [dict(template, points=LINE.tolist() + [[1.0]])]),
             "wires[0]['points']: expected an (n, 2) array of numbers, got list"),
            (lambda: m.write_svg(None, [template], None, {"margin_mm": "5"}),
             "options['margin_mm']: expected a number, got str"),
            (lambda: m.stream_program("/dev/null", [], {}, {"next_line": -1}, dry_run=True),
             "state['next_line']: expected an integer from 0 to 9223372036854775807, got -1"),
        ]
        self.check_all(cases)

    def test_slicing(self):
        m = native.module
        V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
        F = np.array([[0, 1, 2]], dtype=np.int32)
        self.check(lambda: m.slice_mesh(V, F, [("a", (0, 0, 0))]), "planes[0]: expected (name, origin, normal), got 2 items")
        self.check(lambda: m.slice_mesh(V, F, [(1, (0, 0, 0), (0, 0, 1))]), "planes[0][0]: expected a string, got int")
        # a bad origin or normal is named with its plane's name
        good = ("Z0", (0, 0, 0), (0, 0, 1))
        self.check(lambda: m.slice_mesh(V, F, [good, ("Z1", (0, 0, float("nan")), (0, 0, 1))]),
                   "planes[1] (plane 'Z1') origin[2]: expected a finite number, got nan")
        self.check(lambda: m.slice_mesh(V, F, [("Y", (0, 0, 0), (0, 1))]),
                   "planes[0] (plane 'Y') normal: expected 3 numbers, got tuple of 2")

    def test_good_values_of_other_types_still_read(self):
        """numpy scalars and tuples are numbers and vectors; a numpy bool is a bool."""
        m = native.module
        x = dict(wire("X", [1, 0, 0]), origin=(np.float32(0), 0, np.int64(0)), closed=np.bool_(True))
        r = m.layering([x, wire("Y", [0, 1, 0])], {"max_nodes": np.int32(1000), "friction": np.float64(0.3)})
        self.assertEqual(len(r["network"]["crossings"]), 2)


if __name__ == "__main__":
    unittest.main()
