"""native.py, the one door: a wrapper for every function the module registers, each refusing a
bad array with ValueError before C++ (in the binding's words) and passing good input through."""
import os
import tempfile
import unittest

import numpy as np

from helpers import circle
from wiresculpt import native

# Module names whose wrapper has another name.
RENAMED = {"StreamControl": "stream_control", "SerialLink": "open_link", "Cancelled": "Cancelled"}
LINE = np.array([[0.0, 0.0], [0.05, 0.0], [0.1, 0.02]])


def wire(name, normal, key="points"):
    return {"name": name, "origin": [0, 0, 0], "normal": normal, key: circle(normal, n=32), "closed": True}


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Wrappers(unittest.TestCase):
    def test_every_module_function_has_a_wrapper(self):
        for name in dir(native.module):
            if name.startswith("_") or not callable(getattr(native.module, name)):
                continue
            with self.subTest(name):
                self.assertTrue(callable(getattr(native, RENAMED.get(name, name), None)), f"native.{name} is missing")

    def test_bad_arrays_are_refused_in_the_bindings_words(self):
        x, y = wire("X", [1, 0, 0]), wire("Y", [0, 1, 0])
        cases = [
            (lambda: native.layering([x, dict(y, points=np.zeros((5, 2)))]),
             "wires[1]['points']: expected an (n, 3) array of numbers, got shape (5, 2)"),
            (lambda: native.layering([x, dict(y, points=[["a", "b", "c"]])]),
             "wires[1]['points']: expected an (n, 3) array of numbers, got an array of <U1"),
            (lambda: native.optimize_target_shape(np.zeros((4, 3)), False, []),
             "points: expected an (n, 2) array of numbers, got shape (4, 3)"),
            (lambda: native.forces_and_rest([dict(wire("X", [1, 0, 0], "target"), target=np.zeros(3))], [], [], {}),
             "wires[0]['target']: expected an (n, 3) array of numbers, got shape (3,)"),
            (lambda: native.make_bend_program(np.zeros((3, 3))),
             "points: expected an (n, 2) array of numbers, got shape (3, 3)"),
            (lambda: native.check_assembly("X", [], []), "wires: expected a list, got str"),
            (lambda: native.plane_frame([0, 1]), "normal: expected 3 numbers, got shape (2,)"),
        ]
        for call, message in cases:
            with self.subTest(message):
                with self.assertRaises(ValueError) as ctx:
                    call()
                self.assertEqual(str(ctx.exception), message)

    def test_good_input_reaches_the_module(self):
        x, y, z = wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])
        r = native.layering([x, y, z])
        direct = native.module.layering([x, y, z])
        self.assertEqual(r["network"], direct["network"])
        self.assertEqual(r["hook"], direct["hook"])
        verdict = native.check_assembly([x, y, z], r["hook"], r["steps"])
        self.assertTrue(verdict["stable"])
        program, direct = native.make_bend_program(LINE.tolist()), native.module.make_bend_program(LINE)
        self.assertEqual(program["bends_deg"], direct["bends_deg"])
        np.testing.assert_array_equal(program["rebuilt"], direct["rebuilt"])
        self.assertEqual(native.default_machine_profile(), native.module.default_machine_profile())
        with tempfile.TemporaryDirectory() as out:
            path = os.path.join(out, "w.gcode")
            text = native.write_gcode(path, LINE, None, "X", "steel")
            with open(path) as f:
                self.assertEqual(f.read(), text)
            self.assertTrue(native.stream_lines(text))
            template = [{"name": "X", "points": LINE.tolist()}]
            self.assertIn("<svg", native.write_svg(None, template))
            self.assertIn("SECTION", native.write_dxf(None, template))
            self.assertIn("step", native.write_bend_table(None, LINE))
        control = native.stream_control()
        control.abort()
        self.assertTrue(control.aborted)

    def test_target_shapes_read_an_iterator_one_problem_at_a_time(self):
        # The stage hands over a generator that prepares each wire as it is read: the same results
        # as a list; the points may be lists (converted as each problem is read); an error raised
        # while making the next problem is the call's, with the other thread stopped.
        def ring(r, n):
            angle = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
            return [[r * np.cos(a), r * np.sin(a)] for a in angle]
        problems = [{"points": ring(0.05 + 0.02 * k, 40 + 20 * k), "closed": True,
                     "crossings": [{"vertex": 0, "bisector": (1.0, 0.0)}], "options": {"wire_name": f"W{k}"}}
                    for k in range(3)]
        read = []

        def made():
            for k, p in enumerate(problems):
                read.append(k)
                yield p
        listed = native.optimize_target_shapes(problems)
        for threads in (1, 2):
            read.clear()
            fed = native.optimize_target_shapes(made(), None, threads)
            self.assertEqual(read, [0, 1, 2])
            self.assertEqual(len(fed), 3)
            for a, b in zip(listed, fed):
                np.testing.assert_array_equal(a["points"], b["points"])
                self.assertEqual(a["energy"], b["energy"])

        def failing():
            yield problems[0]
            raise RuntimeError("the next wire could not be prepared")
        with self.assertRaisesRegex(RuntimeError, "could not be prepared"):
            native.optimize_target_shapes(failing())
        self.assertEqual(len(native.optimize_target_shapes(iter(problems))), 3)  # the other thread is free again

    def test_a_target_shape_problem_with_a_plane_is_placed_and_measured_as_numpy_does(self):
        # The native places each result in space and measures it on the solving thread; it must give
        # what core.frames.to_3d and core.polylines.polyline_length (numpy) give, to the bit. Wires of fewer than 8 points, of 8-128 and of more than 128 (numpy
        # sums those in halves), open and closed, in tilted planes.
        from wiresculpt.core.frames import plane_frame, to_3d
        from wiresculpt.core.polylines import polyline_length

        def arc(r, n, closed):
            angle = np.linspace(0.0, (2.0 if closed else 1.2) * np.pi, n, endpoint=not closed)
            return np.column_stack([r * np.cos(angle), r * np.sin(angle)])
        cases = [(0.012, 12, True, [0.0, 0.0, 1.0]), (0.1, 60, False, [0.3, -0.5, 0.8]),
                 (0.45, 400, True, [1.0, 2.0, -0.5])]
        problems, frames = [], []
        for k, (r, n, closed, normal) in enumerate(cases):
            _n, u, v = plane_frame(normal)
            origin = [0.1 * k, -0.37, 1.3]
            frames.append((origin, u, v))
            problems.append({"points": arc(r, n, closed), "closed": closed,
                             "options": {"wire_name": f"P{k}", "min_segment": 0.01},
                             "plane": {"origin": origin, "u": u, "v": v}})
        for threads in (1, 2):
            results = native.optimize_target_shapes(iter(problems), None, threads)
            counts = []
            for problem, frame, r in zip(problems, frames, results):
                expected = to_3d(r["points"], *frame)
                self.assertIsInstance(r["target"], list)
                self.assertEqual(r["target"], expected.tolist())
                self.assertEqual(r["length"], polyline_length(expected, problem["closed"]))
                counts.append(len(r["points"]))
            self.assertLess(counts[0], 8)
            self.assertTrue(8 <= counts[1] <= 128 < counts[2], counts)
        plain = native.optimize_target_shapes([{k: v for k, v in problems[0].items() if k != "plane"}])[0]
        self.assertNotIn("target", plain)
        with self.assertRaisesRegex(ValueError, r"problems\[0\]\['plane'\]: the key 'v' is missing"):
            native.optimize_target_shapes([dict(problems[0], plane={"origin": [0, 0, 0], "u": [1, 0, 0]})])
        with self.assertRaisesRegex(ValueError, r"problems\[0\]\['plane'\]\['origin'\]\[2\]: expected a finite number"):
            native.optimize_target_shapes([dict(problems[0], plane={"origin": [0, 0, float("nan")], "u": [1, 0, 0],
                                                                    "v": [0, 1, 0]})])

    def test_target_shape_results_have_the_documented_keys_and_types(self):
        # The keys as the module's docstring lists them (the Python side reads them by name).
        result_keys = {"points", "crossing_vertices", "crossings", "max_distance", "rms_distance",
                       "min_segment", "max_bend", "max_length_violation", "max_angle_violation", "iterations",
                       "sweeps", "sqp_blocks", "sqp_fallbacks", "seconds", "nlopt_result", "energy", "feasible",
                       "warnings"}
        status_keys = {"status", "realised", "vertex", "bisector", "contact_angle", "contact_violation", "scale",
                       "message", "cause", "words"}
        angle = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
        ring = np.column_stack([0.1 * np.cos(angle), 0.1 * np.sin(angle)])
        crossings = [{"vertex": 0, "bisector": (1.0, 0.0)}, {"vertex": 20, "bisector": (1.0, 0.0)}]
        one = native.optimize_target_shape(ring, True, crossings, {"wire_name": "R"})
        both = native.optimize_target_shapes([{"points": ring, "closed": True, "crossings": crossings,
                                               "options": {"wire_name": "R"}}] * 2)
        for r in [one] + both:
            self.assertEqual(set(r), result_keys)
            self.assertEqual(r["points"].dtype, np.float64)
            self.assertEqual(r["points"].shape[1], 2)
            self.assertEqual(len(r["crossings"]), 2)
            for st in r["crossings"]:
                self.assertEqual(set(st), status_keys)
                self.assertIsInstance(st["status"], str)
                self.assertIsInstance(st["realised"], bool)
                self.assertIsInstance(st["vertex"], int)
                self.assertIsInstance(st["bisector"], tuple)
                self.assertEqual(len(st["bisector"]), 2)
                for key in ("contact_angle", "contact_violation", "scale"):
                    self.assertIsInstance(st[key], float)
                self.assertIsInstance(st["message"], str)
            self.assertIsInstance(r["crossing_vertices"], list)
            self.assertIsInstance(r["feasible"], bool)
            self.assertIsInstance(r["nlopt_result"], str)
            self.assertIsInstance(r["warnings"], list)
            for key in ("max_distance", "rms_distance", "min_segment", "max_bend", "max_length_violation",
                        "max_angle_violation", "energy", "seconds"):
                self.assertIsInstance(r[key], float)
            for key in ("iterations", "sweeps", "sqp_blocks", "sqp_fallbacks"):
                self.assertIsInstance(r[key], int)
        # Solved in a batch, each result is the wire's own (all but the clock).
        for r in both:
            np.testing.assert_array_equal(r["points"], one["points"])
            self.assertEqual({k: v for k, v in r.items() if k not in ("points", "seconds")},
                             {k: v for k, v in one.items() if k not in ("points", "seconds")})

    def test_plane_frame_is_right_handed_and_unit(self):
        n, u, v = native.plane_frame([0.0, 0.0, 2.0])
        np.testing.assert_allclose(n, [0, 0, 1])
        np.testing.assert_allclose(np.cross(u, v), n, atol=1e-15)
        self.assertAlmostEqual(float(u @ n), 0.0)
        with self.assertRaises(ValueError):
            native.plane_frame([0.0, 0.0, 0.0])


if __name__ == "__main__":
    unittest.main()
