"""Target shape (Sec. 4.3): per wire, a fabricable polyline through its fixed crossings whose
kinks open the way the layering's hooks say (docs/formats.md `hook`).

Contact angle: the layering stage assumes each kink's edges lie exactly contact_angle/2 from the
bisector, with friction widening its pyramid by atan(mu). The paper's constraint is
angle(edge, h*) + atan(mu) <= alpha*/2; the kink the layering judged stable needs every edge
within contact_angle/2 of h*, which is that constraint with alpha* = contact_angle and the
friction term left out (mu = 0 here: friction is already in the layering's pyramid). The
realised kink is then at least as sharp as the one the layering judged stable.
"""
import math
import os
import time

import numpy as np

from .. import native
from ..core.design import TOO_CLOSE, crossing_axis, model_size
from ..core.frames import plane_frame, to_2d, to_3d
from ..core.polylines import ContourArrays, polyline_length
from . import layering

FAILED = ("too_close", "infeasible", "open_end")
# The solver's causes (TargetCrossingStatus::cause) that no hook cures: the straight piece to a
# neighbouring crossing shorter than min_segment, an open end, a contact angle that friction or the
# machine's bend limit rules out whichever way the kink opens.
EVERY_HOOK = frozenset({"short_piece", "open_end", "contact_vs_friction", "min_bend"})


def whatever_the_hook(cause):
    """Whether a failed crossing's `cause` (the native status's code) is one the other hook cannot cure."""
    return cause in EVERY_HOOK


# After the solve, a crossing counts as realised when its kink is inside the contact cone and its
# segments and bends within the machine's limits to within what a bender can make at all (its
# reliable minimum bend is 1 deg): SLSQP ends within about 0.02 deg, far below this, while the
# solver's own default check (1e-6 rad) nulled crossings missing the cone by 0.0003 deg.
REALISED_ANGLE = math.radians(0.1)
REALISED_LENGTH = 1e-5  # metres
MAX_ROUNDS = 4  # solve, null what cannot be realised, solve again (each round nulls at least one)
# The window sweeps stop once a sweep lowers a wire's energy by less than this fraction: later sweeps
# only creep points along the wire (TargetShapeOptions::sweep_ftol; docs/method-target-shape.md,
# "The solver": the same distances to the contour and crossings, 3-6x fewer evaluations on long wires).
SWEEP_FTOL = 1e-3
# Wires of up to this many target points are one NLopt block, longer ones are solved in windows
# (TargetShapeOptions::one_block_points; the solver's own default is 4 x window = 32). SLSQP's
# dense subproblem costs about n^3: a 32-point block took 560 us an evaluation against 20 us for
# an 8-point window, and the Teddy's 32-point Arms/0 0.05 s against 0.005 s in windows, at the same
# distances and crossings. At 28 every stand-in and real-mesh scene keeps its distances (0.1 mm),
# crossings and verdict; at 24 or 16 some (the Chair's 26-point backrest) reach other optima
# (docs/method-target-shape.md, "The solver").
ONE_BLOCK_POINTS = 28
# Wires are independent problems: a round's are solved in one native call (optimize_target_shapes)
# on up to this many threads, the dearest first, a windowed wire handed from one thread to the other
# between its windows when another has more work left (three equal wires end together), with the
# GIL released throughout; each result depends only on its own wire, so the order is kept. The call
# reads its wires from a generator: the native helper thread (kept for the process) starts on the
# first while this thread prepares the next: a Python thread pool per call cost about a millisecond
# more on the Duck and the Car (docs/method-target-shape.md, "A round's wires on two threads").
MAX_THREADS = 2
# The machine's cores, read once: os.cpu_count() reads /sys at every call (40-60 us on a VM, about
# 1.5 % of the globe's stage).
CORES = os.cpu_count() or 1
# Blocks by the Newton SQP (led by SLSQP's first evaluations where a kink's arrangement is chosen,
# SLSQP where it fails): 2-4.5x fewer instructions than SLSQP alone, the same distances and crossings
# on the stand-ins, the globe and the corpus (docs/method-target-shape.md, "The solver").
ALGORITHM = "sqp"


def desired_bisector(design, crossing, k):
    """The 3D direction wire k (0 or 1) of `crossing` must open towards: hook * d for wires[0],
    -hook * d for wires[1] (d itself for a null crossing, which is not constrained)."""
    return np.array(_bisector(design, crossing, k))


def _bisector(design, crossing, k):
    """desired_bisector as a tuple of floats (the same products)."""
    sign = (crossing["hook"] if k == 0 else -crossing["hook"]) or 1
    return tuple(sign * x for x in crossing_axis(design, crossing))


def bisector_in_frame(design, crossing, k, u, v):
    """desired_bisector in the plane frame (u, v), as two floats: its dot products with u and v,
    written out (numpy's per-call cost is most of a 3-vector's dot product; the same sums)."""
    h = _bisector(design, crossing, k)
    u0, u1, u2 = map(float, u)
    v0, v1, v2 = map(float, v)
    return (h[0] * u0 + h[1] * u1 + h[2] * u2, h[0] * v0 + h[1] * v1 + h[2] * v2)


def solve_wire(design, wire, material, settings, size, native_progress=None, memo=None):
    """(result, [(crossing, k)], frame) of the native optimisation of one wire; with a `memo`, a
    result from an earlier coupling round is taken instead of solving when it is still optimal
    (Memo.reusable)."""
    job = prepare_wire(design, wire, settings, size, memo)
    return finish_wire(job, solve_job(job, native_progress), memo)


def sides_by_wire(design):
    """{wire id: [(crossing, k)]}: the crossings through each wire in the design's order, k the
    wire's index in the crossing's `wires` (the first, should both be the wire)."""
    sides = {}
    for c in design["crossings"]:
        for k, w in enumerate(c["wires"]):
            if k == 0 or w != c["wires"][0]:
                sides.setdefault(w, []).append((c, k))
    return sides


def prepare_wire(design, wire, settings, size, memo=None, sides=None):
    """Everything one wire's solve needs, read from the design (call on the thread that owns the
    design and the memo): {"contour", "closed", "specs", "options", "refs", "frame", "key",
    "start_key", "result"}, where "result" is the memo's reusable result or None (solve_job
    computes it) and "start_key" the key of Memo.starts (None without a memo). `sides`:
    sides_by_wire(design), when already at hand."""
    origin = wire["plane"]["origin"]
    u, v, contour = memo.frame(wire) if memo is not None else _frame(wire)
    contact = math.radians(settings["contact_angle_deg"])
    specs, refs = [], []
    if sides is None:
        sides = sides_by_wire(design)
    for c, k in sides.get(wire["id"], ()):
        bisector = memo.bisector_2d(design, c, k) if memo is not None else bisector_in_frame(design, c, k, u, v)
        specs.append({"vertex": c["contour_vertices"][k], "bisector": bisector,
                      "contact_angle": contact, "active": c["hook"] != 0})
        refs.append((c, k))
    options = {"min_segment": settings["min_segment"], "max_bend": math.radians(settings["max_bend_deg"]),
               "friction": 0.0, "model_size": size, "wire_name": wire["name"],
               "angle_tolerance": REALISED_ANGLE, "length_tolerance": REALISED_LENGTH, "sweep_ftol": SWEEP_FTOL,
               "one_block_points": ONE_BLOCK_POINTS, "algorithm": ALGORITHM}
    limits = memo.vertex_limits.get(wire["name"]) if memo is not None else None
    if limits:  # the coupling's own limits at some points (pipeline._tighten), radians by target index
        options["vertex_max_bend"] = tuple(limits.get(i, 0.0) for i in range(max(limits) + 1))
    key = Memo.key(contour, wire["closed"], specs, options) if memo is not None else None
    start_key = Memo.key(contour, wire["closed"], specs, options, Memo.LIMITS, key) if memo is not None else None
    result = memo.reusable(key, options["max_bend"]) if memo is not None else None
    if result is None and memo is not None:  # a coupling round: start from the looser limit's optimum
        start = memo.starts.get(start_key)
        if start is not None:
            options = {**options, "start": start}
    return {"contour": contour, "closed": wire["closed"], "specs": specs, "options": options, "refs": refs,
            "frame": (origin, u, v), "key": key, "start_key": start_key, "result": result}


def _frame(wire, contour=None):
    """(u, v, contour in 2D): the wire's plane axes and its contour in that frame (`contour`: the
    wire's contour already as an array)."""
    _n, u, v = plane_frame(wire["plane"]["normal"])
    return u, v, to_2d(wire["contour"] if contour is None else contour, wire["plane"]["origin"], u, v)


def solve_job(job, native_progress=None):
    """The native result of a prepared wire (its memo's result when it had one). Touches neither the
    design nor the memo, so several run at once."""
    if job["result"] is not None:
        return job["result"]
    return native.optimize_target_shape(job["contour"], job["closed"], job["specs"], job["options"], native_progress)


def finish_wire(job, result, memo=None):
    """Remembers a new solve in the memo; (result, refs, frame) as solve_wire returns them."""
    if memo is not None and job["result"] is None:
        memo.remember(job["key"], job["options"]["max_bend"], result)
        memo.remember_start(job["start_key"], result)
    return result, job["refs"], job["frame"]


def solve_all(jobs, native_progress=None, count=None):
    """(the jobs, their results): solve_job of every job of `jobs`, in order, the ones to solve in
    one native call on up to MAX_THREADS threads. `jobs` is read once, and may be a generator that
    prepares each wire as it is read (then `count` says how many it makes): the native call reads
    its problems one at a time, so the other thread solves the first wire while this one prepares
    the next."""
    count = len(jobs) if count is None else count
    jobs = iter(jobs)
    taken = []
    first = None
    for job in jobs:  # up to the first to solve: no native call when every result is reused
        taken.append(job)
        if job["result"] is None:
            first = job
            break
    if first is None:
        return taken, [job["result"] for job in taken]

    def problems():
        yield _problem(first)
        for job in jobs:
            taken.append(job)
            if job["result"] is None:
                yield _problem(job)
    solved = iter(native.optimize_target_shapes(problems(), native_progress,
                                                max(1, min(MAX_THREADS, CORES, count))))
    return taken, [next(solved) if job["result"] is None else job["result"] for job in taken]


def _problem(job):
    """The native problem of a job. Its plane makes the native place the result in space and
    measure it ("target", "length") on the thread that solved it, to_3d and polyline_length's own
    numbers, while the other thread still solves (a twentieth of the globe's stage after the call)."""
    origin, u, v = job["frame"]
    return {"points": job["contour"], "closed": job["closed"], "crossings": job["specs"], "options": job["options"],
            "plane": {"origin": origin, "u": u, "v": v}}


class Memo:
    """What the target shape learnt in one coupling round (Sec. 4.3), for the next, which only
    lowers the maximum bend:

    - `nulled`: the crossings it could not realise. A lower bend limit only shrinks each wire's
      feasible set, so they are nulled from the start of the next round instead of being solved
      (and failing) again.
    - `vertex_limits`: {wire name: {target index: radians}}, the bend limits the coupling set at
      single points (pipeline._tighten); they only ever go down, so the same argument holds.
    - every wire's solve. A result that was a converged, feasible optimum with every active crossing
      realised under the old limit and whose bends all lie within the new one is still a local
      optimum of the tighter problem (the same point, feasible, in a smaller feasible set): it is
      reused for the same contour, crossings and options. Only the other wires are solved again.
    - `starts`: the optimum of each wire problem whatever its per-vertex bend limits
      (vertex_max_bend left out of the key), when it converged with every active crossing
      realised. A wire solved again because the coupling lowered the limit of some of its
      vertices starts from it (the native `start` option: the same problem, a warm start) instead
      of from the resampled contour: most of its points are already where the tighter problem
      wants them. Not when the global limit (max_bend) went down: every bend of the wire is then
      constrained anew, and started from the old optimum the coupling's soft-sphere case
      (test_pipeline.Coupling) reached an optimum whose hooked kink stayed over the machine's
      limit (docs/method-target-shape.md, "Coupling rounds").
    """

    CONVERGED = ("NLOPT_SUCCESS", "NLOPT_FTOL_REACHED", "NLOPT_XTOL_REACHED", "SQP_CONVERGED", "none")  # "none": nothing free

    def __init__(self, same=None, contour_cache=None):
        """`same`: a dict {(key, max_bend): result} of earlier solves of exactly the same problem,
        shared with other memos (pipeline.relayer hands one to every re-layering round: wires whose
        crossings and hooks the new layering left alone are the same problems). Its results are
        reused whatever they were: the solve is a deterministic function of its input.
        `contour_cache`: a core.polylines.ContourArrays shared with the solve's other stages (the
        layering fills it with the arrays of the contours it makes); a memo of its own without."""
        self.nulled = []
        self.vertex_limits = {}
        self.solves = {}  # key -> (max_bend, result)
        self.starts = {}  # key without the per-vertex bend limits (LIMITS) -> points of a converged solve
        self.same = {} if same is None else same
        self.reused = 0
        # What every round derives again from the same contours and planes (read-only after the
        # layering, shared by the rounds' copies of the design): each wire's frame and 2D contour,
        # each crossing's bisector and the model's size, checked against the objects they came from.
        # wire name -> (contour, origin, normal, (u, v, 2D contour), (u, v) as tuples of floats)
        self._frames = {}
        self._bisectors = {}  # (the two wires' plane normals, k, hook) -> h in wire k's frame
        self._size = None  # (the contours, size)
        self.contour_cache = ContourArrays() if contour_cache is None else contour_cache

    def frame(self, wire):
        """_frame(wire), computed once per contour and plane."""
        return self._frame_entry(wire)[3]

    def _frame_entry(self, wire):
        """The wire's entry of _frames, made again when its contour or plane changed; its last item
        is the frame's axes as floats (bisector_in_frame reads them element by element)."""
        plane = wire["plane"]
        entry = self._frames.get(wire["name"])
        if (entry is None or entry[0] is not wire["contour"] or entry[1] != list(plane["origin"])
                or entry[2] != list(plane["normal"])):
            frame = _frame(wire, self.array(wire))
            entry = (wire["contour"], list(plane["origin"]), list(plane["normal"]), frame,
                     (tuple(frame[0].tolist()), tuple(frame[1].tolist())))
            self._frames[wire["name"]] = entry
        return entry

    def bisector_2d(self, design, crossing, k):
        """desired_bisector(design, crossing, k) in the frame (u, v) of wire k's plane (Memo.frame),
        as floats, computed once per pair of plane normals and hook (the frame is a function of
        the wire's normal)."""
        w0, w1 = crossing["wires"]
        key = (tuple(design["wires"][w0]["plane"]["normal"]), tuple(design["wires"][w1]["plane"]["normal"]), k,
               crossing["hook"])
        found = self._bisectors.get(key)
        if found is None:
            u, v = self._frame_entry(design["wires"][crossing["wires"][k]])[4]
            found = self._bisectors[key] = bisector_in_frame(design, crossing, k, u, v)
        return found

    def model_size(self, design):
        """core.design.model_size(design), computed once for the same contours, in one native call
        (numpy's concatenation and column extremes took about 40 us of the globe's stage, before
        its first wire could start; the same extremes, so the same number)."""
        contours = [w["contour"] for w in design["wires"]]
        if self._size is None or len(self._size[0]) != len(contours) or any(
                a is not b for a, b in zip(self._size[0], contours)):
            arrays = [self.array(w) for w in design["wires"]]
            size = native.largest_box_side(arrays) if arrays else model_size(design, arrays)
            self._size = (contours, size)
        return self._size[1]

    def array(self, wire):
        """The wire's contour as a float64 array, converted once per contour (a long contour's
        list of lists took ~0.1 ms each time, twice per wire and round) or handed over by the
        layering that made it (`contour_cache`)."""
        return self.contour_cache.get(wire["contour"])

    @staticmethod
    def key(contour, closed, specs, options, ignore=("max_bend",), like=None):
        """Everything the solve depends on except the bend limit (the options named in `ignore`;
        a start is never part of it). `like`: a key of the same contour, closed and specs, whose
        parts for them are taken instead of being built again (the contour's bytes)."""
        other = tuple(sorted((k, v) for k, v in options.items() if k not in ignore and k != "start"))
        if like is not None:
            return like[:3] + (other,)
        spec_key = tuple((s["vertex"], s["bisector"], s["contact_angle"], s["active"]) for s in specs)
        return (np.ascontiguousarray(contour, dtype=np.float64).tobytes(), bool(closed), spec_key, other)

    LIMITS = ("vertex_max_bend",)

    @classmethod
    def _converged(cls, result):
        """Whether a solve converged with every active crossing realised."""
        return (result["nlopt_result"] in cls.CONVERGED
                and all(s["status"] in ("ok", "inactive") for s in result["crossings"]))

    def remember_start(self, start_key, result):
        """Keeps a converged solve's points as the start of the same problem under other per-vertex
        bend limits (`start_key`: Memo.key with LIMITS left out)."""
        if self._converged(result):
            self.starts[start_key] = result["points"]

    def reusable(self, key, max_bend):
        """The remembered result for `key` if it is an optimum that the limit `max_bend` (radians)
        leaves optimal, or the result of exactly this problem (same key and limit), else None."""
        same = self.same.get((key, max_bend))
        if same is not None:
            self.reused += 1
            return same
        entry = self.solves.get(key)
        if entry is None:
            return None
        old_limit, r = entry
        optimum = r["feasible"] and self._converged(r)
        if not (optimum and max_bend <= old_limit and r["max_bend"] <= max_bend):
            return None
        self.reused += 1
        return r

    def remember(self, key, max_bend, result):
        self.solves[key] = (max_bend, result)
        self.same[(key, max_bend)] = result


def unrealisable(design):
    """The (crossing id, hook) pairs this stage could not realise (stages.target_shape's nulled
    crossings), for the re-layering loop (pipeline.relayer) to forbid: the hook that failed, or
    both hooks of a crossing whose failure no hook cures (`whatever_the_hook`, the solver's own
    verdict on either of its wires: a straight piece to a neighbour shorter than min_segment, an
    open end, a kink the contact angle rules out). A "too_close" crossing with a longer piece failed
    because that piece, fixed between the two crossings, lies outside the kink this hook needs: the
    other hook may hold it. Empty when the stage did not run."""
    pairs = set()
    for n in design["stages"].get("target_shape", {}).get("nulled_crossings", []):
        pairs.update((n["crossing"], h) for h in ((-1, 1) if n.get("whatever_the_hook") else (n["hook"],)))
    return pairs


def id_list(numbers):
    """"3" or "1, 2 and 5": the ids sorted, as the messages name crossings (the native's crossing_list)."""
    numbers = sorted(numbers)
    return ", ".join(map(str, numbers[:-1])) + f" and {numbers[-1]}" if len(numbers) > 1 else str(numbers[0])


def crossing_words(failure):
    """The solver's words for one failed crossing (`failure`: a nulled entry), naming it by the
    design's id, which users see, instead of the solver's number along the wire: the design's
    "crossing N on wire W: " and then the solver's `words`, what follows its own name ("it needs a
    bend …")."""
    return f"crossing {failure['crossing']} on wire {failure['wire']}: " + failure["words"]


def unrealised_summary(nulled, size):
    """One sentence for the crossings the target shape could not realise: those too close along
    their wires as one group with the size to scale to, the others each with the solver's words."""
    parts = []
    close = [n for n in nulled if n["status"] == "too_close"]
    if close:
        worst = max(close, key=lambda n: n["scale"])
        parts.append(f"crossing{'s' if len(close) > 1 else ''} {id_list(n['crossing'] for n in close)}, too "
                     f"close to {'their' if len(close) > 1 else 'its'} neighbours along the wires for a free "
                     f"bending point between them (the closest: {worst['message']})")
    for n in nulled:
        if n["status"] != "too_close":
            parts.append(crossing_words(n))
    return "the target shape cannot realise " + "; ".join(parts)


def run(design, material, settings, native_progress=None, memo=None):
    """Fills each wire's target, length and distances, each crossing's vertices, stages.target_shape;
    nulls crossings that cannot be realised and re-checks stability. Returns a progress line.
    `memo` (a Memo) carries the nulled crossings and the solves of an earlier coupling round with a
    higher bend limit into this one, and is updated with this round's."""
    start = time.perf_counter()
    # the model's size the scale advice names: the recorded mesh's (core/sizes.model_size), else the contours'
    size = design.get("model_size") or (memo.model_size(design) if memo is not None else model_size(design))
    nulled, iterations, wire_solves = [], 0, 0
    if memo is not None:
        for failure in memo.nulled:
            design["crossings"][failure["crossing"]]["hook"] = 0
            nulled.append(dict(failure))
    solved = [None] * len(design["wires"])
    reused = [False] * len(design["wires"])
    pending = range(len(design["wires"]))  # the first round solves every wire
    for _round in range(MAX_ROUNDS):
        sides = sides_by_wire(design)
        jobs, results = solve_all((prepare_wire(design, design["wires"][i], settings, size, memo, sides)
                                   for i in pending), native_progress, len(pending))
        for i, job, result in zip(pending, jobs, results):
            reused[i] = job["result"] is not None
            solved[i] = finish_wire(job, result, memo)
            if not reused[i]:
                iterations += result["iterations"]
                wire_solves += 1
        failing = {}
        for wire, (r, refs, _frame) in zip(design["wires"], solved):
            for (c, _k), status in zip(refs, r["crossings"]):
                if c["hook"] != 0 and status["status"] in FAILED:
                    entry = failing.setdefault(c["id"], {"crossing": c["id"], "hook": c["hook"], "wire": wire["name"],
                                                         "status": status["status"], "scale": status["scale"],
                                                         "message": status["message"], "cause": status["cause"],
                                                         "words": status["words"], "whatever_the_hook": False})
                    # on either of its wires (the first one's words are kept)
                    entry["whatever_the_hook"] |= whatever_the_hook(status["cause"])
        if not failing:
            break
        for cid, failure in failing.items():
            design["crossings"][cid]["hook"] = 0
            nulled.append(failure)
        # Only the wires through a newly nulled crossing change; the others keep their shapes.
        pending = sorted({w for cid in failing for w in design["crossings"][cid]["wires"]})
    else:
        raise RuntimeError("target shape: crossings kept failing after nulling; this is a solver bug")

    per_wire = []
    for wire, (r, refs, frame), again in zip(design["wires"], solved, reused):
        if again or "target" not in r:  # placed by the native only for the wire it was solved for
            target = to_3d(r["points"], *frame)
            wire["target"] = target.tolist()
            wire["length"] = polyline_length(target, wire["closed"])
        else:  # taken out of the result (which the memo keeps) to be the design's own list
            wire["target"] = r.pop("target")
            wire["length"] = r["length"]
        wire["target_max_distance"] = r["max_distance"]
        wire["target_rms_distance"] = r["rms_distance"]
        for (c, k), vertex in zip(refs, r["crossing_vertices"]):
            c.setdefault("vertices", [None, None])[k] = int(vertex)
        # A reused result cost nothing in this round (its solve is counted in the round that ran it).
        per_wire.append({"id": wire["id"], "seconds": 0.0 if again else r["seconds"],
                         "iterations": 0 if again else r["iterations"], "reused": again,
                         "max_distance": r["max_distance"], "rms_distance": r["rms_distance"],
                         "feasible": r["feasible"], "nlopt_result": r["nlopt_result"]})
        design.setdefault("warnings", []).extend(f"wire {wire['name']}: {w}" for w in r["warnings"])
        if not r["feasible"]:
            design["warnings"].append(f"wire {wire['name']}: the target shape violates a machine limit "
                                      f"(segments {r['max_length_violation'] * 1000:.3f} mm short, bends "
                                      f"{math.degrees(r['max_angle_violation']):.3f} deg over)")
    for c in design["crossings"]:
        if c["hook"] == 0:
            c["metric"] = 0.0
    seconds = time.perf_counter() - start
    design["stages"]["target_shape"] = {"seconds": seconds, "iterations": iterations, "wire_solves": wire_solves,
                                        "reused_wires": sum(reused),
                                        "wires": per_wire, "nulled_crossings": nulled}
    if memo is not None:
        memo.nulled = [dict(n) for n in nulled]
    if nulled:  # the verdict is the layering's: it re-checks the assembly without them
        design["stages"]["target_shape"]["recheck_lp_solves"] = layering.recheck_verdict(
            design, material, settings, unrealised_summary(nulled, size), len(nulled), native_progress,
            [memo.array(w) for w in design["wires"]] if memo is not None else None,
            [TOO_CLOSE] if any(n["status"] == "too_close" for n in nulled) else [])
    worst = max(w["max_distance"] for w in per_wire)
    return (f"{len(per_wire)} wires, largest distance to the contour {worst * 1000:.2f} mm, "
            f"{len(nulled)} crossings nulled, {iterations} iterations ({seconds:.3f} s)")
