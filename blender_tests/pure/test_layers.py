"""The add-on's import rule (DESIGN.md): imports point down only,

    ui -> operators -> live -> props -> blend -> plane_search -> pipeline -> {stages, fab} -> core -> native,

a module may import its own folder's modules (an operator module only operators/progress.py, the
helpers they share: one operator never asks another), and no import circle exists. Every import counts,
lazy ones inside functions too, except those inside register()/unregister() (the package's
__init__ imports its top layers there). Checked by parsing every module's source."""
import ast
import os
import tempfile
import unittest

from helpers import ROOT

PACKAGE = os.path.join(ROOT, "addon", "wiresculpt")
# Layer of each top-level part of the package: a module may import parts of a lower number, or of
# its own part.
LAYERS = {"ui": 8, "operators": 7, "live": 6.5, "props": 6, "blend": 5, "plane_search": 4.5, "pipeline": 4, "stages": 3,
          "fab": 3, "core": 2, "native": 1, "_wiresculpt": 0}
# The one module of operators/ that the others may import: what their modals share.
OPERATORS_SHARED = {"operators.progress"}


def modules():
    """{dotted name below wiresculpt: path} of every module of the package."""
    found = {}
    for folder, _dirs, files in os.walk(PACKAGE):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, PACKAGE)[:-3].replace(os.sep, ".")
                found["" if rel == "__init__" else rel.removesuffix(".__init__")] = path
    return found


def imports(name, path, known):
    """[(line, imported module)] of the module `name`, relative imports resolved, outside
    register()/unregister()."""
    tree = ast.parse(open(path, encoding="utf-8").read(), path)
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.name in ("register", "unregister"):
            skip.update(id(n) for n in ast.walk(node))
    package = name.split(".") if path.endswith("__init__.py") else name.split(".")[:-1]
    package = [p for p in package if p]
    out = []
    for node in ast.walk(tree):
        if id(node) in skip or not isinstance(node, ast.ImportFrom) or not node.level:
            if isinstance(node, ast.Import) and id(node) not in skip:
                out += [(node.lineno, a.name[len("wiresculpt."):]) for a in node.names
                        if a.name.startswith("wiresculpt.")]
            continue
        base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
        stem = base + (node.module.split(".") if node.module else [])
        for alias in node.names:
            full = ".".join(stem + [alias.name])
            out.append((node.lineno, full if full in known or alias.name == "_wiresculpt" else ".".join(stem)))
    return out


def part(module):
    return module.split(".")[0]


class Layers(unittest.TestCase):
    def setUp(self):
        self.known = modules()
        self.graph = {name: imports(name, path, self.known) for name, path in self.known.items()}

    def test_every_part_has_a_layer(self):
        for name in self.known:
            if name:
                self.assertIn(part(name), LAYERS, f"{name}: add its part to DESIGN.md's layers and LAYERS")

    def test_imports_point_down(self):
        wrong = []
        for name, found in self.graph.items():
            if not name:
                continue  # the package's __init__: imports only inside register()
            for line, target in found:
                if part(target) == part(name):
                    continue
                if LAYERS[part(target)] >= LAYERS[part(name)]:
                    wrong.append(f"{self.known[name]}:{line}: {name} imports {target}, a layer above or beside it")
        self.assertEqual(wrong, [])

    def test_operators_do_not_import_each_other(self):
        wrong = [f"{self.known[name]}:{line}: {name} imports {target}"
                 for name, found in self.graph.items() if part(name) == "operators" and name != "operators"
                 for line, target in found
                 if part(target) == "operators" and target not in OPERATORS_SHARED | {"operators"}]
        self.assertEqual(wrong, [])

    def test_no_import_circle(self):
        edges = {name: {t for _line, t in found if t in self.known} for name, found in self.graph.items()}
        state, circles = {}, []

        def visit(node, trail):
            state[node] = "open"
            for nxt in sorted(edges.get(node, ())):
                if state.get(nxt) == "open":
                    circles.append(" -> ".join(trail[trail.index(nxt):] + [nxt]))
                elif nxt not in state:
                    visit(nxt, trail + [nxt])
            state[node] = "done"

        for name in sorted(edges):
            if name not in state:
                visit(name, [name])
        self.assertEqual(circles, [])

    def imports_of_source(self, name, source):
        """imports() of a made-up module `name` whose text is `source`."""
        with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
            f.write(source)
        try:
            return imports(name, f.name, self.known)
        finally:
            os.remove(f.name)

    def test_the_checker_sees_a_wrong_import(self):
        """The parser resolves relative imports: a made-up module of core importing props is
        found, so the rule above can fail."""
        found = self.imports_of_source("core.fake", "from ..props import material_of\nfrom . import files\n")
        self.assertEqual([t for _l, t in found], ["props", "core.files"])
        self.assertGreater(LAYERS[part("props")], LAYERS[part("core.fake")])

    def test_the_checker_sees_an_operator_importing_another(self):
        """An operator module importing another (not the shared progress helpers) is found, so the
        rule above can fail."""
        found = self.imports_of_source("operators.fake",
                                       "from .optimize import running\nfrom .progress import JOIN_SECONDS\n")
        targets = [t for _l, t in found]
        self.assertEqual(targets, ["operators.optimize", "operators.progress"])
        self.assertEqual([t for t in targets if t not in OPERATORS_SHARED], ["operators.optimize"])


if __name__ == "__main__":
    unittest.main()
