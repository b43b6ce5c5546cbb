"""Why a placement of the slicing planes gives no stable design, read from its layered crossing
network, so that every nearby search ends stable or says why no nearby placement exists. bpy-free,
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

Every kind is one entry of FAULTS: its words (one sentence, named by the fault for describe and
generic for summary's counts), the items summary counts under it, and its advice.
"""
from typing import Callable, NamedTuple

import numpy as np

from .design import TOO_CLOSE


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
    # what the layering's hook-relaxed check found moving (`what_moves`), else the reason's first clause
    what = design.get("what_moves") or reason.split(";", 1)[0]
    return ("mechanism", (), (what[:160],))


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


def verdict_fault(probe, solved):
    """The fault of a candidate that passed the screen (`probe`: its layered design) after its full
    solve `solved` ended not stable: "close" when its reason names crossings too close along a wire
    for a free bending point between them (`reason_causes` holds TOO_CLOSE), named by the probe's
    closest gap (its wire and the two wires crossing it there), else "unstable" with the solve's
    reason cut at the first ';'."""
    if TOO_CLOSE in solved.get("reason_causes", ()):
        closest = closest_gap(probe)
        return ("close", (closest[1],), closest[2]) if closest is not None else ("close", (), ())
    reason = solved.get("reason") or ""
    return ("unstable", (), (reason.split(";", 1)[0][:160],))


def _wires(joined):
    """"A/0+B/1" -> "wire A/0 and wire B/1"."""
    return " and ".join(f"wire {w}" for w in joined.split("+")) if joined else "no other wire"


def plane_of(wire_name):
    """The plane a wire's name belongs to ("Z1/0" -> "Z1")."""
    return wire_name.rsplit("/", 1)[0]


def _by(other):
    """", where wires A and B cross it" for the two wires whose crossings come close, else ""."""
    return f", where wires {other[0]} and {other[1]} cross it" if len(other) == 2 else ""


def _limits(min_segment):
    """The words' min_segment figures: {min} and {two} (2 x min_segment), "" without one."""
    return {"min": f" ({1000 * min_segment:.0f} mm)" if min_segment else "",
            "two": f" ({2000 * min_segment:.0f} mm)" if min_segment else ""}


def _named(fault):
    """The words' fields as one fault names them (describe)."""
    _kind, wires, other = fault
    hinged = " and ".join(f"wire {w} (on {_wires(o)})" for w, o in zip(wires, other))
    return {"wires": " and ".join(f"wire {w}" for w in wires), "by": _by(other),
            "detail": f" ({other[0]})" if other else "", "plane": f"plane {other[0]}" if other else "a plane",
            "hinged": hinged + (" is" if len(wires) == 1 else " are"), "tail": "" if len(wires) == 1 else " each"}


def _no_items(fault):
    return []


def _each_wire(fault):
    return [f"wire {w}" for w in fault[1]]


def _wire_on(fault):
    return [f"wire {w} on {_wires(o)}" for w, o in zip(fault[1], fault[2])]


def _wire_by(fault):
    return [f"wire {w}" + _by(fault[2]) for w in fault[1]]


def _plane(fault):
    return [f"plane {fault[2][0]}"]


def _other(fault):
    return list(fault[2])


def _no_advice(fault, min_segment):
    return []


def _advise_hinge(fault, min_segment):
    _kind, wires, other = fault
    out = [f"add a plane whose wire crosses wire {w} away from its line with {_wires(on)}"
           for w, on in zip(wires, other)]
    planes = sorted({plane_of(w) for w in wires})
    if len(planes) >= 2:
        out.append(f"move or tilt planes {' and '.join(planes)} towards each other until their wires cross "
                   "each other off those lines")
    return out


def _advise_alone(fault, min_segment):
    return [f"move plane {plane_of(w)} until wire {w} crosses at least two other wires, or add a plane crossing "
            f"wire {w}" for w in fault[1]]


def _advise_apart(fault, min_segment):
    return [f"add a plane crossing {' and '.join(f'wire {w}' for w in fault[1])} and the rest"]


def _advise_spacing(fault, min_segment):
    """Crossings too close along a wire: the two planes whose wires cross it there moved apart."""
    _kind, wires, other = fault
    if len(other) != 2:
        return []
    a, b = plane_of(other[0]), plane_of(other[1])
    gap = f" at least {2000 * min_segment:.0f} mm" if min_segment else ""
    if a == b:
        return [f"move plane {a} so that its two crossings along wire {wires[0]} are{gap} apart, or scale the model up"]
    return [f"move planes {a} and {b} apart, so that their crossings along wire {wires[0]} are{gap} apart, or "
            "scale the model up"]


class Kind(NamedTuple):
    """One kind of fault: the words a count of its candidates goes with ("41 hinge: ..."), whose
    {fields} the fault names (describe, _named) or `generic` fills (summary, counting many faults of
    the kind), {min} and {two} the min_segment figures; what it names, one label each (`items`,
    counted by summary); what to change (`advice`)."""
    words: str
    generic: dict = {}
    items: Callable = _no_items
    advice: Callable = _no_advice
    names_wires: bool = False  # the fault names the wires at fault
    passed: bool = False  # a fault of a candidate that passed the screen


SOME_WIRE = {"wires": "a wire", "by": ""}
FAULTS = {
    "misses": Kind("put {plane} off the mesh (it cuts no contour)", {"plane": "a plane"}, _plane),
    "few": Kind("leave fewer than two wires"),
    "refused": Kind("are refused by the crossing network{detail}", {"detail": ""}, _other),
    "slow": Kind("were stopped in the layering's search (its screening time)"),
    "incomplete": Kind("were left undecided: the layering's search reached max_nodes"),
    "alone": Kind("leave {wires} crossing no other wire", {"wires": "a wire"}, _each_wire, _advise_alone,
                  names_wires=True),
    "apart": Kind("leave {wires} apart from the rest", {"wires": "wires"}, _each_wire, _advise_apart,
                  names_wires=True),
    "hinge": Kind("hinge: {hinged} held only at crossings on one line{tail}",
                  {"hinged": "a wire", "tail": " turns about it"}, _wire_on, _advise_hinge, names_wires=True),
    "dropped": Kind("are no stable structure without the hooks the target shape cannot realise at crossings closer "
                    "than 2 x min_segment{two} along {wires}{by}", SOME_WIRE, _wire_by, _advise_spacing),
    "mechanism": Kind("are a mechanism{detail}", {"detail": " of several wires"}, _other),
    "near": Kind("passed the screen, but have crossings closer than min_segment{min} along {wires}{by} (left "
                 "unsolved: such candidates are solved last, and the search ended first)", SOME_WIRE, _wire_by,
                 _advise_spacing, passed=True),
    "close": Kind("passed the screen, but have crossings closer than 2 x min_segment{two} along {wires}{by}, which "
                  "the target shape cannot realise", SOME_WIRE, _wire_by, _advise_spacing, passed=True),
    "unstable": Kind("passed the screen, but their full solve is not stable{detail}", {"detail": ""}, _other,
                     passed=True),
    "stopped": Kind("passed the screen, but the budget stopped their full solve", passed=True),
    "failed": Kind("passed the screen, but the solver could not finish them", passed=True),
    "unsolved": Kind("passed the screen, but the search ended before their full solve", passed=True),
    "stable": Kind("are stable", passed=True),
}
KINDS = tuple(FAULTS)  # their order ranks kinds of equal counts
WIRE_KINDS = tuple(k for k, v in FAULTS.items() if v.names_wires)  # faults that name the wires at fault
PASSED_KINDS = tuple(k for k, v in FAULTS.items() if v.passed)  # faults after the screen


def _entry(fault):
    try:
        return FAULTS[fault[0]]
    except KeyError:
        raise ValueError(f"unknown fault kind {fault[0]!r}") from None


def describe(fault, min_segment=None):
    """A fault as the words a count goes with ("41 hinge: ..."), naming what it names."""
    return _entry(fault).words.format(**_limits(min_segment), **_named(fault))


def summary(faults, min_segment=None, shown=4):
    """{fault: count} as words: for each kind (commonest first, `shown` of them, then the rest as one
    count) how many candidates and, in brackets, what they name with how many each (commonest
    three), e.g. "41 hinge: ... (wire Y2/0 on wire X0/0 in 30, ...)". The kinds' counts add up to
    the candidates counted."""
    kinds, named = {}, {}
    for fault, n in faults.items():
        kinds[fault[0]] = kinds.get(fault[0], 0) + n
        for item in _entry(fault).items(fault):
            named.setdefault(fault[0], {})
            named[fault[0]][item] = named[fault[0]].get(item, 0) + n
    ranked = sorted(kinds.items(), key=lambda kv: (-kv[1], KINDS.index(kv[0])))
    limits = _limits(min_segment)
    parts = []
    for kind, n in ranked[:shown]:
        items = sorted(named.get(kind, {}).items(), key=lambda kv: (-kv[1], kv[0]))
        detail = ", ".join(item if len(items) == 1 else f"{item} in {k}" for item, k in items[:3])
        more = f", {len(items) - 3} more" if len(items) > 3 else ""
        words = FAULTS[kind].words.format(**limits, **FAULTS[kind].generic)
        parts.append(f"{n} {words}" + (f" ({detail}{more})" if detail else ""))
    rest = sum(n for _kind, n in ranked[shown:])
    if rest:
        parts.append(f"{rest} for {len(ranked) - shown} other reason{'s' if len(ranked) - shown > 1 else ''} "
                     f"({', '.join(k for k, _n in ranked[shown:])})")
    return ", ".join(parts)


def advice(faults, min_segment=None):
    """What to change, from the faults that stopped the most candidates (a list of sentences, each
    once): for a hinged wire, a plane crossing it away from its line; for two planes whose wires
    hinge, moving them together so that their wires cross; for a wire crossing nothing, a plane
    crossing it; for crossings too close along a wire, the two planes at fault moved apart."""
    unique = []
    for fault in faults:
        for s in _entry(fault).advice(fault, min_segment):
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

    def ending(self, min_segment=None):
        """How the search ended, as data (the design's `plane_search.not_found`, docs/formats.md):
        {"screened": candidates screened, "total": candidates in all, "budget_ended": whether the
        budget stopped it with candidates left, "advice": [what to change, as report says each]}."""
        fam = self.families
        left = self.left()[0]
        budget_ended = bool(self.out_of_time and left)
        todo = advice(self.worst(), min_segment)[:4]
        if budget_ended:
            todo.append("give the search more time")
        return {"screened": sum(f["screened"] for f in fam.values()), "total": sum(f["total"] for f in fam.values()),
                "budget_ended": budget_ended, "advice": todo}

    def report(self, offset_mm, size_mm, tilt_deg, budget, min_segment=None, shown=4):
        """The sentence a nearby search that found nothing ends with: what it searched, how many
        placements it screened and solved, whether the budget cut it short and how much was left,
        each family's candidates counted by fault (the `shown` commonest, then the rest as one
        count), and what to change (advice on the commonest faults). `budget`: the seconds of the
        budget that ended it, or what ended it in words ("limit of 24 full solves")."""
        fam = self.families
        ending = self.ending(min_segment)
        screened, total, todo = ending["screened"], ending["total"], ending["advice"]
        solved = sum(f["solved"] for f in fam.values())
        singles = sum(f["total"] for k, f in fam.items() if k not in ("given", "pairs"))
        out = [f"no nearby placement gives a stable design. Searched: planes {', '.join(self.names)} one at a time "
               f"({singles} changes: offsets up to {offset_mm:.0f} mm ({100 * offset_mm / size_mm:.0f} % of the "
               f"model's {size_mm:.0f} mm) each way along each normal, tilts up to {tilt_deg:g} deg about two axes "
               f"each way, each plane's other contour rule) and two at a time ({fam['pairs']['total']} pairs); "
               f"{screened} placements screened, {solved} fully solved, in {self.seconds:.1f} s"]
        left, left_given, left_singles, left_pairs = self.left()
        if ending["budget_ended"]:
            ended = f"{budget:g} s budget" if isinstance(budget, (int, float)) else budget  # or a count, in words
            out.append(f"the {ended} ended the search after {screened} of {total} candidates: "
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
        if todo:
            out.append("to change: " + "; or ".join(todo))
        return ". ".join(out[:1] + [s[0].upper() + s[1:] for s in out[1:]])
