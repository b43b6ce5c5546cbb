"""The 3D check shown where people look: the as-built ghosts (ui/overlay.as_built_shown, drawn by
the overlay), their toggle and the assembly slider, the distance ramp, the slipping crossings'
marks, the sag per wire in the Stability box, and Live's 3D line.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- as_built
"""
import math
import unittest

import bpy
import numpy as np

from wiresculpt import native
from wiresculpt.blend import results as scene_results
from wiresculpt.core import as_built_view, standing
from wiresculpt.live import engine as live
from wiresculpt.live.state import STATE
from wiresculpt.operators import optimize
from wiresculpt.ui import overlay, panel
from wiresculpt.ui import results as results_ui

from helpers import BlenderCase as Case
from helpers import draw, globe


def labels(log):
    return [kw.get("text", "") for name, _a, kw in log if name == "label"]


def text_of(log):
    """The panel's labels joined (wrap_labels splits a sentence over several)."""
    return " ".join(labels(log))


def walked(wire):
    """The target point of each as-built point, by hand: a closed wire of n target points is walked
    from its cut c as c, c+1, ..., n-1, 0, ..., c (n+1 points); an open one 0..n-1."""
    target = wire["target"]
    n = len(target)
    if not wire["closed"]:
        return [target[i] for i in range(n)]
    c = wire["cut"]
    return [target[(c + k) % n] for k in range(n + 1)]


def hand_segments(points):
    """[(a, b)] of consecutive points, as an open polyline's segments."""
    return [(points[i], points[i + 1]) for i in range(len(points) - 1)]


def small_design(**extra):
    """Two open wires of three target points each, with as-built shapes moved by known amounts, one
    hooked crossing that slips (admissible false) and one that holds; two assembly steps."""
    return {"format": "wiresculpt-design", "material": {"wire_diameter": 0.002},
            "wires": [{"id": 0, "name": "A/0", "closed": False, "cut": -1, "plane": {"normal": [0, 0, 1]},
                       "target": [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]],
                       "as_built": [[0, 0, 0], [0.1, 0, 0.001], [0.2, 0, 0.004]], "sag": 0.004},
                      {"id": 1, "name": "B/0", "closed": False, "cut": -1, "plane": {"normal": [1, 0, 0]},
                       "target": [[0.1, -0.1, 0], [0.1, 0, 0], [0.1, 0.1, 0]],
                       "as_built": [[0.1, -0.1, 0], [0.1, 0, 0.001], [0.1, 0.1, 0.0005]], "sag": 0.001}],
            "crossings": [{"id": 0, "wires": [0, 1], "point": [0.1, 0, 0], "vertices": [1, 1], "hook": 1,
                           "admissible": False, "force_3d": [0, 0, 1]},
                          {"id": 1, "wires": [0, 1], "point": [0.1, 0, 0], "vertices": [1, 1], "hook": -1,
                           "admissible": True, "force_3d": [0, 0, 1]}],
            "stands_3d": {"stands": False, "cause": "slips", "sag_limit": 0.002, "max_sag": 0.004,
                          "max_sag_wire": "A/0", "slipping": [0], "tilt_deg": 0.0},
            "assembly_steps": [[0], [1]], "stable": True, "reason": "", "stages": {}, **extra}


class Ramp(Case):
    def test_colour_of_a_distance_by_hand(self):
        blue, yellow, red = (0.10, 0.35, 1.00, 1.0), (1.00, 0.85, 0.00, 1.0), (1.00, 0.10, 0.10, 1.0)
        limit = 0.002
        for distance, want in ((0.0, blue), (0.001, yellow), (0.002, red), (0.01, red)):
            np.testing.assert_allclose(as_built_view.ramp_colour(distance, limit), want, atol=1e-12)
        # a quarter of the limit: half way from blue to yellow, channel by channel
        np.testing.assert_allclose(as_built_view.ramp_colour(0.0005, limit), (0.55, 0.60, 0.50, 1.0), atol=1e-12)
        # three quarters: half way from yellow to red
        np.testing.assert_allclose(as_built_view.ramp_colour(0.0015, limit), (1.0, 0.475, 0.05, 1.0), atol=1e-12)

    def test_ghost_colours_follow_each_points_distance(self):
        d = small_design()
        lines, colours = as_built_view.ghost_lines(d)[0]
        # wire A/0's points are 0, 1 and 4 mm from their targets; the limit 2 mm
        np.testing.assert_allclose(colours[0], (0.10, 0.35, 1.00, 1.0), atol=1e-6)  # segment 0, point 0
        np.testing.assert_allclose(colours[1], (1.00, 0.85, 0.00, 1.0), atol=1e-6)  # segment 0, point 1
        np.testing.assert_allclose(colours[3], (1.00, 0.10, 0.10, 1.0), atol=1e-6)  # segment 1, point 2 (over)

    def test_legend_in_mm(self):
        legend = as_built_view.legend(small_design())
        self.assertEqual([label for _x, _c, label in legend["stops"]], ["0 mm", "1.00 mm", "2.00 mm"])
        self.assertIn("red: at the 2.00 mm sag limit or past it", legend["notes"])
        self.assertEqual([x for x, _c, _l in legend["stops"]], [0.0, 0.5, 1.0])
        self.assertIn("largest 4.00 mm (A/0)", legend["notes"])
        self.assertIn("+ marks: crossing 0 slips", legend["notes"])
        self.assertIn("shape change drawn 10x", as_built_view.legend(small_design(), 10.0)["notes"])


class Ghosts(Case):
    def scene_with(self, design):
        scene_results.store_design(design)
        return bpy.context.scene

    def test_toggle_hides_and_shows_them(self):
        scene = self.scene_with(small_design())
        ws = scene.wiresculpt
        self.assertFalse(ws.show_as_built)  # off by default
        self.assertIsNone(overlay.as_built_shown(scene))
        ws.show_as_built = True
        try:
            shown = overlay.as_built_shown(scene)
            self.assertEqual(sorted(shown["lines"]), [0, 1])
            ws.show_as_built = False
            self.assertIsNone(overlay.as_built_shown(scene))
        finally:
            ws.property_unset("show_as_built")

    def test_slider_hides_later_steps(self):
        scene = self.scene_with(small_design())
        ws = scene.wiresculpt
        ws.show_as_built = True
        try:
            ws.assembly_step = 1  # wire A/0 alone: wire B/0 and the crossing between them are later
            shown = overlay.as_built_shown(scene)
            self.assertEqual(sorted(shown["lines"]), [0])
            self.assertIsNone(shown["marks"])
            ws.assembly_step = 2
            shown = overlay.as_built_shown(scene)
            self.assertEqual(sorted(shown["lines"]), [0, 1])
            self.assertEqual(shown["marks"].shape, (6, 3))  # crossing 0 slips, crossing 1 holds
        finally:
            ws.property_unset("show_as_built")
            ws.property_unset("assembly_step")

    def test_slip_mark_at_the_ghost(self):
        d = small_design()
        marks = as_built_view.slip_marks(d, size=0.2)
        centre = marks.reshape(3, 2, 3).mean(axis=1)  # each arm's middle
        np.testing.assert_allclose(centre, [[0.1, 0, 0.001]] * 3, atol=1e-7)  # A/0's as-built vertex 1
        arm = 0.03 * 0.2
        np.testing.assert_allclose(np.linalg.norm(marks[1] - marks[0]), 2 * arm, rtol=1e-6)

    def test_exaggerated_ghost_by_hand(self):
        d = small_design()
        lines, _colours = as_built_view.ghost_lines(d, scale=10.0)[0]
        # A/0: target + 10 (as_built - target): z 0, 10 mm, 40 mm
        want = [[0, 0, 0], [0.1, 0, 0.01], [0.1, 0, 0.01], [0.2, 0, 0.04]]
        np.testing.assert_allclose(lines, want, atol=1e-7)

    def test_no_ghosts_without_the_3d_check(self):
        d = small_design()
        for w in d["wires"]:
            del w["as_built"]
        scene = self.scene_with(d)
        scene.wiresculpt.show_as_built = True
        try:
            self.assertIsNone(overlay.as_built_shown(scene))
            shown = [a[1] for n, a, _k in draw(results_ui.VIEW3D_PT_wiresculpt_display, bpy.context) if n == "prop"]
            self.assertNotIn("show_as_built", shown)
        finally:
            scene.wiresculpt.property_unset("show_as_built")


@unittest.skipUnless(native.available(), "the native module is not built")
class Globe(Case):
    """The bundled globe optimized: its design's as-built shapes, sags and 3D verdict shown."""

    def setUp(self):
        super().setUp()
        globe()
        assert bpy.ops.wiresculpt.optimize() == {'FINISHED'}
        self.design = scene_results.stored_design()
        self.assertTrue(self.design["stands_3d"]["stands"], self.design["stands_3d"])

    def test_ghost_geometry_is_the_as_built_shape(self):
        ws = bpy.context.scene.wiresculpt
        ws.show_as_built = True
        try:
            shown = overlay.as_built_shown(bpy.context.scene)
        finally:
            ws.property_unset("show_as_built")
        self.assertEqual(sorted(shown["lines"]), [w["id"] for w in self.design["wires"]])
        for w in self.design["wires"]:
            lines, colours = shown["lines"][w["id"]]
            want = hand_segments(w["as_built"])
            self.assertEqual(len(lines), 2 * len(want))
            np.testing.assert_allclose(lines, np.asarray(want, dtype=np.float32).reshape(-1, 3), atol=1e-7)
            # each end's colour from its distance to the target point it was walked from
            targets = walked(w)
            self.assertEqual(len(targets), len(w["as_built"]))
            limit = self.design["stands_3d"]["sag_limit"]
            for k, (a, b) in enumerate(hand_segments(list(zip(w["as_built"], targets)))):
                for end, (p, t) in enumerate((a, b)):
                    x = min(math.dist(p, t) / limit, 1.0)
                    # below half the limit: blue (0.10, 0.35, 1) towards yellow (1, 0.85, 0) by 2x
                    self.assertLess(x, 0.5)
                    want_colour = (0.10 + 2 * x * 0.90, 0.35 + 2 * x * 0.50, 1.0 - 2 * x, 1.0)
                    np.testing.assert_allclose(colours[2 * k + end], want_colour, atol=1e-5)
        # the globe's crossings all hold: no marks
        self.assertIsNone(shown["marks"])

    def test_sag_is_the_largest_distance(self):
        for w in self.design["wires"]:
            largest = max(math.dist(p, t) for p, t in zip(w["as_built"], walked(w)))
            self.assertAlmostEqual(w["sag"], largest, places=12)

    def test_report_shows_the_sag_per_wire(self):
        shown = text_of(draw(results_ui.VIEW3D_PT_wiresculpt_report, bpy.context))
        record = self.design["stands_3d"]
        self.assertIn(f"Per wire: closure gap, sag in 3D (limit {record['sag_limit'] * 1000:.2f} mm)", shown)
        for w in self.design["wires"]:
            self.assertIn(f"{w['name']}: gap", shown)
            self.assertIn(f"sag {w['sag'] * 1000:.2f} mm", shown)
        self.assertNotIn("out of plane", shown)
        self.assertIn(f"within {record['max_sag'] * 1000:.1f} mm of their targets", shown)  # the 3D sentence

    def test_optimize_reports_the_3d_verdict(self):
        record = self.design["stands_3d"]
        kind, sentence = optimize.summary(self.design)
        self.assertEqual(kind, {'INFO'})
        self.assertTrue(sentence.startswith("Stable: 3 wires, 6 crossings; assemble "), sentence)
        self.assertTrue(sentence.endswith(f". 3D: stands, sag at most {record['max_sag'] * 1000:.2f} mm "
                                          f"(limit {record['sag_limit'] * 1000:.2f} mm)"), sentence)

    def test_slipping_crossing_marker_is_magenta(self):
        design = scene_results.stored_design()
        design = {**design, "crossings": [dict(c) for c in design["crossings"]]}
        design["crossings"][2]["admissible"] = False
        scene_results.write_results(bpy.context.scene, design)
        markers = {o[scene_results.CROSSING_KEY]: o for o in bpy.context.scene.objects if scene_results.CROSSING_KEY in o}
        colour = lambda c: tuple(round(x, 6) for x in markers[c].material_slots[0].material.diffuse_color)
        self.assertEqual(colour(2), (1.0, 0.0, 1.0, 1.0))
        self.assertEqual(colour(0), (0.1, 0.85, 0.2, 1.0))  # hooked and holding: green

    def test_result_panel_has_the_toggle(self):
        shown = [a[1] for n, a, _k in draw(results_ui.VIEW3D_PT_wiresculpt_display, bpy.context) if n == "prop"]
        self.assertIn("show_as_built", shown)
        self.assertIn("as_built_scale", shown)

    def test_live_says_the_3d_verdict(self):
        job = live.LiveJob(None, [], [], [], {}, {}, {})
        job.design = self.design
        record = self.design["stands_3d"]
        line = (f"3D: stands, sag at most {record['max_sag'] * 1000:.2f} mm "
                f"(limit {record['sag_limit'] * 1000:.2f} mm)")
        self.assertEqual(job.standing(), line)
        job.design = dict(self.design, stands_3d={**record, "stands": False, "cause": "slips", "slipping": [2, 4]})
        self.assertEqual(job.standing(), "3D: crossings 2, 4 slip")
        job.design = {k: v for k, v in self.design.items() if k != "stands_3d"}  # the check did not run
        self.assertEqual(job.standing(), "")
        # the panel's Live box shows it under the verdict line
        was = (STATE.running, STATE.verdict, STATE.kind, STATE.standing)
        STATE.running, STATE.verdict, STATE.kind, STATE.standing = True, "stable", "stable", line
        try:
            shown = labels(draw(panel.VIEW3D_PT_wiresculpt, bpy.context))
        finally:
            STATE.running, STATE.verdict, STATE.kind, STATE.standing = was
        self.assertIn("Live: stable", shown)
        self.assertIn(line, " ".join(shown))


class DeflectionWords(Case):
    def test_out_of_plane_labelled_without_the_3d_check(self):
        d = small_design()
        del d["stands_3d"]
        for w in d["wires"]:
            w.pop("sag")
            w["out_of_plane_deflection"] = 0.003
        self.assertEqual(standing.wire_heading(d), "Per wire: closure gap, out of plane (each wire alone)")
        self.assertEqual(results_ui.wire_rows(d), [("A/0", None, "3.00 mm"), ("B/0", None, "3.00 mm")])
        self.assertFalse(results_ui.deflection_note(d))
        d = small_design()
        for w in d["wires"]:
            w["out_of_plane_deflection"] = 0.003
        self.assertEqual(results_ui.wire_rows(d), [("A/0", None, "4.00 mm"), ("B/0", None, "1.00 mm")])
        self.assertTrue(results_ui.deflection_note(d))
        self.assertEqual(overlay.deflection_whiskers(d), {})  # the ghosts show it instead
