"""Why a placement of the slicing planes gives no stable design, read from its layered crossing
network (issue 15: "every scene ends stable or says why no nearby placement exists"). bpy-free,
numpy only; plane_search.py counts these faults over the candidates it screens and solves.

A fault is a tuple (kind, wires, other): `kind` one of KINDS, `wires` the names of the wires at
fault (sorted), `other` the names of the wires or planes that go with them (the wire a hinged wire
turns on, the two wires whose crossings come close), so that equal faults of many candidates count
as one cause. Structural faults come from the crossings alone, in this order (the first that
applies is the candidate's fault):

- "alone": a wire that crosses no other wire (nothing holds it);
- "apart": wires not connected to the largest part of the network through crossings;
- "hinge": a wire whose crossings all lie on one line (two planar wires cross only on their
  planes' common line, so a wire crossing only one other wire always hinges) or at one point: it
  turns about that line or point;
- "incomplete": none of those, and the layering's search reached max_nodes (a stable design may
  still exist);
- "dropped": none of those, and the hooks the screen's layering forbade (stages.layering.run's
  too_close: those the target shape cannot realise at crossings closer than 2 x min_segment along
  a wire, with no free bending point between them) decided the verdict: with them the hook-relaxed
  check passes. Named by the closest such gap's wire and the two wires crossing it there;
- "mechanism": the layering's hook-relaxed check finds a motion of several wires, or no hook
  configuration for another reason: its own words (`reason`), cut at the first ';'.

Faults of a candidate that passed the screen come from its full solve (see verdict_fault).
"""
import re

import numpy as np

WIRE_KINDS = ("alone", "apart", "hinge")  # faults that name the wires at fault
PASSED_KINDS = ("near", "close", "unstable", "stopped", "failed", "unsolved", "stable")  # faults after the screen
KINDS = ("misses", "few", "refused", "slow", "incomplete", "alone", "apart", "hinge", "dropped", "mechanism", "near",
         "close", "unstable", "stopped", "failed", "unsolved", "stable")


def wire_gaps(design):
    """[(gap in metres, wire index, crossing before, crossing after)] along each wire between
    consecutive crossings (crossings by their index in design["crossings"]), from a layered design
    (its contours hold the crossing points and crossings[i]["contour_vertices"] their indices); a
    closed wire's last gap runs over its end."""
    at = {}
    for k, c in enumerate(design["crossings"]):
        for w, v in zip(c["wires"], c["contour_vertices"]):
            at.setdefault(w, []).append((v, k))
    gaps = []
    for w, marks in at.items():
        wire = design["wires"][w]
        pts = np.asarray(wire["contour"], dtype=float)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
        total = arc[-1] + (float(np.linalg.norm(pts[-1] - pts[0])) if wire["closed"] else 0.0)
        s = sorted((arc[v], c) for v, c in marks)
        gaps += [(b - a, w, ca, cb) for (a, ca), (b, cb) in zip(s, s[1:])]
        if wire["closed"] and len(s) >= 2:
            gaps.append((total - s[-1][0] + s[0][0], w, s[-1][1], s[0][1]))
    return gaps


def crossing_gaps(design):
    """The distances along each wire between consecutive crossings (metres), from a layered design."""
    return [g[0] for g in wire_gaps(design)]


def close_gaps(design, min_segment):
    """How many crossings follow another along a wire closer than 2 * min_segment: the target
    shape then has no free bending point between them and mostly cannot realise them (its
    "too close to their neighbours" verdict), so such candidates are verified last."""
    return sum(1 for g in crossing_gaps(design) if g < 2.0 * min_segment)


def closest_gap(design, among=None):
    """(gap in metres, wire name, (names of the two wires crossing it there)) of the closest two
    consecutive crossings along any wire (with `among`, a set of crossing indices: of the gaps that
    end at one of them), or None when there is none."""
    gaps = [g for g in wire_gaps(design) if among is None or g[2] in among or g[3] in among]
    if not gaps:
        return None
    gap, w, ca, cb = min(gaps, key=lambda g: (g[0], g[1]))
    names = [x["name"] for x in design["wires"]]
    crossings = design["crossings"]
    others = tuple(names[next(v for v in crossings[c]["wires"] if v != w)] for c in (ca, cb))
    return gap, names[w], others


def _partners(design):
    n = len(design["wires"])
    partners, points = {i: set() for i in range(n)}, {i: [] for i in range(n)}
    for c in design["crossings"]:
        a, b = c["wires"]
        partners[a].add(b)
        partners[b].add(a)
        points[a].append(c["point"])
        points[b].append(c["point"])
    return partners, points


def _on_one_line(points, tol):
    """True when the points lie on one line (or at one point) within `tol` metres (two points always
    do: answered without numpy, as for most wires of a screened placement)."""
    if len(points) <= 2:
        return True
    x = np.asarray(points, dtype=float)
    x = x - x.mean(axis=0)
    return float(np.linalg.svd(x, compute_uv=False)[1]) <= tol * max(1.0, len(x) ** 0.5)


def structural_fault(design, tol=1e-6):
    """The fault of a layered design that the layering found not stable (see the module's
    docstring), or None when the crossings show none of "alone", "apart", "hinge" and the layering
    gave no reason."""
    names = [w["name"] for w in design["wires"]]
    partners, points = _partners(design)
    alone = sorted(names[i] for i, p in partners.items() if not p)
    if alone:
        return ("alone", tuple(alone), ())
    part, seen = [], set()
    for i in range(len(names)):
        if i in seen:
            continue
        stack, comp = [i], set()
        while stack:
            w = stack.pop()
            if w not in comp:
                comp.add(w)
                stack.extend(partners[w] - comp)
        seen |= comp
        part.append(comp)
    if len(part) > 1:
        largest = max(part, key=lambda c: (len(c), -min(c)))
        return ("apart", tuple(sorted(names[i] for i in range(len(names)) if i not in largest)), ())
    hinged = [i for i in range(len(names)) if _on_one_line(points[i], tol)]
    if hinged:
        return ("hinge", tuple(names[i] for i in hinged),
                tuple("+".join(sorted(names[j] for j in partners[i])) for i in hinged))
    reason = design.get("reason") or ""
    if not reason:
        return None
    reason = reason.split("allowed at every crossing, ", 1)[-1].split(";", 1)[0]
    return ("mechanism", (), (reason[:160],))


def screen_fault(probe, decided=lambda: False):
    """The fault of a placement whose screen (the layering with too_close) found it not stable:
    structural_fault of its crossings; else "incomplete" when max_nodes stopped the layering's
    search (a stable design may exist); else "dropped" when the screen forbade hooks as too close
    (`too_close_forbidden`) and they decided it (`decided()`, asked only then: with them the
    hook-relaxed check passes), named by the closest gap that holds a crossing with such a hook;
    else "mechanism"."""
    fault = structural_fault(probe)
    if fault is not None and fault[0] != "mechanism":
        return fault
    if probe.get("search_incomplete"):
        return ("incomplete", (), ())
    if probe.get("too_close_forbidden") and decided():
        closest = closest_gap(probe, {c for c, _h in probe.get("too_close_forbidden", ())})
        if closest is not None:
            return ("dropped", (closest[1],), closest[2])
    return fault or ("mechanism", (), ("the layering's verdict",))


def verdict_fault(probe, solved, min_segment):
    """The fault of a candidate that passed the screen (`probe`: its layered design) after its full
    solve `solved` ended not stable: "close" when the target shape could not realise crossings too
    close along a wire (named with the two wires whose crossings come closest on it, from the
    probe), else "unstable" with the solve's reason cut at the first ';'."""
    reason = solved.get("reason") or ""
    if "too close to" in reason and "free bending point" in reason:
        closest = closest_gap(probe)
        named = re.search(r"the closest: wire '([^']+)'", reason)
        if closest is not None and (named is None or named.group(1) == closest[1] or closest[0] < 2.0 * min_segment):
            return ("close", (closest[1],), closest[2])
        return ("close", (named.group(1),) if named else (), ())
    return ("unstable", (), (reason.split(";", 1)[0][:160],))


def _wires(joined):
    """"A/0+B/1" -> "wire A/0 and wire B/1"."""
    return " and ".join(f"wire {w}" for w in joined.split("+")) if joined else "no other wire"


def plane_of(wire_name):
    """The plane a wire's name belongs to ("Z1/0" -> "Z1")."""
    return wire_name.rsplit("/", 1)[0]


def describe(fault, min_segment=None):
    """A fault as the words a count goes with ("41 hinge: ...")."""
    kind, wires, other = fault
    ws = " and ".join(f"wire {w}" for w in wires)
    if kind == "misses":
        return f"put plane {other[0]} off the mesh (it cuts no contour)"
    if kind == "few":
        return "leave fewer than two wires"
    if kind == "refused":
        return f"are refused by the crossing network ({other[0]})"
    if kind == "slow":
        return "stopped in the layering's search after its screening time"
    if kind == "incomplete":
        return "were left undecided: the layering's search reached max_nodes"
    if kind == "alone":
        return f"leave {ws} crossing no other wire"
    if kind == "apart":
        return f"leave {ws} apart from the rest"
    if kind == "hinge":
        on = " and ".join(f"wire {w} (on {_wires(o)})" for w, o in zip(wires, other))
        return f"hinge: {on} {'is' if len(wires) == 1 else 'are'} held only at crossings on one line" + (
            "" if len(wires) == 1 else " each")
    if kind == "mechanism":
        return f"are a mechanism ({other[0]})"
    if kind == "dropped":
        limit = f" ({2000 * min_segment:.0f} mm)" if min_segment else ""
        by = f", where wires {other[0]} and {other[1]} cross it" if len(other) == 2 else ""
        return (f"are no stable structure without the hooks the target shape cannot realise at crossings closer "
                f"than 2 x min_segment{limit} along {ws}{by}")
    if kind == "near":
        limit = f" ({1000 * min_segment:.0f} mm)" if min_segment else ""
        by = f", where wires {other[0]} and {other[1]} cross it" if len(other) == 2 else ""
        return (f"passed the screen, but have crossings closer than min_segment{limit} along {ws}{by} "
                "(left unsolved: such candidates are solved last, and the search ended first)")
    if kind == "close":
        limit = f" ({2000 * min_segment:.0f} mm)" if min_segment else ""
        by = f", where wires {other[0]} and {other[1]} cross it" if len(other) == 2 else ""
        return f"passed the screen, but have crossings closer than 2 x min_segment{limit} along {ws}{by}"
    if kind == "unstable":
        return f"passed the screen, but their full solve is not stable ({other[0]})"
    if kind == "stopped":
        return "passed the screen, but the budget stopped their full solve"
    if kind == "failed":
        return "passed the screen, but the solver could not finish them"
    if kind == "unsolved":
        return "passed the screen, but the budget ended before their full solve"
    if kind == "stable":
        return "are stable"
    raise ValueError(f"unknown fault kind {kind!r}")


KIND_WORDS = {
    "misses": "put a plane off the mesh (it cuts no contour)",
    "few": "leave fewer than two wires",
    "refused": "are refused by the crossing network",
    "slow": "were stopped in the layering's search (its screening time)",
    "incomplete": "were left undecided: the layering's search reached max_nodes",
    "alone": "leave a wire crossing no other wire",
    "apart": "leave wires apart from the rest",
    "hinge": "hinge: a wire held only at crossings on one line turns about it",
    "dropped": "are no stable structure without the hooks the target shape cannot realise at crossings closer "
               "than 2 x min_segment{two} along a wire",
    "mechanism": "are a mechanism of several wires",
    "near": "passed the screen, but have crossings closer than min_segment{min} along a wire (left unsolved: such "
            "candidates are solved last, and the search ended first)",
    "close": "passed the screen, but have crossings closer than 2 x min_segment{two} along a wire, which the target "
             "shape cannot realise",
    "unstable": "passed the screen, but their full solve is not stable",
    "stopped": "passed the screen, but the budget stopped their full solve",
    "failed": "passed the screen, but the solver could not finish them",
    "unsolved": "passed the screen, but the search ended before their full solve",
    "stable": "are stable",
}


def _items(fault):
    """What a fault names, one label each: the wires at fault (with the wires they hinge on, or
    the two wires whose crossings come close on them), the plane off the mesh, the solver's words."""
    kind, wires, other = fault
    if kind == "hinge":
        return [f"wire {w} on {_wires(o)}" for w, o in zip(wires, other)]
    if kind in ("near", "close", "dropped"):
        return [f"wire {w}" + (f", where wires {other[0]} and {other[1]} cross it" if len(other) == 2 else "")
                for w in wires]
    if kind == "misses":
        return [f"plane {other[0]}"]
    if kind in ("alone", "apart"):
        return [f"wire {w}" for w in wires]
    if kind in ("mechanism", "unstable", "refused"):
        return [o for o in other]
    return []


def summary(faults, min_segment=None, shown=4):
    """{fault: count} as words: for each kind (commonest first, `shown` of them, then the rest as one
    count) how many candidates and, in brackets, what they name with how many each (commonest
    three), e.g. "41 hinge: ... (wire Y2/0 on wire X0/0 in 30, ...)". The kinds' counts add up to
    the candidates counted."""
    kinds, named = {}, {}
    for fault, n in faults.items():
        kinds[fault[0]] = kinds.get(fault[0], 0) + n
        for item in _items(fault):
            named.setdefault(fault[0], {})
            named[fault[0]][item] = named[fault[0]].get(item, 0) + n
    ranked = sorted(kinds.items(), key=lambda kv: (-kv[1], KINDS.index(kv[0])))
    words = {"min": f" ({1000 * min_segment:.0f} mm)" if min_segment else "",
             "two": f" ({2000 * min_segment:.0f} mm)" if min_segment else ""}
    parts = []
    for kind, n in ranked[:shown]:
        items = sorted(named.get(kind, {}).items(), key=lambda kv: (-kv[1], kv[0]))
        detail = ", ".join(item if len(items) == 1 else f"{item} in {k}" for item, k in items[:3])
        more = f", {len(items) - 3} more" if len(items) > 3 else ""
        parts.append(f"{n} {KIND_WORDS[kind].format(**words)}" + (f" ({detail}{more})" if detail else ""))
    rest = sum(n for _kind, n in ranked[shown:])
    if rest:
        parts.append(f"{rest} for {len(ranked) - shown} other reason{'s' if len(ranked) - shown > 1 else ''} "
                     f"({', '.join(k for k, _n in ranked[shown:])})")
    return ", ".join(parts)


def advice(faults, min_segment=None):
    """What to change, from the faults that stopped the most candidates (a list of sentences):
    for a hinged wire, a plane crossing it away from its line; for two planes whose wires hinge,
    moving them together so that their wires cross; for a wire crossing nothing, a plane crossing it;
    for crossings too close along a wire, the two planes at fault moved apart."""
    out = []
    for kind, wires, other in faults:
        if kind == "hinge":
            for w, on in zip(wires, other):
                out.append(f"add a plane whose wire crosses wire {w} away from its line with {_wires(on)}")
            planes = sorted({plane_of(w) for w in wires})
            if len(planes) >= 2:
                out.append(f"move or tilt planes {' and '.join(planes)} towards each other until their wires cross "
                           "each other off those lines")
        elif kind == "alone":
            for w in wires:
                out.append(f"move plane {plane_of(w)} until wire {w} crosses at least two other wires, or add a "
                           f"plane crossing wire {w}")
        elif kind == "apart":
            out.append(f"add a plane crossing {' and '.join(f'wire {w}' for w in wires)} and the rest")
        elif kind in ("near", "close", "dropped") and len(other) == 2:
            a, b = plane_of(other[0]), plane_of(other[1])
            gap = f" at least {2000 * min_segment:.0f} mm" if min_segment else ""
            if a == b:
                out.append(f"move plane {a} so that its two crossings along wire {wires[0]} are{gap} apart, or "
                           "scale the model up")
            else:
                out.append(f"move planes {a} and {b} apart, so that their crossings along wire {wires[0]} are{gap} "
                           "apart, or scale the model up")
    unique = []
    for s in out:
        if s not in unique:
            unique.append(s)
    return unique


class Tally:
    """The nearby search's account of its candidates, in families: the planes as given, the
    one-plane changes of each plane (named by the plane) and the two-plane changes ("pairs"). For
    each family: how many candidates it has, how many were screened and solved, and for each
    screened candidate its fault (or "stable"), so that a family's fault counts add up to its
    screened candidates."""

    def __init__(self, base, singles, pair_count):
        self.names = [p.name for p in base]
        self.families = {"given": self._family(1)}
        for i, changes in singles.items():
            self.families[self.names[i]] = self._family(len(changes))
        self.families["pairs"] = self._family(pair_count)
        self.single_fault = {}  # id(one-plane change) -> its fault
        self.given_fault = None
        self.seconds, self.out_of_time = 0.0, False

    @staticmethod
    def _family(total):
        return {"total": total, "screened": 0, "solved": 0, "faults": {}}

    def family_of(self, changes):
        if not changes:
            return "given"
        return self.names[changes[0][0]] if len(changes) == 1 else "pairs"

    def screened(self, family):
        self.families[family]["screened"] += 1

    def solved(self, family):
        self.families[family]["solved"] += 1

    def fault(self, family, fault, changes=()):
        faults = self.families[family]["faults"]
        faults[fault] = faults.get(fault, 0) + 1
        if family == "given":
            self.given_fault = fault
        elif len(changes) == 1:
            self.single_fault[id(changes[0][1])] = fault

    def fixed(self, change):
        """The wires at fault in the planes as given that a one-plane change (screened) is free of:
        all of them when it passed the screen or failed it only for want of the hooks at crossings
        too close along a wire ("dropped": its crossings hold no alone, apart or hinged wire), none
        when its fault is not about named wires."""
        given = set(self.given_fault[1]) if self.given_fault and self.given_fault[0] in WIRE_KINDS else set()
        fault = self.single_fault.get(id(change))
        if fault is None:
            return set()
        if fault[0] in PASSED_KINDS or fault[0] == "dropped":
            return given
        return given - set(fault[1]) if fault[0] in WIRE_KINDS else set()

    def pair_order(self, pairs):
        """The two-plane changes in the order to screen them, [(cost, ((i, change), (j, change)))]:
        first those whose two changes, each screened alone, together free every wire at fault in the
        planes as given (fewest such wires left first), then those whose second plane is at fault
        in the first change's screen (the wires it names, or the wires they turn on), then by cost."""
        given = set(self.given_fault[1]) if self.given_fault and self.given_fault[0] in WIRE_KINDS else set()

        def planes_at_fault(change):
            fault = self.single_fault.get(id(change))
            if fault is None or fault[0] not in WIRE_KINDS:
                return set()
            return {plane_of(w) for w in fault[1] + tuple(x for o in fault[2] for x in o.split("+")) if w}

        def key(pair):
            cost, ((i, a), (j, b)) = pair
            left = len(given - self.fixed(a) - self.fixed(b))
            aimed = self.names[j] in planes_at_fault(a) or self.names[i] in planes_at_fault(b)
            return (left, not aimed, cost)
        return sorted(pairs, key=key)

    def left(self):
        """(candidates not screened, whether the planes as given are among them, of them one-plane
        changes, two-plane changes)."""
        rest = {k: f["total"] - f["screened"] for k, f in self.families.items()}
        singles = sum(n for k, n in rest.items() if k not in ("given", "pairs"))
        return sum(rest.values()), rest["given"], singles, rest["pairs"]

    def totals(self):
        """{fault: count} over every family."""
        out = {}
        for f in self.families.values():
            for fault, n in f["faults"].items():
                out[fault] = out.get(fault, 0) + n
        return out

    def worst(self, kinds=2):
        """The faults to advise on: the planes as given's, then the commonest fault of each of the
        `kinds` commonest kinds of fault over every family (other than the given's kind)."""
        totals = self.totals()
        by_kind = {}
        for fault, n in totals.items():
            by_kind[fault[0]] = by_kind.get(fault[0], 0) + n
        out = [self.given_fault] if self.given_fault is not None else []
        for kind, _n in sorted(by_kind.items(), key=lambda kv: (-kv[1], KINDS.index(kv[0]))):
            if len(out) > kinds or (out and kind == out[0][0]):
                continue
            out.append(max((f for f in totals if f[0] == kind), key=lambda f: (totals[f], str(f))))
        return out

    def report(self, offset_mm, size_mm, tilt_deg, budget, min_segment=None, shown=4):
        """The sentence a nearby search that found nothing ends with: what it searched, how many
        placements it screened and solved, whether the budget cut it short and how much was left,
        each family's candidates counted by fault (the `shown` commonest, then the rest as one
        count), and what to change (advice on the commonest faults)."""
        fam = self.families
        screened = sum(f["screened"] for f in fam.values())
        solved = sum(f["solved"] for f in fam.values())
        total = sum(f["total"] for f in fam.values())
        singles = sum(f["total"] for k, f in fam.items() if k not in ("given", "pairs"))
        out = [f"no nearby placement gives a stable design. Searched: planes {', '.join(self.names)} one at a time "
               f"({singles} changes: offsets up to {offset_mm:.0f} mm ({100 * offset_mm / size_mm:.0f} % of the "
               f"model's {size_mm:.0f} mm) each way along each normal, tilts up to {tilt_deg:g} deg about two axes "
               f"each way, each plane's other contour rule) and two at a time ({fam['pairs']['total']} pairs); "
               f"{screened} placements screened, {solved} fully solved, in {self.seconds:.1f} s"]
        left, left_given, left_singles, left_pairs = self.left()
        if self.out_of_time and left:
            out.append(f"the {budget:g} s budget ended the search after {screened} of {total} candidates: "
                       f"{left} left ({'the planes as given, ' if left_given else ''}{left_singles} one-plane and "
                       f"{left_pairs} two-plane changes)")
        elif left:
            out.append(f"{left} of {total} candidates not screened")
        else:
            out.append(f"every one of the {total} candidates was screened")
        why = []
        for name, f in fam.items():
            if not f["screened"]:
                continue
            label = ("the planes as given" if name == "given" else
                     "two-plane changes" if name == "pairs" else f"changes of plane {name}")
            count = "" if name == "given" else f" ({f['screened']} of {f['total']} screened)"
            why.append(f"{label}{count}: " + summary(f["faults"], min_segment, shown))
        out.append("why: " + "; ".join(why))
        todo = advice(self.worst(), min_segment)[:4]
        if self.out_of_time and left:
            todo.append("give the search more time")
        if todo:
            out.append("to change: " + "; or ".join(todo))
        return ". ".join(out[:1] + [s[0].upper() + s[1:] for s in out[1:]])
