"""No Python function of the add-on takes more than MAX_PARAMETERS parameters (self and cls not
counted; *args and **kwargs count one each): a solve's progress, cancel and deadline travel as one
core.solve_context.SolveContext, not as closures passed by position. Checked by parsing every
module's source."""
import ast
import os
import unittest

from test_layers import PACKAGE

MAX_PARAMETERS = 8
# (module path below wiresculpt, function name) -> why it takes more
EXCEPTIONS = {
    ("ui/panel.py", "draw_item"): "Blender's UIList.draw_item signature, called by Blender",
    ("native.py", "stream_program"): "the binding's stream_program, one keyword argument each",
    ("fab/streaming.py", "__init__"): "StreamJob holds the arguments of one stream_program call",
}
# Still over the bound, in files this rule has not reached yet: each to take fewer parameters
# (the test fails when one is fixed, so that it leaves this list).
OUTSTANDING = set()


def parameter_count(args):
    names = [a.arg for a in args.posonlyargs + args.args + args.kwonlyargs]
    if names and names[0] in ("self", "cls"):
        names = names[1:]
    return len(names) + (args.vararg is not None) + (args.kwarg is not None)


def offenders(source, path):
    """[(line, function name, parameters)] of the functions and lambdas of `source` over MAX_PARAMETERS."""
    out = []
    for node in ast.walk(ast.parse(source, path)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            count = parameter_count(node.args)
            if count > MAX_PARAMETERS:
                out.append((node.lineno, getattr(node, "name", "<lambda>"), count))
    return out


class Parameters(unittest.TestCase):
    def test_no_function_takes_more_than_eight_parameters(self):
        found = set()
        wrong = []
        for folder, _dirs, files in os.walk(PACKAGE):
            for name in sorted(files):
                if not name.endswith(".py"):
                    continue
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, PACKAGE).replace(os.sep, "/")
                for line, function, count in offenders(open(path, encoding="utf-8").read(), path):
                    found.add((rel, function))
                    if (rel, function) not in EXCEPTIONS and (rel, function) not in OUTSTANDING:
                        wrong.append(f"{path}:{line}: {function} takes {count} parameters")
        self.assertEqual(wrong, [])
        self.assertLessEqual(len(EXCEPTIONS), 3)
        self.assertEqual((set(EXCEPTIONS) | OUTSTANDING) - found, set(), "no longer over the bound: take it off the list")

    def test_the_count_sees_a_long_signature(self):
        """Nine parameters are found, eight are not; self, *args and **kwargs as documented."""
        source = ("def nine(a, b, c, d, e, f, g, h, i): pass\n"
                  "def eight(a, b, c, d, e, f, g, h=None): pass\n"
                  "class C:\n"
                  "    def method(self, a, b, c, d, e, f, g, h): pass\n"
                  "    def starred(self, a, b, c, d, e, f, g, *args, **kwargs): pass\n")
        self.assertEqual([(n, c) for _l, n, c in offenders(source, "made-up")], [("nine", 9), ("starred", 9)])


if __name__ == "__main__":
    unittest.main()
