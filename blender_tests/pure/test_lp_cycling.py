"""A load-capacity LP on which GLPK's primal simplex cycled for ever (found in the bundled globe's
hook search once the target shape came from the SQP: forces_and_rest never returned, and Blender
with it). GLPK has no iteration limit by default; lp.cpp now sets one and, when it is reached,
solves again with the textbook ratio test from a fresh basis. The inputs of that call are
cycling_lp.json (wires with their target shapes, crossings, assembly steps, material, settings)."""
import json
import os
import subprocess
import sys
import unittest

from wiresculpt import native

HERE = os.path.dirname(os.path.abspath(__file__))
ADDON = os.path.dirname(os.path.dirname(os.path.abspath(native.__file__)))

SOLVE = """
import json, sys
from wiresculpt import native
d = json.load(open(sys.argv[1]))
r = native.forces_and_rest(d["wires"], d["crossings"], d["steps"], d["material"], d["settings"])
print(json.dumps(r["load_capacity"]))
"""


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class CyclingLp(unittest.TestCase):
    def test_the_solve_ends_with_every_direction_solved(self):
        # In a process of its own with a time limit: a hang fails this test instead of stopping the
        # suite. (It takes about half a second.)
        env = dict(os.environ, PYTHONPATH=ADDON + os.pathsep + os.environ.get("PYTHONPATH", ""))
        try:
            done = subprocess.run([sys.executable, "-c", SOLVE, os.path.join(HERE, "cycling_lp.json")], env=env,
                                  capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            self.fail("forces_and_rest did not return within 120 s: GLPK cycles again")
        self.assertEqual(done.returncode, 0, done.stderr)
        capacity = json.loads(done.stdout)
        directions = ("+x", "-x", "+y", "-y", "+z", "-z")
        self.assertEqual({capacity["status"][a] for a in directions}, {"optimal"})
        for a in directions:
            self.assertGreater(capacity[a], 0.0, a)  # every direction holds some multiple of its weight
            self.assertLess(capacity[a], 1e6, a)


if __name__ == "__main__":
    unittest.main()
