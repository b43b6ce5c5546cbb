"""blender_tests/pure/recheck.py: passes the globe's design from the batch run, and fails each
hand-made or mutated broken design for the reason it was broken."""
import copy
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)

import recheck as R  # noqa: E402

BLENDER = os.environ.get("BLENDER", "blender")


def globe_design():
    """The batch run's design of scripts/examples/globe/scene.json (or $WIRESCULPT_GLOBE_DESIGN),
    or None with the reason."""
    given = os.environ.get("WIRESCULPT_GLOBE_DESIGN")
    if given:
        with open(given) as f:
            return json.load(f), ""
    if not shutil.which(BLENDER):
        return None, "blender is not on PATH"
    with tempfile.TemporaryDirectory() as out:
        proc = subprocess.run([BLENDER, "--background", "--factory-startup", "--python-exit-code", "1", "--python",
                               os.path.join(ROOT, "scripts", "wiresculpt_batch.py"), "--",
                               os.path.join(ROOT, "scripts", "examples", "globe", "scene.json"), "--out", out],
                              capture_output=True, text=True, timeout=600)
        path = os.path.join(out, "design.json")
        if proc.returncode != 0 or not os.path.exists(path):
            return None, f"the globe batch run failed (exit {proc.returncode}): {proc.stderr.strip()[-300:]}"
        with open(path) as f:
            return json.load(f), ""


def mirror_kink(design, cid):
    """Crossing cid with its hook flipped and both kinks mirrored to match (the neighbours of each
    crossing vertex reflected through the crossing's plane normal to d): a consistent design
    whose contact opens the other way."""
    d = copy.deepcopy(design)
    c = d["crossings"][cid]
    i, j = c["wires"]
    dd = R._unit(np.cross(R._unit(d["wires"][i]["plane"]["normal"]), R._unit(d["wires"][j]["plane"]["normal"])))
    for w, r in zip(c["wires"], c["vertices"]):
        t = np.asarray(d["wires"][w]["target"], dtype=float)
        for k in ((r - 1) % len(t), (r + 1) % len(t)):
            t[k] -= 2 * ((t[k] - t[r]) @ dd) * dd
        d["wires"][w]["target"] = t.tolist()
    c["hook"] = -c["hook"]
    return d


def rotate_tail(rest, k, degrees):
    """The rest shape with everything after vertex k turned about it (lengths kept)."""
    rest = np.asarray(rest, dtype=float)
    a = math.radians(degrees)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    rest[k + 1:] = (rest[k + 1:] - rest[k]) @ rot.T + rest[k]
    return rest.tolist()


def has(problems, text):
    return any(text in p for p in problems)


class HandMade(unittest.TestCase):
    """Designs written out by hand: no Blender, no solver."""

    def open_wire(self, rest, machine=None):
        rest3 = [[x, y, 0.0] for x, y in rest]
        return {"material": {"friction": 0.32}, "machine": machine or {"min_segment": 0.015, "max_bend_deg": 120.0,
                                                                     "min_bend_deg": 1.0},
                "wires": [{"id": 0, "name": "A/0", "plane": {"origin": [0, 0, 0], "normal": [0, 0, 2]},
                           "closed": False, "target": rest3, "rest": rest, "cut": -1}],
                "crossings": [], "assembly_order": [0], "stable": True}

    def test_a_buildable_zigzag_passes(self):
        self.assertEqual(R.recheck(self.open_wire([[0, 0], [0.02, 0], [0.02, 0.02], [0.05, 0.02]])), [])

    def test_too_short_segment(self):
        problems = R.recheck(self.open_wire([[0, 0], [0.02, 0], [0.02, 0.01], [0.05, 0.01]]))
        self.assertTrue(has(problems, "< min_segment 15 mm"), problems)

    def test_over_bend(self):
        # turning 150 degrees at vertex 1
        a = math.radians(150)
        problems = R.recheck(self.open_wire([[0, 0], [0.02, 0], [0.02 + 0.02 * math.cos(a), 0.02 * math.sin(a)]]))
        self.assertTrue(has(problems, "turns 150.00 deg > max_bend_deg 120"), problems)

    def test_load_basis_is_self_equilibrated(self):
        for p in (2, 3, 5):
            L = R.load_basis(p)
            self.assertEqual(L.shape, (6 * p, 6 * (p - 1) + 1))
            for k in range(6):  # every load: forces and couples sum to zero over the wires
                np.testing.assert_allclose(L[k::6].sum(axis=0), 0.0)
            self.assertEqual(np.linalg.matrix_rank(L), 6 * (p - 1))


class Globe(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.design, why = globe_design()
        if cls.design is None:
            raise unittest.SkipTest(why)

    def mutated(self):
        return copy.deepcopy(self.design)

    def test_the_batch_design_passes(self):
        self.assertTrue(self.design["stable"])
        self.assertEqual(R.recheck(self.design), [])

    def test_point_off_its_plane(self):
        d = self.mutated()
        w = d["wires"][0]
        crossing_vertices = {v for c in d["crossings"] for wi, v in zip(c["wires"], c["vertices"]) if wi == 0}
        k = next(k for k in range(len(w["target"])) if k not in crossing_vertices)
        w["target"][k] = (np.asarray(w["target"][k]) + 0.001 * R._unit(w["plane"]["normal"])).tolist()
        self.assertTrue(has(R.recheck(d), f"target point {k} is 1 mm off its plane"))

    def test_crossing_vertices_apart(self):
        d = self.mutated()
        c = d["crossings"][2]
        w = d["wires"][c["wires"][1]]
        t = np.asarray(w["target"][c["vertices"][1]])
        w["target"][c["vertices"][1]] = (t + 0.002 * np.cross(R._unit(w["plane"]["normal"]), R._unit(t))).tolist()
        self.assertTrue(has(R.recheck(d), "crossing 2: target vertices"))

    def test_machine_with_a_longer_minimum_segment(self):
        d = self.mutated()
        d["machine"]["min_segment"] = 0.04
        self.assertTrue(has(R.recheck(d), "< min_segment 40 mm"))

    def test_over_bent_rest_shape(self):
        d = self.mutated()
        w = d["wires"][1]
        rest = np.asarray(w["rest"])
        e = np.diff(rest, axis=0)
        turns = [R._turn_deg(e[k - 1], e[k]) for k in range(1, len(rest) - 1)]
        k = 1 + int(np.argmax(turns))
        w["rest"] = rotate_tail(w["rest"], k, 125 - turns[k - 1])  # same sense: turns by 125 degrees
        problems = R.recheck(d)
        self.assertTrue(has(problems, f"bend at rest vertex {k} from the cut") and has(problems, "> max_bend_deg 120"),
                        problems)

    def test_rest_not_as_long_as_target(self):
        d = self.mutated()
        d["wires"][2]["rest"] = (1.01 * np.asarray(d["wires"][2]["rest"])).tolist()
        self.assertTrue(has(R.recheck(d), "(inextensible wire)"))

    def test_hook_flipped_in_the_file_only(self):
        d = self.mutated()
        d["crossings"][3]["hook"] *= -1
        self.assertTrue(has(R.recheck(d), "crossing 3 (hook"))

    def test_hook_flipped_so_the_structure_falls_apart(self):
        # The globe's hooks are chosen by their forces (docs/method-forces.md §12): the "ellipse"
        # hooks, under which no single mirrored flip (nor any pair) makes the sculpture fall apart.
        # Without both crossings between the Equator and Meridian0 (hook 0, no force) those two
        # hold each other only through Meridian90 and the sculpture cannot carry every load;
        # without one of them it still stands.
        pair = [c["id"] for c in self.design["crossings"] if sorted(c["wires"]) == [0, 1]]
        self.assertEqual(len(pair), 2)
        d = self.mutated()
        for cid in pair:
            d["crossings"][cid].update(hook=0, force=[0.0, 0.0, 0.0])
        problems, _ = R.check_stability(d)
        self.assertTrue(has(problems, "unstable: wires [0, 1, 2]: cannot carry"), problems)
        d = self.mutated()
        d["crossings"][pair[0]].update(hook=0, force=[0.0, 0.0, 0.0])
        self.assertEqual(R.check_stability(d)[0], [])
        # a flip that keeps the structure stable is not reported
        problems, _ = R.check_stability(mirror_kink(self.design, 2))
        self.assertEqual(problems, [])

    def test_a_wire_with_no_hooked_crossing_falls_off(self):
        d = self.mutated()
        for c in d["crossings"]:
            if 2 in c["wires"]:
                c["hook"], c["force"] = 0, [0.0, 0.0, 0.0]
        problems, _ = R.check_stability(d)
        self.assertTrue(has(problems, "unstable: wires [0, 1, 2]"), problems)

    def test_assembly_prefix_is_checked(self):
        # a fourth wire, a copy of Meridian0 turned 45 degrees, crossing no other with a hook:
        # the finished sculpture is unstable and so is its prefix
        d = self.mutated()
        w = copy.deepcopy(d["wires"][1])
        w["id"], w["name"] = 3, "extra"
        d["wires"].append(w)
        d["assembly_order"] = d["assembly_order"] + [3]
        problems, _ = R.check_stability(d)
        self.assertTrue(has(problems, "unstable: wires [0, 1, 2, 3]"), problems)
        self.assertFalse(has(problems, "prefix of 3"), problems)

    def test_force_outside_its_pyramid(self):
        d = self.mutated()
        c = d["crossings"][4]
        i, j = c["wires"]
        dd = R._unit(np.cross(R._unit(d["wires"][i]["plane"]["normal"]), R._unit(d["wires"][j]["plane"]["normal"])))
        f = np.asarray(c["force"])
        c["force"] = (f + 2 * c["hook"] * np.linalg.norm(f) * dd).tolist()  # pulls instead of pushing
        self.assertTrue(has(R.recheck(d), "crossing 4: force"))

    def test_forces_that_do_not_balance(self):
        d = self.mutated()
        d["crossings"][5]["force"] = (1.5 * np.asarray(d["crossings"][5]["force"])).tolist()
        self.assertTrue(has(R.recheck(d), "contact forces do not balance"))

class Prefixes(unittest.TestCase):
    """Which assembly states the re-check examines: every prefix of 3 wires and more, or, with
    assembly_steps, the states that end a step."""

    def checked(self, steps):
        import recheck as module

        seen = []
        real = module.carries_all_loads
        module.carries_all_loads = lambda design, wires, pyramids: seen.append(len(wires))
        try:
            design = {"wires": [{"id": i} for i in range(5)], "crossings": [], "assembly_order": [0, 1, 2, 3, 4]}
            if steps is not None:
                design["assembly_steps"] = steps
            self.assertEqual(module.check_stability(design)[0], [])
        finally:
            module.carries_all_loads = real
        return seen

    def test_two_hand_steps_are_one_state(self):
        self.assertEqual(self.checked(None), [3, 4, 5])
        self.assertEqual(self.checked([[0, 1], [2], [3], [4]]), [3, 4, 5])
        self.assertEqual(self.checked([[0, 1], [2, 3], [4]]), [4, 5])
        self.assertEqual(self.checked([[0, 1, 2], [3, 4]]), [3, 5])


if __name__ == "__main__":
    unittest.main()
