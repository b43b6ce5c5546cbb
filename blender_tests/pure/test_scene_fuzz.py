"""The scene-file fuzz target's corpus replayed (scene_fuzz.py): every seed in
blender_tests/fuzz_scenes/ (the bundled globe's scene, corpus-style placements, plane search,
settings, and the findings of earlier runs, `finding-*.json`) and 300 fixed mutations of each go
through the batch's scene reader; each is read into bounded planes or refused in one line."""
import random
import tempfile
import unittest

import scene_fuzz

MUTATIONS = 300


class SceneFuzzCorpus(unittest.TestCase):
    def test_seeds_and_their_fixed_mutations(self):
        corpus = scene_fuzz.seeds()
        self.assertGreaterEqual(len(corpus), 6)
        outcomes = {"read": 0, "refused": 0}
        with tempfile.TemporaryDirectory() as folder:
            scene_fuzz.prepare(folder)
            for name, text in corpus:
                with self.subTest(name):
                    outcome = scene_fuzz.check(text, folder)
                    self.assertEqual(outcome, "refused" if name.startswith("finding-") else "read", name)
                for k in range(MUTATIONS):
                    mutant = scene_fuzz.mutate(random.Random(f"{name}:{k}"), text)
                    with self.subTest(f"{name} mutation {k}"):
                        outcomes[scene_fuzz.check(mutant, folder)] += 1
        # the mutations reach both ends: scenes that read and scenes refused
        self.assertGreater(outcomes["read"], 100)
        self.assertGreater(outcomes["refused"], 100)


if __name__ == "__main__":
    unittest.main()
