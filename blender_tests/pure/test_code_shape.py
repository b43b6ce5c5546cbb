"""The code's shape limits: no function body in native/src over 120 lines, no lambda there over
40 (the add-on's parameter limit is test_parameters.py's).

A body's length is counted in physical lines, from the line of its opening brace to the line of
its closing brace, both included; a function's lines include those of the lambdas inside it,
and each lambda is also measured alone. The C++ is read by a brace-matching scan over the
source with its comments, string and character literals and preprocessor lines blanked (line
breaks kept), so it needs no compiler."""
import os
import re
import unittest

from helpers import ROOT

MAX_FUNCTION_LINES = 120
MAX_LAMBDA_LINES = 40

IDENT = re.compile(r"[A-Za-z_][A-Za-z_0-9]*")
KEYWORDS_BEFORE_BODY = {"const", "noexcept", "override", "final", "mutable", "constexpr", "consteval",
                        "volatile", "try", "static"}


def blank(source):
    """The source with comments, string and character literals (raw strings too) and
    preprocessor lines replaced by spaces, line breaks kept: what is left is code only. A quote
    inside a number (10'000) is a digit separator, not a character literal."""
    out = list(source)
    n = len(source)
    i = 0
    line_start = True

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = source[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if line_start and c in " \t":
            i += 1
            continue
        if line_start and c == "#":
            j = i
            while j < n and source[j] != "\n":
                if source[j] == "\\" and j + 1 < n and source[j + 1] == "\n":
                    j += 2
                    continue
                if source.startswith("/*", j):
                    end = source.find("*/", j + 2)
                    j = n if end < 0 else end + 2
                    continue
                j += 1
            wipe(i, j)
            i = j
            continue
        line_start = False
        if source.startswith("//", i):
            j = source.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif source.startswith("/*", i):
            j = source.find("*/", i + 2)
            j = n if j < 0 else j + 2
            wipe(i, j)
            i = j
        elif c == '"':
            word = re.search(r"[A-Za-z_0-9]*$", source[max(0, i - 3):i]).group(0)
            if word.endswith("R") and word in ("R", "uR", "UR", "LR", "u8R"):
                m = re.match(r'"([^()\\ \t\n]{0,16})\(', source[i:])
                if m:
                    end = source.find(")" + m.group(1) + '"', i)
                    j = n if end < 0 else end + len(m.group(1)) + 2
                    wipe(i, j)
                    i = j
                    continue
            j = i + 1
            while j < n and source[j] != '"' and source[j] != "\n":
                j += 2 if source[j] == "\\" else 1
            wipe(i, min(j + 1, n))
            i = j + 1
        elif c == "'":
            token = re.search(r"[A-Za-z_0-9.']*$", source[:i]).group(0)
            if token[:1].isdigit() or (token[:1] == "." and token[1:2].isdigit()):
                i += 1  # a digit separator
                continue
            j = i + 1
            while j < n and source[j] != "'" and source[j] != "\n":
                j += 2 if source[j] == "\\" else 1
            wipe(i, min(j + 1, n))
            i = j + 1
        else:
            i += 1
    return "".join(out)


def tokens(code):
    """[(text, offset)]: identifiers, numbers, and every other non-space character alone
    ('->' and '::' as one token each)."""
    out = []
    for m in re.finditer(r"[A-Za-z_][A-Za-z_0-9]*|\d[\w.']*|->|::|\S", code):
        out.append((m.group(0), m.start()))
    return out


def matching_back(toks, k, close, open_):
    """Index of the token opening the group that toks[k] (== close) closes, or -1."""
    depth = 0
    for j in range(k, -1, -1):
        if toks[j][0] == close:
            depth += 1
        elif toks[j][0] == open_:
            depth -= 1
            if depth == 0:
                return j
    return -1


def is_lambda(toks, k):
    """Whether the '{' at toks[k] opens a lambda's body: [captures] {, or [captures](params)
    with specifiers and a trailing return type between the ')' and the '{'."""
    j = k - 1
    # a trailing return type (names, '::', '<', '>', ',', '*', '&') back to its '->'
    for m in range(k - 1, -1, -1):
        t = toks[m][0]
        if t == "->":
            j = m - 1
            break
        if not (IDENT.fullmatch(t) or t in ("::", "<", ">", ",", "*", "&")):
            break
    while j >= 0 and toks[j][0] in KEYWORDS_BEFORE_BODY:
        j -= 1
    if j >= 0 and toks[j][0] == ")":
        o = matching_back(toks, j, ")", "(")
        if o > 0 and toks[o - 1][0] in ("noexcept",):
            j = o - 2
            while j >= 0 and toks[j][0] in KEYWORDS_BEFORE_BODY:
                j -= 1
    if j < 0:
        return False
    if toks[j][0] == ")":
        o = matching_back(toks, j, ")", "(")
        if o <= 0:
            return False
        j = o - 1
    if toks[j][0] != "]":
        return False
    o = matching_back(toks, j, "]", "[")
    if o < 0:
        return False
    if o > 0 and toks[o - 1][0] == "operator":
        return False
    if o > 0 and toks[o - 1][0] == "[":
        return False  # an attribute [[...]]
    return True


def head_kind(head):
    """What a '{' at namespace or class level opens, from the tokens since the statement's
    start: 'scope' (namespace, class, struct, union, extern block), 'function', or 'other' (an
    enum's or a variable's braces)."""
    names = [t for t, _ in head]
    # template parameter lists say nothing about what follows them
    while "template" in names:
        at = names.index("template")
        if at + 1 < len(names) and names[at + 1] == "<":
            depth, e = 0, at + 1
            for e in range(at + 1, len(names)):
                depth += {"<": 1, ">": -1}.get(names[e], 0)
                if depth == 0:
                    break
            names = names[:at] + names[e + 1:]
        else:
            names = names[:at] + names[at + 1:]
    first_paren = names.index("(") if "(" in names else len(names)
    if "namespace" in names or "extern" in names[:first_paren] and "(" not in names:
        return "scope"
    if "enum" in names[:first_paren]:
        return "other"
    if any(w in names[:first_paren] for w in ("class", "struct", "union")):
        return "scope"
    if "(" not in names:
        return "other"
    depth = 0
    for k, t in enumerate(names):
        depth += {"(": 1, ")": -1, "[": 1, "]": -1}.get(t, 0)
        if t == "=" and depth == 0 and (k == 0 or names[k - 1] != "operator"):
            return "other"
    return "function" if depth == 0 else "other"


def in_init_list(head):
    """Whether the head ends inside a constructor's member initialiser list (a single ':' after
    the parameter list's ')'), where name{...} initialises a member."""
    names = [t for t, _ in head]
    depth = 0
    closed = False
    for k, t in enumerate(names):
        if t == "(":
            depth += 1
        elif t == ")":
            depth -= 1
            if depth == 0:
                closed = True
        elif t == ":" and depth == 0 and closed:
            return True
    return False


def measure(source):
    """[(kind, first line, lines)] of every function body ('function') and lambda body
    ('lambda') in a C++ source, lines 1-based."""
    code = blank(source)
    toks = tokens(code)
    line_at = []
    line = 1
    for ch in code:
        line_at.append(line)
        if ch == "\n":
            line += 1
    found = []
    stack = []  # (kind, token index of '{')
    head_start = 0  # first token of the statement at the innermost scope level
    for k, (t, offset) in enumerate(toks):
        at_scope = not stack or stack[-1][0] == "scope"
        if t == "{":
            if is_lambda(toks, k):
                kind = "lambda"
            elif at_scope:
                head = toks[head_start:k]
                if in_init_list(head) and head and (IDENT.fullmatch(head[-1][0]) or head[-1][0] == ">") \
                        and head[-1][0] not in KEYWORDS_BEFORE_BODY:
                    kind = "member-init"
                else:
                    kind = head_kind(head)
            else:
                kind = "block"
            stack.append((kind, k))
            if kind == "scope":
                head_start = k + 1
        elif t == "}":
            if not stack:
                continue
            kind, opened = stack.pop()
            if kind in ("function", "lambda"):
                first = line_at[toks[opened][1]]
                found.append((kind, first, line_at[offset] - first + 1))
            if kind != "member-init" and (not stack or stack[-1][0] == "scope"):
                head_start = k + 1
        elif t == ";" and at_scope:
            head_start = k + 1
        elif t == ":" and at_scope and k > 0 and toks[k - 1][0] in ("public", "private", "protected"):
            head_start = k + 1
    return sorted(found, key=lambda f: f[1])


def native_offenders():
    """["path:line: kind of N lines"] over native/src."""
    out = []
    for folder, _dirs, files in os.walk(os.path.join(ROOT, "native", "src")):
        for name in sorted(files):
            if not name.endswith((".cpp", ".hpp")):
                continue
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, ROOT).replace(os.sep, "/")
            for kind, first, lines in measure(open(path, encoding="utf-8").read()):
                limit = MAX_FUNCTION_LINES if kind == "function" else MAX_LAMBDA_LINES
                if lines > limit:
                    out.append(f"{rel}:{first}: {kind} of {lines} lines (at most {limit})")
    return out


def numbered(body_lines, head="void f() {", tail="}"):
    """A function whose body spans `body_lines` lines, braces' lines included."""
    inner = [f"  x += {k};" for k in range(body_lines - 2)]
    return "\n".join([head] + inner + [tail]) + "\n"


class Scanner(unittest.TestCase):
    def test_a_function_of_120_lines_passes_and_121_fails(self):
        self.assertEqual(measure(numbered(120)), [("function", 1, 120)])
        self.assertEqual(measure(numbered(121)), [("function", 1, 121)])

    def test_the_body_counts_from_the_opening_brace_line(self):
        src = "int\nf(int a,\n  int b)\n{\n  return a + b;\n}\n"
        self.assertEqual(measure(src), [("function", 4, 3)])

    def test_a_lambda_is_measured_alone(self):
        lam = ["  auto g = [&](int y) -> int {"] + [f"    y += {k};" for k in range(39)] + ["    return y;", "  };"]
        src = "void f() {\n  int x = 0;\n" + "\n".join(lam) + "\n  x = g(x);\n}\n"
        self.assertEqual(measure(src), [("function", 1, 46), ("lambda", 3, 42)])

    def test_lambdas_without_parameters_nested_and_as_arguments(self):
        src = ("void f() {\n"
               "  auto a = [&] {\n"
               "    auto b = [x](int k) mutable {\n"
               "      return k;\n"
               "    };\n"
               "  };\n"
               "  std::sort(v.begin(), v.end(), [](int p, int q) noexcept {\n"
               "    return p < q; });\n"
               "}\n")
        self.assertEqual(measure(src), [("function", 1, 9), ("lambda", 2, 5), ("lambda", 3, 3), ("lambda", 7, 2)])

    def test_braces_in_comments_strings_and_characters_do_not_count(self):
        src = ('void f() {\n'
               '  // }\n'
               '  /* } { */ const char* s = "}{\\"}";\n'
               "  char c = '}', d = '\\'';\n"
               '  auto r = R"x(})x";\n'
               "  int n = 10'000;\n"
               '#define CLOSE }\n'
               '}\n'
               'void g() {\n'
               '}\n')
        self.assertEqual(measure(src), [("function", 1, 8), ("function", 9, 2)])

    def test_blocks_classes_namespaces_and_initialisers_are_not_functions(self):
        src = ("namespace a {\n"
               "namespace {\n"
               "const int table[] = {\n"
               "  1, 2,\n"
               "};\n"
               "enum class E { x, y };\n"
               "struct S : B {\n"
               " public:\n"
               "  S(int v) : v_{v}, w_(v) {\n"
               "    if (v) {\n"
               "      v_ = 2;\n"
               "    }\n"
               "  }\n"
               "  int operator[](int i) const { return i; }\n"
               "  int v_{0};\n"
               "  int w_;\n"
               "};\n"
               "}  // namespace\n"
               "template <class T>\n"
               "T S2::g(T t) const noexcept {\n"
               "  return t;\n"
               "}\n"
               "void h(const O& o = {}) ;\n"
               "extern \"C\" {\n"
               "int c_fn(int) {\n"
               "  return 0;\n"
               "}\n"
               "}\n"
               "}\n")
        self.assertEqual(measure(src), [("function", 9, 5), ("function", 14, 1), ("function", 20, 3),
                                        ("function", 25, 3)])


class Limits(unittest.TestCase):
    def test_native_functions_and_lambdas_are_short(self):
        offenders = native_offenders()
        self.assertEqual(offenders, [], "split these by role:\n" + "\n".join(offenders))


if __name__ == "__main__":
    unittest.main()
