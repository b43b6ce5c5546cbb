"""The plane assistant (the plane_search package) in-process, on a sphere whose plane circles are
known by hand: the planes z = c1 and x = c2 (c in units of the radius) cut circles that cross iff
c1^2 + c2^2 < 1, and a plane at distance c from the centre along (1, 1, 0)/sqrt2 meets y = 0 iff
c < 1/sqrt2 and z = 0.7 iff c^2 < 0.51. Every stable design found is re-checked by
blender_tests/pure/recheck.py (numpy/scipy only, no solver code), after a JSON round trip."""
import copy
import json
import math
import unittest

import numpy as np

from wiresculpt import native, pipeline, plane_search
from wiresculpt.core import contours as contour_rules
from wiresculpt.core import design as vocabulary
from wiresculpt.core import sizes
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec, parse_scene
from wiresculpt.stages import layering, slicing, target_shape

from helpers import ROOT, settings, sphere
import recheck

R = 0.125  # the sphere's radius (m); its size S is 0.25 m


def P(name, origin, normal):
    return PlaneSpec(name, tuple(R * c for c in origin), normal)


# Z1, Z2 (z = +-0.7), X1 (x = -0.3) and Y (y = 0) all cross each other where they can: a stable base.
BASE = [P("Z1", (0, 0, 0.7), (0, 0, 1)), P("Z2", (0, 0, -0.7), (0, 0, 1)), P("X1", (-0.3, 0, 0), (1, 0, 0)),
        P("Y", (0, 0, 0), (0, 1, 0))]
# W at x = 0.8 misses Z1 and Z2 (0.64 + 0.49 > 1) and is parallel to X1: it crosses Y alone, at two
# points on the line x = 0.8, y = 0, so it turns about that line (a hinge).
HINGE = BASE + [P("W", (0.8, 0, 0), (1, 0, 0))]
# W at distance 0.9 along (1, 1, 0): misses Y (0.9 > 0.707), Z1, Z2 (0.81 > 0.51) and X1.
MISS = BASE + [P("W", (0.9 / math.sqrt(2), 0.9 / math.sqrt(2), 0), (1, 1, 0))]


def torus(major=0.1, minor=0.04, n=64, m=24):
    V = [((major + minor * math.cos(2 * math.pi * j / m)) * math.cos(2 * math.pi * i / n),
          (major + minor * math.cos(2 * math.pi * j / m)) * math.sin(2 * math.pi * i / n),
          minor * math.sin(2 * math.pi * j / m)) for i in range(n) for j in range(m)]
    F = []
    for i in range(n):
        for j in range(m):
            a, b, c, d = i * m + j, ((i + 1) % n) * m + j, ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
            F += [(a, b, c), (a, c, d)]
    return np.array(V), np.array(F)


def round_trip(design):
    return json.loads(json.dumps(design))


def untimed(value):
    """`value` without the keys that hold a measured time (they differ between two equal runs), its
    arrays as lists."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if "seconds" not in k}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def crossing_partners(design, wire_name):
    """{names of the other wires} that the wire crosses, and the crossing points of the wire."""
    ids = {w["id"]: w["name"] for w in design["wires"]}
    me = [w["id"] for w in design["wires"] if w["name"] == wire_name][0]
    partners, points = set(), []
    for c in design["crossings"]:
        if me in c["wires"]:
            partners |= {ids[w] for w in c["wires"] if w != me}
            points.append(c["point"])
    return partners, np.array(points)


def collinear(points, tol=1e-6):
    if len(points) < 3:
        return True
    x = points - points[0]
    return np.linalg.svd(x, compute_uv=False)[1] < tol


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Nearby(unittest.TestCase):
    def setUp(self):
        self.V, self.F = sphere()

    def test_the_scenes_are_what_the_hand_says(self):
        hinge = pipeline.run(self.V, self.F, HINGE, PRESETS["steel"], settings())
        self.assertFalse(hinge["stable"])
        partners, points = crossing_partners(hinge, "W/0")
        self.assertEqual(partners, {"Y/0"})
        self.assertTrue(collinear(points))
        miss = pipeline.run(self.V, self.F, MISS, PRESETS["steel"], settings())
        self.assertFalse(miss["stable"])
        self.assertEqual(crossing_partners(miss, "W/0")[0], set())
        base = pipeline.run(self.V, self.F, BASE, PRESETS["steel"], settings())
        self.assertTrue(base["stable"], base["reason"])

    def check_found(self, design, used):
        d = round_trip(design)
        self.assertTrue(d["stable"], d["reason"])
        self.assertEqual(recheck.recheck(d), [])
        # the design speaks the design's vocabulary (core/design.py), slicing recorded as slicing.run does
        self.assertLessEqual(set(d), set(vocabulary.KEYS["top"]))
        self.assertLessEqual(set(d["stages"]), set(vocabulary.KEYS["stages"]))
        self.assertEqual(set(d["stages"]["slicing"]), {"seconds", "planes", "contours", "mesh"})
        # the hinge is gone: W crosses a second wire, off the line it turned about
        partners, points = crossing_partners(d, "W/0")
        self.assertGreaterEqual(len(partners), 2)
        self.assertFalse(collinear(points))
        # the wires' planes are the planes used and recorded
        after = {p["name"]: p for p in d["plane_search"]["planes_after"]}
        self.assertEqual(sorted(after), sorted(p.name for p in used))
        for w in d["wires"]:
            plane = after[w["name"].split("/")[0]]
            self.assertLess(np.linalg.norm(np.subtract(w["plane"]["normal"], plane["normal"])), 1e-12)
            self.assertLess(abs(np.dot(np.subtract(w["plane"]["origin"], plane["origin"]), plane["normal"])), 1e-12)
        return d

    def changed(self, record):
        before = {p["name"]: p for p in record["planes_before"]}
        return {p["name"] for p in record["planes_after"]
                if p["origin"] != before[p["name"]]["origin"] or p["normal"] != before[p["name"]]["normal"]
                or p["contours"] != before[p["name"]]["contours"]}

    def test_a_hinged_wire_gets_a_second_partner(self):
        design, used = plane_search.run(self.V, self.F, HINGE, PRESETS["steel"], settings(plane_search="nearby"))
        d = self.check_found(design, used)
        record = d["plane_search"]
        self.assertEqual(record["mode"], "nearby")
        self.assertTrue(self.changed(record))
        self.assertGreater(record["candidates"], record["full_solves"])  # the screen rejected some
        self.assertLess(record["score"], 0.0)
        self.assertTrue(record["changes"])

    def test_a_plane_that_crosses_nothing_is_moved_until_it_does(self):
        design, used = plane_search.run(self.V, self.F, MISS, PRESETS["steel"], settings(plane_search="nearby"))
        d = self.check_found(design, used)
        # only W can make the difference: no other plane's change reaches it (the base keeps |c| <= 0.7)
        self.assertIn("W", self.changed(d["plane_search"]))
        w = [p for p in d["plane_search"]["planes_after"] if p["name"] == "W"][0]
        distance = abs(np.dot(w["origin"], w["normal"])) / R
        self.assertLess(distance, 0.9)  # W moved towards the centre (or turned), never away

    def test_every_candidate_returned_passes_the_recheck(self):
        found, searcher, _start = plane_search.nearby((self.V, self.F), HINGE, PRESETS["steel"],
                                                      settings(plane_search="nearby"), want=3, budget=60.0)
        self.assertTrue(found)
        costs = [c["cost"] for c in found]
        self.assertEqual(costs, sorted(costs))
        for c in found:
            d = round_trip(c["design"])
            self.assertTrue(d["stable"])
            self.assertEqual(recheck.recheck(d), [], c["changes"])
            # the cost is the documented measure of the placements, recomputed from them
            by_name = {p.name: p for p in HINGE}
            cost = 0.0
            for p in c["planes"]:
                q = by_name[p.name]
                n0 = np.asarray(q.normal, float) / np.linalg.norm(q.normal)
                tilt = math.acos(max(-1.0, min(1.0, float(np.dot(n0, p.normal)))))
                shift = abs(float(np.dot(np.subtract(p.origin, q.origin), p.normal))) if tilt < 1e-9 else 0.0
                cost += shift / 0.25 + tilt + (plane_search.RULE_COST if p.contours != q.contours else 0.0)
            self.assertAlmostEqual(c["cost"], cost, delta=1e-9)

    def test_stable_planes_are_kept(self):
        design, used = plane_search.run(self.V, self.F, BASE, PRESETS["steel"], settings(plane_search="nearby"))
        self.assertTrue(design["stable"])
        self.assertEqual(design["plane_search"]["changes"], [])
        self.assertEqual(design["plane_search"]["score"], 0.0)
        self.assertEqual([(p.origin, p.normal) for p in used],
                         [(tuple(float(c) for c in p.origin), tuple(float(c) for c in p.normal)) for p in BASE])

    def test_a_solve_past_the_budget_is_stopped_and_a_cancel_still_cancels(self):
        s = plane_search.Searcher((self.V, self.F), PRESETS["steel"], settings())
        placements = [plane_search.Placement(p.name, p.origin, p.normal, p.contours) for p in BASE]
        ok, design, _close = s.screen(placements)
        self.assertTrue(ok)  # the base is stable (test_the_scenes_are_what_the_hand_says)
        s.guard = 0.0  # the search's guard long past: the solve stops at its first check
        self.assertIsNone(s.solve(copy.deepcopy(design)))
        self.assertEqual((s.full_solves, s.timed_out), (1, 1))
        s.guard, s.time_stopped = math.inf, False
        self.assertTrue(s.solve(copy.deepcopy(design))["stable"])
        s.cancel = lambda: True
        with self.assertRaises(pipeline.Cancelled):
            s.solve(copy.deepcopy(design))

    def test_off_is_the_pipeline(self):
        design, used = plane_search.run(self.V, self.F, HINGE, PRESETS["steel"], settings())
        self.assertNotIn("plane_search", design)
        self.assertFalse(design["stable"])
        self.assertEqual(used, HINGE)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class ReusedSlices(unittest.TestCase):
    """A screen with the search's shared slices (the placements of many candidates sliced in one
    native call, contours converted once and shared by the designs, the probe copied without its
    points) equals a screen from scratch: each plane sliced by its own call, the wires made by
    core.design.wire_entry, the layering run on a deep copy (the screen as it was before slices were
    shared). On the sphere with BASE's planes, whose circles and crossings are known by hand: a plane
    at distance c R from the centre cuts the circle of radius R sqrt(1 - c^2); the planes z = c1 and
    x = c2 (or y = c2) cross at the two points (c2, +-sqrt(1 - c1^2 - c2^2), c1) R when
    c1^2 + c2^2 < 1; Z1 and Z2 are parallel. So every pair of BASE's planes but (Z1, Z2) crosses
    twice: 10 crossings."""

    def setUp(self):
        self.V, self.F = sphere()
        self.settings = settings()

    def from_scratch(self, placements):
        design = vocabulary.new_design(PRESETS["steel"], self.settings)
        design["model_size"] = sizes.mesh_size(self.V)  # as pipeline.slice_and_pick records it
        contours = 0
        for p in placements:
            found, info = slicing.slice_planes(self.V, self.F, [p.spec()], self.settings.get("weld_tolerance"))
            contours += len(found[0])
            design["stages"]["slicing"] = {"planes": len(placements), "contours": contours, "mesh": info}
            for k in contour_rules.pick(found[0], p.contours, p.name):
                c = found[0][k]
                design["wires"].append(vocabulary.wire_entry(len(design["wires"]), f"{p.name}/{k}", list(p.origin),
                                                             list(p.normal), c["closed"], c["points"]))
        probe = copy.deepcopy(design)
        # as the screen layers (Searcher._layer): the hooks the target shape cannot realise forbidden,
        # the contours as arrays
        layering.run(probe, PRESETS["steel"], self.settings, too_close=target_shape.REALISED_ANGLE, arrays=True)
        return design, probe

    def candidates(self, searcher):
        """The given planes, Z1 moved down 4 % of S (z = 0.62 R), and that with X1 moved +x 2 % of S
        (x = -0.26 R), as the nearby search makes them."""
        base = [plane_search.Placement(p.name, p.origin, p.normal, p.contours) for p in BASE]
        singles = {i: plane_search.single_changes(p, searcher.centre, searcher.size) for i, p in enumerate(BASE)}
        down = [c for c in singles[0] if c.changes == ["move plane Z1 down 10 mm"]][0]
        right = [c for c in singles[2] if c.changes == ["move plane X1 +x 5 mm"]][0]
        return singles, [(base, (0.7, -0.3)), ([down] + base[1:], (0.62, -0.3)),
                         ([down, base[1], right, base[3]], (0.62, -0.26))]

    def by_hand(self, probe, z1, x1):
        """The circles and crossings of Z1 at z = z1 R, Z2 at z = -0.7 R, X1 at x = x1 R and Y at y = 0."""
        distance = {"Z1/0": z1, "Z2/0": -0.7, "X1/0": x1, "Y/0": 0.0}
        axis = {"Z1/0": 2, "Z2/0": 2, "X1/0": 0, "Y/0": 1}
        for w in probe["wires"]:
            points = np.asarray(w["contour"]) / R
            c = distance[w["name"]]
            np.testing.assert_allclose(points[:, axis[w["name"]]], c, atol=1e-12)
            # on the mesh's chords, within 1 % inside the sphere (its triangles span at most 7.5 deg)
            off = np.delete(points, axis[w["name"]], axis=1)
            radius = np.linalg.norm(off, axis=1)
            self.assertTrue(np.all(radius <= math.sqrt(1 - c * c) + 1e-12), w["name"])
            self.assertTrue(np.all(np.linalg.norm(points, axis=1) >= 0.99), w["name"])
        names = {w["id"]: w["name"] for w in probe["wires"]}
        self.assertEqual(len(probe["crossings"]), 10)
        for c in probe["crossings"]:
            pair = sorted(names[i] for i in c["wires"])
            self.assertNotEqual(pair, ["Z1/0", "Z2/0"])
            point = np.asarray(c["point"]) / R
            for name in pair:
                self.assertAlmostEqual(point[axis[name]], distance[name], delta=1e-9)
            free = ({0, 1, 2} - {axis[n] for n in pair}).pop()
            fixed = sum(distance[n] ** 2 for n in pair)
            self.assertAlmostEqual(abs(point[free]), math.sqrt(1 - fixed), delta=0.01)

    def test_a_screen_with_shared_slices_equals_one_from_scratch(self):
        s = plane_search.Searcher((self.V, self.F), PRESETS["steel"], self.settings)
        singles, candidates = self.candidates(s)
        s.slice_ahead([p for c, _ in candidates for p in c] + [c for cs in singles.values() for c in cs])
        # the 4 given planes and 25 changes of each, less the 4 changes of the contour rule, which
        # cut where their given plane does (the key is the cut, not the rule)
        self.assertEqual(len(s.cache), 4 + 4 * 25 - 4)
        for placements, (z1, x1) in candidates * 2:  # the second round: every design from the shared lists
            ok, design, probe = s.screen_layered(placements)
            mine_design, mine_probe = self.from_scratch(placements)
            self.assertTrue(ok, probe["reason"])
            self.assertTrue(mine_probe["stable"])
            self.assertEqual(untimed(design), untimed(mine_design))
            self.assertEqual(untimed(probe), untimed(mine_probe))
            self.assertEqual(json.dumps(untimed(probe), sort_keys=True), json.dumps(untimed(mine_probe), sort_keys=True))
            self.by_hand(probe, z1, x1)

    def test_slicing_ahead_leaves_refused_placements_to_their_candidates(self):
        s = plane_search.Searcher((self.V, self.F), PRESETS["steel"], self.settings)
        good = plane_search.Placement("Z1", (0.0, 0.0, 0.7 * R), (0, 0, 1), "largest")
        bad = plane_search.Placement("Bad", (0.0, 0.0, 0.0), (0, 0, 1), "largest")
        bad.origin = (math.nan, 0.0, 0.0)  # a placement the slicer refuses
        s.slice_ahead([good, bad])
        self.assertEqual(list(s.cache), [good.key()])  # the good one sliced alone, the refused one left
        ok, _design, _probe = s.screen_layered([good, bad])
        self.assertFalse(ok)
        self.assertEqual(s.fault[0], "refused")
        self.assertIn("expected a finite number, got nan", s.fault[2][0])
        self.assertEqual(len(s._contours(good)), 1)
        # A look-ahead of the refused placement alone does not raise (it would end the search):
        # the refusal is kept and only reaches the candidates that hold it, when screened.
        again = plane_search.Searcher((self.V, self.F), PRESETS["steel"], self.settings)
        again.slice_ahead([bad])
        self.assertEqual(list(again.cache), [])
        self.assertIn("expected a finite number, got nan", again.refused[repr(bad.key())])
        ok, _design, _probe = again.screen_layered([good, bad])
        self.assertFalse(ok)
        self.assertEqual(again.fault[0], "refused")


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Auto(unittest.TestCase):
    def check(self, V, F, count):
        design, used = plane_search.run(V, F, [], PRESETS["steel"], settings(plane_search="auto", plane_count=count))
        d = round_trip(design)
        self.assertTrue(d["stable"], d["reason"])
        self.assertEqual(recheck.recheck(d), [])
        self.assertEqual(len(used), count)
        self.assertEqual(len(d["plane_search"]["planes_after"]), count)
        self.assertEqual(d["plane_search"]["planes_before"], [])
        # every plane cuts the mesh: its centre-distance is inside the mesh's extent along its normal
        for p in used:
            t = np.asarray(V) @ np.asarray(p.normal)
            self.assertTrue(t.min() < np.dot(p.origin, p.normal) < t.max(), p.name)
        return d

    def test_sphere(self):
        V, F = sphere()
        self.check(V, F, 5)

    def test_torus(self):
        V, F = torus()
        self.check(V, F, 5)


class SceneSettings(unittest.TestCase):
    def scene(self, **extra):
        data = {"mesh": "globe/globe.obj", "planes": [{"origin": [0, 0, 0], "normal": [0, 0, 1]}]}
        data.update(extra)
        return parse_scene(data, f"{ROOT}/scripts/examples/scene.json")

    def test_defaults(self):
        s = self.scene().settings
        self.assertEqual((s["plane_search"], s["plane_count"]), ("off", 5))

    def test_bad_values_name_the_key(self):
        for value, text in ((("near"), 'scene key "settings.plane_search" must be one of "off", "nearby", "auto", got "near"'),
                            ((3), 'scene key "settings.plane_search" must be one of')):
            with self.assertRaises(ValueError) as cm:
                self.scene(settings={"plane_search": value})
            self.assertIn(text, str(cm.exception))
        with self.assertRaises(ValueError) as cm:
            self.scene(settings={"plane_count": 1})
        self.assertIn('"settings.plane_count" must be at least 2', str(cm.exception))
        with self.assertRaises(ValueError) as cm:
            self.scene(settings={"plane_count": 4.5})
        self.assertIn('"settings.plane_count" must be a whole number', str(cm.exception))

    def test_empty_planes_only_with_auto(self):
        self.assertEqual(self.scene(planes=[], settings={"plane_search": "auto"}).planes, [])
        with self.assertRaises(ValueError) as cm:
            self.scene(planes=[], settings={"plane_search": "nearby"})
        self.assertIn('scene key "planes" must be a non-empty list', str(cm.exception))

    def test_nearby_without_planes_is_refused_in_process(self):
        with self.assertRaises(ValueError) as cm:
            plane_search.run(None, None, [], PRESETS["steel"], settings(plane_search="nearby"))
        self.assertIn('plane_search "nearby" needs planes', str(cm.exception))


if __name__ == "__main__":
    unittest.main()


class StandsFirst(unittest.TestCase):
    """Both searches rank a candidate whose assembled sculpture stands in the 3D check before any
    that does not (searcher.stands_first), from the figures _figures takes from its design."""

    def design(self, record):
        d = {"wires": [{"target_max_distance": 0.001, "closure_gap": 0.0}], "load_capacity": {"+x": 2.0}}
        if record is not None:
            d["stands_3d"] = record
        return d

    def test_the_figures_and_the_key(self):
        from wiresculpt.plane_search.searcher import _figures, stands_first
        stands = _figures(self.design({"stands": True, "cause": "stands", "max_sag": 0.0004}))
        slips = _figures(self.design({"stands": False, "cause": "slips", "max_sag": 0.0002}))
        unchecked = _figures(self.design(None))
        self.assertEqual((stands["stands_3d"], stands["cause_3d"], stands["sag"]), (True, "stands", 0.0004))
        self.assertEqual((unchecked["stands_3d"], unchecked["sag"]), (None, None))
        found = [{"figures": slips, "cost": 0.1}, {"figures": unchecked, "cost": 0.0}, {"figures": stands, "cost": 0.3}]
        found.sort(key=lambda c: (stands_first(c), c["cost"]))  # nearby's order
        self.assertEqual([c["cost"] for c in found], [0.3, 0.0, 0.1])
