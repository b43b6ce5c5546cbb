"""The plane assistant: placements of the slicing planes that give a stable, buildable
design. bpy-free, on top of the pipeline (pipeline.slice_and_pick, stages.layering, pipeline.solve);
the batch (settings.plane_search) and the add-on's operators both call it.

Two searches:

- `nearby(...)`: the user's planes, changed as little as possible. A *change* moves a plane along
  its normal by d, tilts it by an angle a about an axis in the plane (about the plane's point
  nearest the mesh's centre) or changes which contours it takes ("largest" <-> "all"). Its cost,
  the measure the search minimises, is

      cost = sum over changed planes of ( |d| / S  +  a / 1 rad  +  0.05 per contour-rule change )

  with S the model size (largest side of the mesh's bounding box): 5 % of the model's size costs
  as much as a tilt of 0.05 rad (2.9 deg). Candidates are one-plane changes (offsets
  +-{2, 4, 7, 10, 15, 20} % of S, tilts of 5, 10, 15 deg about two axes each way, the other
  contour rule: 25 per plane), tried in order of cost, then pairs of one-plane changes of two
  different planes (25 x 25 per pair of planes), those whose two changes, each screened alone,
  together free every wire at fault in the given planes first (plane_faults.Tally.pair_order), each
  group by cost. When none gives a stable design, the search's reason (nearby_reason) says what it
  searched, whether the budget cut it short and how much was left, its candidates counted by fault
  in each family (plane_faults), and what to change.
- `auto(...)`: planes from the mesh alone: `count` planes in families along the mesh's principal
  axes (area-weighted) or the world's, each family spread over the mesh's extent along its axis or
  over the quantiles of its surface area (family_planes), for every split of `count` over the three
  axes (balanced first) and every spread of SPREADS; each with the largest contour of every plane,
  and, when that fails the screen, the contours of the crossing network's largest connected part
  without hinged wires (Searcher.connected). Screened proposals are verified fewest crossings
  closer than 2 * min_segment along a wire first (close_gaps), then by the fidelity of their
  contours (highest first); its work bounded by auto_limits(count) (AUTO_SCREENS_PER_PLANE and
  AUTO_SOLVES_PER_PLANE per plane). When no proposal of the first screening
  round keeps its crossings 2 * min_segment apart, sets grown from count - 1 planes (grow: a
  family proposal plus one plane at an area quantile along one of its axes) are screened and
  verified first.

Every candidate is screened cheaply first: slicing (each plane placement sliced once per search,
the planes of many candidates in one native call, Searcher.slice_ahead; the designs share each
contour's points, and the layering's copy of a design copies no points) and the layering
(stages.layering), whose first step is the hook-relaxed stability check (every
crossing a ball joint: a mechanism is rejected in about a millisecond) and whose search then
finds the hooks; both without the hooks the target shape cannot realise at crossings too close
along a wire (Searcher._layer). Only survivors run the full pipeline (pipeline.solve: target shape, forces, rest
shape, buildability) with the layering's own hooks (CANDIDATE_HOOK_PATTERNS), and a candidate is
returned only when that says stable (which means buildable, fab/buildability). The returned
design then gets the comparison of hook patterns by their forces (Searcher.finish), at most
FINAL_HOOK_PATTERNS patterns; when that does not end stable, the verified design is kept.

Work, not time: every choice is bounded by counts (candidates screened, full solves, a screen's
layering nodes SCREEN_NODES, FINAL_HOOK_PATTERNS), so a scene gives the same design on any machine
and under any load. The clock (the context's, SolveContext.clock) only stops a search that takes
too long: its guard (BUDGET_SECONDS, auto_budget, FINAL_SECONDS; `stopped_by` "time" in the record)
and the run's one budget, settings.max_solve_seconds (OutOfTime, which ends the run).

Score of a returned candidate (documented in docs/formats.md, higher is better):

    score = fidelity                                   (auto; a design with two-hand assembly
                                                        steps ranks after every one without)
    score = -cost                                      (nearby)

fidelity: the share of the model's outline from the front, the side and the top that the solved
wires trace (core/fidelity.py: within 0.03 S of a projected wire, on rendered masks), written into
the design as `fidelity`. Every returned candidate of either search also carries it, and coverage
(the share of the mesh's vertices within 0.1 S of some wire's contour), in its figures
(Searcher.looks): what the panel shows beside each candidate.
"""
from .auto import (AUTO_SCREENS_PER_PLANE, AUTO_SECONDS_PER_PLANE, AUTO_SOLVES_PER_PLANE, auto_limits,  # noqa: F401
                   EARLY_SOLVES, GROW_BASES, GROW_QUANTILES,  # noqa: F401
                   SPREADS, area_quantile_plane, auto, auto_budget, family_planes, grow, splits_of)
from .batch import MODES, run  # noqa: F401
from .nearby import BUDGET_SECONDS, NEARBY_SCREENS, NEARBY_SOLVES, PAIR_SINGLES, SLICE_AHEAD, nearby  # noqa: F401
from .placements import OFFSETS, RULE_COST, TILTS_DEG, Placement, mesh_frame, single_changes  # noqa: F401
from .records import nearby_reason  # noqa: F401
from .searcher import (CANDIDATE_HOOK_PATTERNS, COVERAGE_RADIUS, FINAL_HOOK_PATTERNS, FINAL_HOOK_SECONDS,  # noqa: F401
                       FINAL_SECONDS, SCREEN_NODES, SCREEN_SECONDS, Searcher)
from ..core.plane_faults import Tally, close_gaps, crossing_gaps  # noqa: F401 (the search's names for them)
