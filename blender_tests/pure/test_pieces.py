"""Wires longer than the stock (fab/pieces.py): split at the least bending moment, each piece its
own files, or the STOCK limit kept with the reason. Answers by hand: a straight wire whose in-plane
moment is written out from its crossing forces, pieces rebuilt from their bend tables."""
import copy
import csv
import importlib.util
import math
import os
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core import limits, sizes
from wiresculpt.core.calibration import default_profile
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.settings import defaults
from wiresculpt.fab import export, pieces

from helpers import BATCH, PLANES, sphere

# A straight open wire along x, 1.6 m, points every 10 mm; forces along y (N) at four crossings,
# balanced (sum 0, moment 0). By hand its in-plane moment t(x) = sum_{p > x} (x - p) f_p is 0 before
# 0.2 and after 1.4, -(x - 0.2) on (0.2, 0.6), 2 x - 1.6 on (0.6, 1.0) (zero at 0.8), 1.4 - x on (1.0, 1.4).
LENGTH, STEP = 1.6, 0.01
FORCES = ((0.2, 1.0), (0.6, -3.0), (1.0, 3.0), (1.4, -1.0))


def by_hand(x):
    return sum((x - p) * f for p, f in FORCES if p > x)


def straight_design(rest_bends=(), forces=FORCES, step=STEP):
    """The straight wire (id 0) as a design: target along x in the plane z = 0, its rest shape bent
    by the given (index, degrees) turns, one crossing per force with a wire 1 not in the design."""
    n = int(round(LENGTH / step)) + 1
    target = [[k * step, 0.0, 0.0] for k in range(n)]
    heading, rest, turn = 0.0, [np.zeros(2)], dict(rest_bends)
    for k in range(1, n):
        rest.append(rest[-1] + step * np.array([math.cos(heading), math.sin(heading)]))
        heading += math.radians(turn.get(k, 0.0))
    wire = {"id": 0, "name": "X0/0", "closed": False, "cut": -1, "plane": {"origin": [0, 0, 0], "normal": [0, 0, 1]},
            "target": target, "rest": [list(p) for p in rest], "length": LENGTH}
    crossings = [{"id": k, "wires": [0, 1], "vertices": [int(round(p / step)), 0], "force": [0.0, f, 0.0], "hook": 1}
                 for k, (p, f) in enumerate(forces)]
    return {"wires": [wire], "crossings": crossings, "model_size": 1.2, "machine": {"min_segment": 0.015, "max_bend_deg": 120.0,
                                                                 "min_bend_deg": 1.0}}


def machine():
    return dict(native.default_machine_profile())


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Straight(unittest.TestCase):
    def test_the_moment_is_the_hand_profile(self):
        d = straight_design()
        t = pieces.in_plane_moments(d, d["wires"][0])
        for k, value in enumerate(t):
            self.assertAlmostEqual(value, by_hand(k * STEP), places=12)

    def test_it_splits_where_the_moment_is_least(self):
        d = straight_design(rest_bends=((30, 4.0), (120, -6.0)))  # straight-ish: bends far from the answer
        plan = pieces.wire_plan(d, d["wires"][0], 1.0, 0.0, machine())
        (joint,) = plan["joints"]
        # two pieces of 1.0 m with a 30 mm joint: centres in [0.615, 0.985]; |t| is least at its zero 0.8
        self.assertAlmostEqual(joint["at"], 0.8, delta=pieces.STEP)
        self.assertAlmostEqual(joint["moment"], 2 * 0.015, delta=2 * pieces.STEP + 1e-9)  # |t(0.8 +- 15 mm)|
        self.assertEqual(joint["kind"], sizes.JOINT_SLEEVE)
        first, second = plan["pieces"]
        self.assertAlmostEqual(first["from"], 0.0)
        self.assertAlmostEqual(first["to"], 0.815, delta=pieces.STEP)
        self.assertAlmostEqual(second["from"], 0.785, delta=pieces.STEP)
        self.assertAlmostEqual(second["to"], LENGTH)
        self.assertEqual([p["name"] for p in plan["pieces"]], ["X0/0 piece 1 of 2", "X0/0 piece 2 of 2"])

    def test_a_bend_at_the_least_moment_moves_the_joint(self):
        # a rest bend at 0.81 m: the feeds from a joint's ends to it must reach 15 mm, so centres in
        # [0.795, 0.81) and (0.81, 0.825] are out; just under 0.795 costs |t(0.78)| = 0.04 (less to
        # the left: |t(x - 15 mm)| grows), past 0.825 at least |t(0.84)| = 0.08
        d = straight_design(rest_bends=((81, 10.0),))
        plan = pieces.wire_plan(d, d["wires"][0], 1.0, 0.0, machine())
        (joint,) = plan["joints"]
        self.assertAlmostEqual(joint["at"], 0.795, places=6)
        self.assertAlmostEqual(joint["moment"], 0.04, places=6)
        s = pieces.arc_lengths(d["wires"][0]["rest"])
        for piece in plan["pieces"]:  # every piece's own program: no feed under the minimum
            line = pieces.piece_polyline(d["wires"][0]["rest"], s, piece["from"], piece["to"])
            self.assertEqual(native.bend_program_problems(line, machine()), [])

    def test_lengths_sum_to_the_wire_and_the_joints(self):
        d = straight_design()
        for stock in (1.0, 0.6, 0.45):
            plan = pieces.wire_plan(d, d["wires"][0], stock, 0.0, machine())
            joints = len(plan["joints"])
            self.assertEqual(len(plan["pieces"]), joints + 1)
            self.assertEqual(joints + 1, {1.0: 2, 0.6: 3, 0.45: 4}[stock])  # the fewest: ceil((1.6 + j 0.03) / stock)
            self.assertAlmostEqual(sum(p["length"] for p in plan["pieces"]), LENGTH + joints * sizes.JOINT_LENGTH,
                                   places=9)
            for p in plan["pieces"]:
                self.assertLessEqual(p["length"], stock * (1 + 1e-9))

    def test_no_admissible_point_keeps_the_stock_limit(self):
        # crossings every 40 mm: a joint (30 mm) with 15 mm to each crossing needs 60 mm between two
        forces = [(0.04 * k, (-1.0) ** k) for k in range(1, 40)]
        d = straight_design(forces=forces)
        plan = pieces.wire_plan(d, d["wires"][0], 1.0, 0.0, machine())
        fault = plan["split_fault"]
        self.assertEqual(fault["cause"], sizes.NO_JOINT_POINT)
        self.assertAlmostEqual(fault["least_stock"], LENGTH)
        d["wires"][0].update(plan)
        records = limits.limit_records(d, 1.0)
        self.assertEqual([c for c, _p in records], [limits.STOCK])
        self.assertIn(sizes.split_sentence(fault), records[0][1])
        self.assertIn("use a stock of at least 1600 mm", records[0][1])
        self.assertIn("scale the model down to 0.62", records[0][1])  # 1.0 / 1.6 = 0.625

    def test_points_too_far_apart_name_the_stock_they_need(self):
        # crossings every 40 mm but between 0.2 and 0.4 m: joint centres 30 mm (half the joint and
        # min_segment) clear of them, only in (0.23, 0.37); the longest piece is at least the second
        # from the stretch's right end: 1.6 - 0.37 + 0.015 = 1.245 m
        forces = [(0.04 * k, 1.0) for k in range(1, 40) if not 0.2 < 0.04 * k < 0.4]
        d = straight_design(forces=forces)
        plan = pieces.wire_plan(d, d["wires"][0], 1.0, 0.0, machine())
        fault = plan["split_fault"]
        self.assertEqual(fault["cause"], sizes.PIECE_TOO_LONG)
        self.assertAlmostEqual(fault["least_stock"], 1.245, places=6)
        self.assertIn("use a stock of at least 1245 mm", sizes.split_sentence(fault))

    def test_a_split_wire_is_within_the_stock(self):
        d = straight_design()
        d["wires"][0].update(pieces.wire_plan(d, d["wires"][0], 1.0, 0.0, machine()))
        self.assertEqual(limits.limit_records(d, 1.0), [])
        self.assertEqual([c for c, _p in limits.limit_records(d, 0.7)], [limits.STOCK])  # pieces over a shorter stock
        facts = sizes.size_facts(d, 1.0)
        self.assertEqual(facts[0]["pieces"], 2)
        self.assertIn("made in 2 pieces", sizes.size_sentence(facts[0]))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Globe(unittest.TestCase):
    """The three great circles (815 mm each) on a 500 mm stock: every wire in pieces, every piece
    its own files, rebuilt from its bend table."""

    @classmethod
    def setUpClass(cls):
        V, F = sphere()
        cls.design = pipeline.run(V, F, PLANES, dict(PRESETS["steel"]), defaults(), stock=(0.5, "short stock"))
        cls.profile = default_profile()
        cls.profile["stock_length"] = 0.5
        cls.tmp = tempfile.TemporaryDirectory()
        cls.result = export.export(cls.design, cls.tmp.name, cls.profile)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_the_moments_are_the_forces_stages(self):
        for w in self.design["wires"]:  # the stage's own figure (native), here from the crossings' forces
            self.assertAlmostEqual(float(np.abs(pieces.in_plane_moments(self.design, w)).max()), w["max_torque"],
                                   places=9)

    def test_the_pipeline_splits_and_the_verdict_is_within_the_stock(self):
        self.assertTrue(self.design["stable"], self.design["reason"])
        for w in self.design["wires"]:
            self.assertGreater(w["length"], 0.5)
            self.assertEqual(len(w["pieces"]), 2)
            self.assertAlmostEqual(sum(p["length"] for p in w["pieces"]), w["length"] + sizes.JOINT_LENGTH, places=6)
        self.assertNotIn(limits.STOCK, [c for c, _p in limits.limit_records(self.design, 0.5)])
        self.assertEqual(self.design["stages"]["pieces"]["split"], 3)

    def test_each_piece_rebent_reproduces_its_share_of_the_rest_shape(self):
        self.assertEqual(self.result["errors"], [])
        for w in self.design["wires"]:
            rest = np.asarray(w["rest"])
            s = pieces.arc_lengths(rest)
            for k, piece in enumerate(w["pieces"]):
                stem = f"{export.file_stem(w)}-piece-{k + 1}-of-{len(w['pieces'])}"
                with open(os.path.join(self.tmp.name, "bends", stem + ".csv"), encoding="utf-8") as f:
                    rows = list(csv.DictReader(f))
                # the table re-bent: feed, then turn by the bend, from the origin heading along +x
                p, heading, made, at = np.zeros(2), 0.0, [np.zeros(2)], [0.0]
                for row in rows:
                    feed = float(row["feed_mm"]) / 1000
                    p = p + feed * np.array([math.cos(heading), math.sin(heading)])
                    made.append(p)
                    at.append(at[-1] + feed)
                    heading += math.radians(float(row["bend_deg"]))
                # its share of the rest shape, moved to start at the origin heading along +x
                share = np.array([[np.interp(a + piece["from"], s, rest[:, c]) for c in (0, 1)] for a in at])
                d = share[1] - share[0]
                angle = -math.atan2(d[1], d[0])
                rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
                share = (share - share[0]) @ rot.T
                self.assertAlmostEqual(at[-1], piece["length"], places=6)
                self.assertLess(float(np.max(np.linalg.norm(np.array(made) - share, axis=1))), 1e-3)  # the small-bend rule
                with open(os.path.join(self.tmp.name, "gcode", stem + ".gcode"), encoding="utf-8") as f:
                    self.assertIn(f"; wire: {w['name']} piece {k + 1} of {len(w['pieces'])}", f.read())
                for folder, ext in (("svg", "svg"), ("dxf", "dxf"), ("templates", "svg"), ("bendlist", "txt")):
                    self.assertTrue(os.path.isfile(os.path.join(self.tmp.name, folder, f"{stem}.{ext}")))
            self.assertFalse(os.path.exists(os.path.join(self.tmp.name, "gcode", export.file_stem(w) + ".gcode")))

    def test_the_templates_mark_each_pieces_crossings(self):
        total = 0
        for w in self.design["wires"]:
            s = pieces.arc_lengths(w["rest"])
            at = [float(s[i]) for i in export.crossing_indices(self.design, w)]
            for k, piece in enumerate(w["pieces"]):
                stem = f"{export.file_stem(w)}-piece-{k + 1}-of-{len(w['pieces'])}"
                root = ET.parse(os.path.join(self.tmp.name, "templates", stem + ".svg")).getroot()
                rings = [e for e in root.iter() if e.get("class") == "crossing"]
                self.assertEqual(len(rings), sum(1 for a in at if piece["from"] < a < piece["to"]))
                total += len(rings)
                # the joints: a band over the first 30 mm (a joint at its start) and the last 30 mm (at its end)
                wire_path = next(e for e in root.iter() if e.get("class") == "wire-path")
                q = np.array([[float(v) for v in p.split(",")] for p in wire_path.get("points").split()])
                bands = [e for e in root.iter() if e.get("class") == "joint"]
                ends = [q[0]] * (k > 0) + [q[-1]] * (k + 1 < len(w["pieces"]))
                self.assertEqual(len(bands), len(ends))
                for band, end in zip(bands, ends):
                    line = next(iter(band))
                    b = np.array([[float(v) for v in p.split(",")] for p in line.get("points").split()])
                    self.assertAlmostEqual(float(pieces.arc_lengths(b)[-1]), 30.0, places=3)
                    self.assertTrue(np.allclose(end, b[0], atol=1e-3) or np.allclose(end, b[-1], atol=1e-3))
        self.assertEqual(total, 2 * len(self.design["crossings"]))  # none inside a joint: each on one piece of each wire

    def test_a_closed_wires_last_piece_carries_the_closing_overlap(self):
        profile = dict(self.profile, closed_overlap=0.02)
        with tempfile.TemporaryDirectory() as tmp:
            result = export.export(self.design, tmp, profile)
            for w in self.design["wires"]:
                plan = result["pieces"][w["id"]]
                last = plan["pieces"][-1]
                self.assertEqual(last["allowance"], 0.02)
                self.assertLessEqual(last["length"] + 0.02, 0.5 * (1 + 1e-9))
                made = [s for s in result["wires"] if s["id"] == w["id"]]
                self.assertAlmostEqual(made[-1]["wire_length"], last["length"] + 0.02, places=9)  # fed 20 mm past the cut
                self.assertAlmostEqual(made[0]["wire_length"], plan["pieces"][0]["length"], places=9)

    def test_the_batch_writes_the_pieces_files_and_keys(self):
        spec = importlib.util.spec_from_file_location("wiresculpt_batch", BATCH)
        batch = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(batch)
        design = copy.deepcopy(self.design)
        for w in design["wires"]:
            for key in pieces.KEYS:
                w.pop(key, None)
        profile = dict(self.profile, stock_length=0.3)
        with tempfile.TemporaryDirectory() as tmp:
            batch.write_fabrication(design, tmp, lambda *_a: None, profile)
            count = 0
            for w in design["wires"]:
                n = len(w["pieces"])  # n pieces of at most 0.3 m carry 815 mm and n - 1 joints: n >= 3
                self.assertGreaterEqual(n, math.ceil((w["length"] - sizes.JOINT_LENGTH) / (0.3 - sizes.JOINT_LENGTH)))
                self.assertLessEqual(max(p["length"] for p in w["pieces"]), 0.3)
                for k in range(n):
                    self.assertTrue(os.path.isfile(os.path.join(tmp, "gcode", f"{export.file_stem(w)}-piece-{k + 1}-of-{n}.gcode")))
                count += n
            self.assertEqual(len(design["fabrication"]["wires"]), count)
            self.assertEqual(design["stages"]["pieces"]["stock_length"], 0.3)

    def test_the_joint_words(self):
        w = self.design["wires"][0]
        text = sizes.joint_sentence(w, w["joints"][0], 0.003)
        self.assertIn(f"join {w['name']} piece 1 of 2 and piece 2 of 2", text)
        self.assertIn("overlap by 30 mm", text)


if __name__ == "__main__":
    unittest.main()
