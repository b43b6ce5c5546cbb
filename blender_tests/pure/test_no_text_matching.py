"""No Python code of the add-on or the scripts decides by the text of a native or stage message.

Causes travel as codes (an enum in C++, a string constant in Python) with their figures, and the
sentence a user reads is made in one place from them: code that tests a message's words would
silently change what it does when the sentence is reworded. An ast scan of addon/wiresculpt and
scripts/ flags every test of a message-like value:

- `in` or `not in` with such a value on the right (words searched for in it), or on the left of a
  string, a constant's name or a tuple of them; `==` or `!=` between one and a string, an
  f-string or a constant's name (comparing two messages, or one with None or "", is allowed: it
  asks whether it changed or whether there is one; so is looking a whole message up among others);
- `.startswith`, `.endswith`, `.find`, `.rfind`, `.index`, `.rindex`, `.count`, `.partition` and
  `.rpartition` called on one, and `.split`/`.rsplit` of one at words or at a constant's name
  (cutting it at punctuation, ";", is allowed);
- `.startswith`/`.endswith` of anything with words made at run time from a constant's name and a
  value (`line.startswith(kind + DASH)`: a line's kind read back from its words);
- an `re` function (`re.search`, `re.match`, ...) or a compiled pattern's method given one.

Message-like: a name (or attribute) called `reason`, `message`, `msg`, `error`, `err`, `why`,
`verdict` or `what` (or ending in `_reason`, `_message`, ...), a subscript or `.get` of such a key
(`design["reason"]`, `failure.get("message")`), `str(exc)` or `exc.args` of a name an `except ... as`
binds, a `.what()` call, a name assigned one of those, and any of those through `.lower()`,
`.strip()`, `.split()`, a slice or an index, `x or ""` or an f-string, and what a loop or a
comprehension takes from a list of messages (LIST_WORDS: `for n in size_warnings(...)`,
`for limit in limits`, `design["warnings"]`). The scanner is tested on snippets whose verdict is
known by hand, among them each fault it was extended to catch.
"""
import ast
import functools
import os
import unittest

from helpers import ROOT

WORDS = ("reason", "message", "msg", "error", "err", "why", "verdict", "what")
TESTS = ("startswith", "endswith", "find", "rfind", "index", "rindex", "count", "partition", "rpartition")
RE_FUNCTIONS = ("search", "match", "fullmatch", "findall", "finditer", "sub", "subn", "split")
PATTERN_METHODS = ("search", "match", "fullmatch", "findall", "finditer", "sub", "subn")
SAME_TEXT = ("lower", "upper", "casefold", "strip", "lstrip", "rstrip", "split", "rsplit", "splitlines")
SCANNED = ("addon/wiresculpt", "scripts")
# Lists of messages: a name (or attribute) so called, or ending so (`size_warnings`), or a call of a
# function so named (`broken_limits(design)`); what a `for` or a comprehension takes from one is a message.
LIST_WORDS = ("warnings", "notes", "limits", "phrases", "reasons", "messages", "errors")
SPLITS = ("split", "rsplit")

# Offenders that wait for codes nothing gives yet (none now: the corpus report's kinds of reason
# read the verdict's codes, scripts/corpus.py cause_kind).
WAITING = set()


def _word(name):
    """A message's name; not a constant's (ERROR, NO_WIRES: the names of kinds and sentences)."""
    if name.isupper():
        return False
    name = name.lower()
    return any(name == w or name.endswith("_" + w) for w in WORDS)


def _list_word(name):
    name = name.lower()
    return not name.isupper() and any(name == w or name.endswith("_" + w) for w in LIST_WORDS)


def _message_list(node):
    """Whether `node` is a list of messages (LIST_WORDS)."""
    if isinstance(node, ast.Name):
        return _list_word(node.id)
    if isinstance(node, ast.Attribute):
        return _list_word(node.attr)
    if isinstance(node, ast.Subscript):  # design["warnings"]
        key = node.slice
        return isinstance(key, ast.Constant) and isinstance(key.value, str) and _list_word(key.value)
    if isinstance(node, ast.Call):
        f = node.func
        if isinstance(f, ast.Attribute) and f.attr == "get" and node.args:  # design.get("warnings", [])
            key = node.args[0]
            return isinstance(key, ast.Constant) and isinstance(key.value, str) and _list_word(key.value)
        return _message_list(f)
    return False


def _words(node):
    """Whether `node` is a string constant with a letter in it (words, not a separator such as ";")."""
    return isinstance(node, ast.Constant) and isinstance(node.value, str) and any(c.isalpha() for c in node.value)


def _pieces(node):
    """The leaves of a string made with `+`."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _pieces(node.left) + _pieces(node.right)
    return [node]


def _sentence_pieces(node):
    """Whether `node` joins a constant's name with a value (`kind + DASH`, f"{kind}{DASH}"): words
    made at run time from the named pieces a message is built from (a file name's fixed pieces,
    "." + JOURNAL + ".", are not)."""
    if isinstance(node, ast.JoinedStr):
        parts = [v.value for v in node.values if isinstance(v, ast.FormattedValue)]
    elif isinstance(node, ast.BinOp):
        parts = _pieces(node)
    else:
        return False
    named = any(_sentence(p) and not isinstance(p, (ast.Constant, ast.JoinedStr)) for p in parts)
    varying = any(isinstance(p, (ast.Name, ast.Attribute)) and not _sentence(p) for p in parts)
    return named and varying


def _sentences(node):
    """Words a message could be looked up in: a sentence (_sentence) or a tuple, list or set of them."""
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return any(_sentence(e) for e in node.elts)
    return _sentence(node)


def _sentence(node):
    """Words a message could be compared with: a string (not "") or f-string, or a constant's name."""
    if isinstance(node, ast.Constant):
        return isinstance(node.value, str) and node.value != ""
    if isinstance(node, ast.Name):
        return node.id.isupper()
    if isinstance(node, ast.Attribute):
        return node.attr.isupper()
    return isinstance(node, ast.JoinedStr)


class Scanner(ast.NodeVisitor):
    """Collects (line, function, what) for each test of a message-like value in one module."""

    def __init__(self):
        self.found, self.function, self.caught, self.assigned = [], "<module>", set(), set()
        self.looped = {}  # name -> whether the loop or comprehension binding it now takes it from messages

    def scan(self, tree):
        for node in ast.walk(tree):  # every name an except clause binds, anywhere in the module
            if isinstance(node, ast.ExceptHandler) and node.name:
                self.caught.add(node.name)
        for _ in range(2):  # names assigned a message, also through another such name
            for node in ast.walk(tree):
                if isinstance(node, ast.Assign) and self.message(node.value):
                    self.assigned.update(t.id for t in node.targets if isinstance(t, ast.Name))

        self.visit(tree)
        return self.found

    def message(self, node):
        """Whether `node` is a message-like value."""
        if isinstance(node, ast.Name):
            if node.id in self.looped:
                return self.looped[node.id]
            return _word(node.id) or node.id in self.assigned
        if isinstance(node, ast.Attribute):
            return _word(node.attr) or (node.attr == "args" and isinstance(node.value, ast.Name)
                                        and node.value.id in self.caught)
        if isinstance(node, ast.Subscript):
            key = node.slice
            if isinstance(key, ast.Constant):
                return isinstance(key.value, str) and _word(key.value) or (
                    isinstance(key.value, int) and self.message(node.value))
            return isinstance(key, ast.Slice) and self.message(node.value)
        if isinstance(node, ast.BoolOp):
            return any(self.message(v) for v in node.values)
        if isinstance(node, ast.JoinedStr):
            return any(self.message(v.value) for v in node.values if isinstance(v, ast.FormattedValue))
        if isinstance(node, ast.Call):
            f = node.func
            if isinstance(f, ast.Name) and f.id == "str" and len(node.args) == 1:
                a = node.args[0]
                return (isinstance(a, ast.Name) and a.id in self.caught) or self.message(a)
            if isinstance(f, ast.Attribute):
                if f.attr == "what":
                    return True
                if f.attr == "get" and node.args and isinstance(node.args[0], ast.Constant):
                    return isinstance(node.args[0].value, str) and _word(node.args[0].value)
                if f.attr in SAME_TEXT:
                    return self.message(f.value)
        return False

    def flag(self, node, what):
        self.found.append((node.lineno, self.function, what))

    def visit_FunctionDef(self, node):
        outer, self.function = self.function, node.name if self.function == "<module>" else self.function
        self.generic_visit(node)
        self.function = outer

    visit_AsyncFunctionDef = visit_FunctionDef

    def _bound(self, target, iterable, visit):
        """Runs `visit` with `target` (a loop's or comprehension's name) a message when `iterable` is
        a list of messages, and not one otherwise (it shadows any other binding meanwhile)."""
        if not isinstance(target, ast.Name):
            return visit()
        had, old = target.id in self.looped, self.looped.get(target.id)
        self.looped[target.id] = _message_list(iterable)
        try:
            return visit()
        finally:
            if had:
                self.looped[target.id] = old
            else:
                del self.looped[target.id]

    def visit_For(self, node):
        self.visit(node.iter)
        self._bound(node.target, node.iter, lambda: [self.visit(n) for n in node.body + node.orelse])

    def _comprehension(self, node, parts):
        def visit(generators):
            if not generators:
                for part in parts:
                    self.visit(part)
                return
            first = generators[0]
            self.visit(first.iter)

            def rest():
                for condition in first.ifs:
                    self.visit(condition)
                visit(generators[1:])
            self._bound(first.target, first.iter, rest)
        visit(node.generators)

    def visit_ListComp(self, node):
        self._comprehension(node, [node.elt])

    visit_SetComp = visit_GeneratorExp = visit_ListComp

    def visit_DictComp(self, node):
        self._comprehension(node, [node.key, node.value])

    def visit_Compare(self, node):
        sides = [node.left] + node.comparators
        for op, left, right in zip(node.ops, sides, sides[1:]):
            if isinstance(op, (ast.In, ast.NotIn)) and (self.message(right) or self.message(left) and _sentences(right)):
                self.flag(node, "`in` on a message")
            elif isinstance(op, (ast.Eq, ast.NotEq)) and any(
                    self.message(a) and _sentence(b) for a, b in ((left, right), (right, left))):
                self.flag(node, "`==` on a message")
        self.generic_visit(node)

    def visit_Call(self, node):
        f = node.func
        if isinstance(f, ast.Attribute):
            if f.attr in TESTS and self.message(f.value):
                self.flag(node, f".{f.attr}() on a message")
            elif f.attr in SPLITS and self.message(f.value) and node.args and (
                    _words(node.args[0]) or _sentence(node.args[0]) and not isinstance(node.args[0], ast.Constant)):
                self.flag(node, f".{f.attr}() of a message at its words")
            elif f.attr in ("startswith", "endswith") and node.args and _sentence_pieces(node.args[0]):
                self.flag(node, f".{f.attr}() of a sentence's pieces")
            elif (f.attr in RE_FUNCTIONS and isinstance(f.value, ast.Name) and f.value.id == "re"
                  and any(self.message(a) for a in node.args)):
                self.flag(node, f"re.{f.attr}() over a message")
            elif (f.attr in PATTERN_METHODS and not (isinstance(f.value, ast.Name) and f.value.id == "re")
                  and node.args and self.message(node.args[0]) and not self.message(f.value)):
                self.flag(node, f"a pattern's .{f.attr}() over a message")
        self.generic_visit(node)


def offences(source):
    """[(line, top-level function, what)] of the source text."""
    return Scanner().scan(ast.parse(source))


@functools.lru_cache(maxsize=None)
def tree_offences():
    """{(path relative to the repository, top-level function): [(line, what)]} over SCANNED."""
    out = {}
    for top in SCANNED:
        for folder, dirs, files in os.walk(os.path.join(ROOT, top)):
            dirs[:] = sorted(d for d in dirs if d != "__pycache__")
            for name in sorted(files):
                if not name.endswith(".py"):
                    continue
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as f:
                    source = f.read()
                rel = os.path.relpath(path, ROOT).replace(os.sep, "/")
                for line, function, what in offences(source):
                    out.setdefault((rel, function), []).append((line, what))
    return out


def flagged(snippet):
    return [what for _line, _function, what in offences(snippet)]


class TheScanner(unittest.TestCase):
    def test_it_flags_tests_of_a_message(self):
        self.assertEqual(flagged('reason.endswith("x")'), [".endswith() on a message"])
        self.assertEqual(flagged('"too close" in design["reason"]'), ["`in` on a message"])
        self.assertEqual(flagged('import re\nre.search(r"the closest: (.*)", reason)'), ["re.search() over a message"])
        self.assertEqual(flagged('message.startswith("crossing")'), [".startswith() on a message"])
        self.assertEqual(flagged('any(w in message for w in WORDS)'), ["`in` on a message"])
        self.assertEqual(flagged('failure.get("message") == "too short"'), ["`==` on a message"])
        self.assertEqual(flagged('solved["reason"].split(";")[0].endswith("x")'), [".endswith() on a message"])
        self.assertEqual(flagged('(design.get("reason") or "").lower().find("close")'), [".find() on a message"])
        self.assertEqual(flagged('try:\n    f()\nexcept ValueError as exc:\n    if "budget" in str(exc): pass'),
                         ["`in` on a message"])
        self.assertEqual(flagged('text = str(err)\nre.match("x", text)'), ["re.match() over a message"])
        self.assertEqual(flagged('PATTERN.search(self.error_message)'), ["a pattern's .search() over a message"])
        self.assertEqual(flagged('e.what().endswith("x")'), [".endswith() on a message"])
        self.assertEqual(flagged('design.get("reason") in SETUP_REASONS'), ["`in` on a message"])
        # what a list of messages holds (fab/export's stock notes picked by their first word)
        self.assertEqual(flagged('[n for n in size_warnings(d, *stock) if n.startswith("wire ")]'),
                         [".startswith() on a message"])
        self.assertEqual(flagged('for w in design["warnings"]:\n    if w.endswith("mm"): pass'),
                         [".endswith() on a message"])
        # a limit's phrase searched for words (core/limits.hooks_may_help before its codes)
        self.assertEqual(flagged('any(words in limit for limit in limits for words in HOOK_LIMITS)'),
                         ["`in` on a message"])
        # a line tested against its kind's words (core/live_verdict.kind_of before Live kept the kind)
        self.assertEqual(flagged('line.startswith(kind + DASH)'), [".startswith() of a sentence's pieces"])
        self.assertEqual(flagged('text.endswith(f"{shown}{MORE}")'), [".endswith() of a sentence's pieces"])
        # a reason cut at its words for display and grouping (core/plane_faults.structural_fault)
        self.assertEqual(flagged('reason = reason.split("allowed at every crossing, ", 1)[-1]'),
                         [".split() of a message at its words"])
        # the limits read back from the verdict's line (ui/stale.live_hint before Live kept their codes)
        self.assertEqual(flagged('hooks_may_help(verdict.split(live_verdict.DASH, 1)[-1].split("; "))'),
                         [".split() of a message at its words"])

    def test_it_leaves_other_strings_and_codes_alone(self):
        self.assertEqual(flagged('name.endswith(".json")'), [])
        self.assertEqual(flagged('path.startswith("//")'), [])
        self.assertEqual(flagged('"too_close" in solved.get("reason_causes", ())'), [])
        self.assertEqual(flagged('n["status"] == "too_close"'), [])
        self.assertEqual(flagged('if not reason: pass\nif reason == "": pass\nif error is None: pass'), [])
        self.assertEqual(flagged('verdict["stable"] == True'), [])
        self.assertEqual(flagged('if STATE.verdict != shown: pass'), [])  # changed, whatever it says
        self.assertEqual(flagged('kind == live_verdict.ERROR'), [])  # a kind's constant, not a message
        self.assertEqual(flagged('reason == NO_WIRES'), ["`==` on a message"])
        self.assertEqual(flagged('reason = design["reason"].split(";", 1)[0][:160]'), [])  # cut, not tested
        self.assertEqual(flagged('import re\nre.sub(r"[^a-z]", "-", wire["name"])'), [])
        self.assertEqual(flagged('for n in notes:\n    print(n.split("; "))'), [])  # cut at punctuation
        self.assertEqual(flagged('[code for code, _p in limit_records(d) if code in HOOK_LIMITS]'), [])
        self.assertEqual(flagged('name.startswith(PREFIX)'), [])  # a constant alone: a name's prefix
        self.assertEqual(flagged('path.endswith(os.sep + "x")'), [])
        self.assertEqual(flagged('entry.startswith("." + JOURNAL + ".")'), [])  # a file name's fixed pieces
        # a whole message looked up among others (a repeat dropped), not searched for words
        self.assertEqual(flagged('warnings = [w for w in design.get("warnings") or [] if w not in shown]'), [])

    def test_the_function_is_the_top_level_one(self):
        self.assertEqual(offences('def f():\n    def g(message):\n        return message.endswith("x")\n'),
                         [(3, "f", ".endswith() on a message")])


class TheTree(unittest.TestCase):
    def test_no_code_tests_a_message_s_text(self):
        found = tree_offences()
        unexpected = {k: v for k, v in found.items() if k not in WAITING}
        self.assertEqual(unexpected, {}, "tests of a message's text; give the cause a code instead")

    def test_the_lists_name_only_offenders_that_remain(self):
        found = tree_offences()
        self.assertEqual({k for k in WAITING if k not in found}, set(),
                         "listed but no longer offending: take them out of the list")


if __name__ == "__main__":
    unittest.main()
