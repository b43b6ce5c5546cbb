"""Whether a stored design still matches the scene (core/stale.py), on hand-made designs: planes
moved, rotated, removed and added, ticks, the recorded target, settings and material, and the
float round trips that must not count as a change."""
import json
import math
import unittest

from wiresculpt.core import stale


def design():
    return {"wires": [
        {"id": 0, "name": "Slice A/0", "plane": {"origin": [0.0, 0.0, 0.01], "normal": [0.0, 0.0, 1.0]}},
        {"id": 1, "name": "Slice B/0", "plane": {"origin": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]}},
        {"id": 2, "name": "Slice B/1", "plane": {"origin": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]}},
        {"id": 3, "name": "Slice C/0", "plane": {"origin": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0]}},
    ]}


def planes():
    return {"Slice A": ((0.0, 0.0, 0.01), (0.0, 0.0, 1.0)), "Slice B": ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
            "Slice C": ((0.0, 0.0, 0.0), (0.0, 1.0, 0.0))}


TICKED = {("Slice A", 0), ("Slice B", 0), ("Slice B", 1), ("Slice C", 0)}
SETTINGS = {"min_segment": 0.015, "max_bend_deg": 120.0, "torque_fraction": None, "in_plane_tiebreak": False,
            "max_nodes": 200000}
MATERIAL = {"name": "steel", "wire_diameter": 0.003, "bending_stiffness": 0.73}
INPUTS = {"target": "Globe", "settings": SETTINGS, "material": MATERIAL}
LABELS = {"max_bend_deg": "Max Bend", "wire_diameter": "Wire Diameter", "name": "Material"}


def changes(p=None, ticked=TICKED, inputs=INPUTS, target="Globe", settings=SETTINGS, material=MATERIAL, d=None,
            names=None):
    now = stale.SceneNow(planes() if p is None else p, ticked, names, target, settings, material)
    return stale.changes(d or design(), now, inputs, LABELS)


def scene(target, mesh=None):
    """The scene now of the fixture's planes, ticks, settings and material, with `target` and `mesh`."""
    return stale.SceneNow(planes(), TICKED, None, target, SETTINGS, MATERIAL, mesh)


def renamed(mapping, p=None, ticked=TICKED):
    """(planes, ticked) of the scene after renaming its handles by `mapping` {old: new}."""
    p = planes() if p is None else p
    return ({mapping.get(n, n): v for n, v in p.items()}, {(mapping.get(n, n), i) for n, i in ticked})


class StaleTest(unittest.TestCase):
    def test_the_targets_mesh(self):
        """An edit or move of the target (another digest of its triangles, or MESH_CHANGED while it
        is not read again) makes the design an earlier one; not known, nothing is said."""
        V = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        digest = stale.mesh_digest(V, [[0, 1, 2]])
        self.assertEqual(digest, stale.mesh_digest(json.loads(json.dumps(V)), [(0, 1, 2)]))
        self.assertNotEqual(digest, stale.mesh_digest([V[0], V[1], [0.0, 1.0, 1e-12]], [[0, 1, 2]]))
        self.assertNotEqual(digest, stale.mesh_digest(V, [[0, 2, 1]]))
        inputs = dict(INPUTS, mesh=digest)
        said = stale.changes(design(), scene("Globe", mesh=digest), inputs, LABELS)
        self.assertEqual(said, [])
        for now in ("0" * 24, stale.MESH_CHANGED):
            said = stale.changes(design(), scene("Globe", mesh=now), inputs, LABELS)
            self.assertEqual(said, ["model Globe edited or moved"])
        self.assertEqual(stale.changes(design(), scene("Globe"), inputs, LABELS), [])
        # another target: that is what is said; a record without a digest (an older add-on's) says nothing
        self.assertEqual(stale.changes(design(), scene("Cube", mesh="0" * 24), inputs, LABELS), ["model changed"])
        self.assertEqual(changes(), [])

    def test_unchanged_scene_is_current(self):
        self.assertEqual(changes(), [])
        self.assertEqual(stale.stale_text([]), "")

    def test_json_and_float32_round_trips_are_not_changes(self):
        # the design as read back from its JSON; the handles' normals from a float32 matrix
        d = json.loads(json.dumps(design()))
        p = planes()
        c = math.cos(1e-7)
        p["Slice B"] = ((3e-8, 0.0, -2e-8), (c, math.sin(1e-7), 0.0))
        self.assertEqual(changes(p, d=d), [])
        self.assertEqual(changes(inputs=json.loads(json.dumps(INPUTS))), [])

    def test_moved_rotated_removed_and_added_planes_are_named(self):
        p = planes()
        p["Slice B"] = ((0.01, 0.0, 0.0), (1.0, 0.0, 0.0))  # 1 cm along its normal
        self.assertEqual(changes(p), ["plane Slice B moved"])
        self.assertEqual(stale.stale_text(changes(p)),
                         "From an earlier Optimize: plane Slice B moved; Optimize again")
        p = planes()
        p["Slice A"] = ((0.0, 0.0, 0.01), (0.0, math.sin(0.01), math.cos(0.01)))
        self.assertEqual(changes(p), ["plane Slice A rotated"])
        p = planes()
        del p["Slice C"]
        ticked = {t for t in TICKED if t[0] != "Slice C"}
        self.assertEqual(changes(p, ticked), ["plane Slice C removed"])
        self.assertEqual(changes(p, None), ["plane Slice C removed"])  # ticks unreadable: the plane says it
        self.assertEqual(changes(p, TICKED), ["plane Slice C removed"])  # its contour still ticked
        p = planes()
        p["Slice D"] = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
        self.assertEqual(changes(p), [])  # a new plane none of whose contours is ticked changes nothing
        self.assertEqual(changes(p, TICKED | {("Slice D", 0)}), ["plane Slice D added"])
        p = planes()
        p["Slice A"] = None  # flattened: no normal
        self.assertEqual(changes(p), ["plane Slice A rotated"])

    def test_sliding_or_spinning_within_its_plane_is_the_same_plane(self):
        p = planes()
        p["Slice A"] = ((0.05, -0.02, 0.01), (0.0, 0.0, 1.0))
        self.assertEqual(changes(p), [])

    def test_ticks(self):
        self.assertEqual(changes(ticked=TICKED - {("Slice B", 1)}),
                         ["contours ticked differently (Slice B #1 unticked)"])
        self.assertEqual(changes(ticked=TICKED | {("Slice C", 1)}),
                         ["contours ticked differently (Slice C #1 ticked)"])
        self.assertEqual(changes(ticked=set()),
                         ["contours ticked differently (Slice A #0 unticked, Slice B #0 unticked, "
                          "Slice B #1 unticked, 1 more)"])
        self.assertEqual(changes(ticked=None), ["contours ticked differently"])
        # a ticked contour of a plane that is gone and was never in the design
        self.assertEqual(changes(ticked=TICKED | {("Slice Z", 0)}), ["contours ticked differently (Slice Z #0 ticked)"])

    def test_target_settings_and_material(self):
        self.assertEqual(changes(target="Duck"), ["model changed"])
        self.assertEqual(changes(settings=dict(SETTINGS, max_bend_deg=90.0)), ["settings changed (Max Bend)"])
        self.assertEqual(changes(settings=dict(SETTINGS, torque_fraction=0.5)), ["settings changed (torque_fraction)"])
        self.assertEqual(changes(settings=None), ["settings changed"])
        self.assertEqual(changes(material=dict(MATERIAL, wire_diameter=0.002, name="brass", bending_stiffness=0.2)),
                         ["settings changed (Material, Wire Diameter)"])  # another material's numbers are its own
        # a preset scaled to another diameter: the diameter, not the numbers that follow it
        self.assertEqual(changes(material=dict(MATERIAL, wire_diameter=0.002, bending_stiffness=0.14)),
                         ["settings changed (Wire Diameter)"])
        self.assertEqual(changes(material=dict(MATERIAL, bending_stiffness=0.5)),
                         ["settings changed (bending_stiffness)"])
        self.assertEqual(changes(settings=dict(SETTINGS, in_plane_tiebreak=True)),
                         ["settings changed (in_plane_tiebreak)"])
        # a design without recorded inputs is compared by its planes and ticks only
        self.assertEqual(changes(inputs=None, target="Duck", settings=None), [])

    def test_several_changes_in_one_line(self):
        p = planes()
        p["Slice B"] = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
        said = changes(p, target="Duck", settings=dict(SETTINGS, max_bend_deg=90.0))
        self.assertEqual(stale.stale_text(said), "From an earlier Optimize: plane Slice B rotated, model changed, "
                                                 "settings changed (Max Bend); Optimize again")

    def test_a_renamed_plane_is_the_same_plane_under_its_new_name(self):
        p, ticked = renamed({"Slice B": "Front"})
        names = {"Slice A": "Slice A", "Slice B": "Front", "Slice C": "Slice C"}
        self.assertEqual(changes(p, ticked, names=names), [])
        # by name alone (a record without ids) it reads as one plane gone and another added
        self.assertEqual(changes(p, ticked), ["plane Slice B removed", "plane Front added"])
        p["Front"] = ((0.01, 0.0, 0.0), (1.0, 0.0, 0.0))
        self.assertEqual(changes(p, ticked, names=names), ["plane Front moved"])
        self.assertEqual(changes(renamed({"Slice B": "Front"})[0], ticked - {("Front", 1)}, names=names),
                         ["contours ticked differently (Front #1 unticked)"])

    def test_swapped_names_and_a_name_taken_by_another_plane(self):
        p, ticked = renamed({"Slice A": "Slice B", "Slice B": "Slice A"})
        names = {"Slice A": "Slice B", "Slice B": "Slice A", "Slice C": "Slice C"}
        self.assertEqual(changes(p, ticked, names=names), [])
        # Slice C deleted, Slice B renamed Slice C: one plane gone, the other compared under its new name
        p, ticked = renamed({"Slice B": "Slice C"}, {n: v for n, v in planes().items() if n != "Slice C"},
                            TICKED - {("Slice C", 0)})
        names = {"Slice A": "Slice A", "Slice B": "Slice C", "Slice C": None}
        self.assertEqual(changes(p, ticked, names=names), ["plane Slice C removed"])
        # a new plane that took a deleted plane's name is another plane
        names = {"Slice A": "Slice A", "Slice B": "Slice B", "Slice C": None}
        self.assertEqual(changes(names=names), ["plane Slice C removed", "plane Slice C added"])

    def test_current_names_by_recorded_id(self):
        recorded = ["Slice A", "Slice B", "Slice C"]
        ids = {"Slice A": "a", "Slice B": "b", "Slice C": "c"}
        handles = {"Slice A": "a", "Front": "b", "Slice C": "x"}
        self.assertEqual(stale.current_names(recorded, ids, handles),
                         {"Slice A": "Slice A", "Slice B": "Front", "Slice C": None})
        # no ids recorded (an older record, or a plane without one): by name
        self.assertEqual(stale.current_names(recorded, None, handles),
                         {"Slice A": "Slice A", "Slice B": None, "Slice C": "Slice C"})
        self.assertEqual(stale.current_names(recorded, {"Slice B": "b"}, {"Slice A": None, "Front": "b"}),
                         {"Slice A": "Slice A", "Slice B": "Front", "Slice C": None})
        self.assertEqual(stale.current_names(recorded, "not a dict", handles)["Slice C"], "Slice C")
        # a copy kept the id (Shift+D copies custom properties): the one of the recorded name is it,
        # and two copies neither of that name tell nothing
        self.assertEqual(stale.current_names(["Slice B"], ids, {"Slice B": "b", "Slice B.001": "b"}),
                         {"Slice B": "Slice B"})
        self.assertEqual(stale.current_names(["Slice B"], ids, {"Front": "b", "Slice B.001": "b"}),
                         {"Slice B": None})

    def test_wire_names_with_their_planes_names_now(self):
        names = {"Slice A": "Slice A", "Slice B": "Front", "Slice C": None}
        self.assertEqual(stale.renamed_wire("Slice B/1", names), "Front/1")
        self.assertEqual(stale.renamed_wire("Slice A/0", names), "Slice A/0")
        self.assertEqual(stale.renamed_wire("Slice C/0", names), "Slice C/0")  # gone: its last known name
        self.assertEqual(stale.renamed_wire("Slice B/1", None), "Slice B/1")
        self.assertEqual(stale.renamed_wire("no index", names), "no index")
        d = {"wires": [{"name": n} for n in ("A/0", "A/1", "A/10", "Slice A/0", "B/2")]}
        names = {"A": "Top", "Slice A": "Slice A", "B": "B"}
        self.assertEqual(stale.renamed_text("crossing 3 on wire A/1: it needs a bend; A/10 and Slice A/0 hold, "
                                            "A/0 slips", d, names),
                         "crossing 3 on wire Top/1: it needs a bend; Top/10 and Slice A/0 hold, Top/0 slips")
        self.assertEqual(stale.renamed_text("wire A/0", d, {"A": "A"}), "wire A/0")
        self.assertEqual(stale.renamed_text("", d, names), "")

    def test_wire_names(self):
        self.assertEqual(stale.wire_contour("Slice A/3"), ("Slice A", 3))
        self.assertEqual(stale.wire_contour("a/b/12"), ("a/b", 12))
        self.assertIsNone(stale.wire_contour("no index"))
        self.assertIsNone(stale.wire_contour("Slice A/x"))


if __name__ == "__main__":
    unittest.main()
