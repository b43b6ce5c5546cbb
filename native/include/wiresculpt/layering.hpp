#pragma once
// Layering and assembly order (Sec. 4.2, Fig. 7 of Miguel, Lepoutre, Bickel 2016): a hook
// configuration per crossing (n_p = 3: null, +1, -1; see contact.hpp for the sign convention)
// and an order of adding wires such that every intermediate assembly is stable (Eq. 1; the first
// pair under forces only, every later prefix under forces and torques), found by depth-first
// branch and bound over the assembly tree. Method notes: docs/method-layering.md.
//
// Objective (lexicographic, minimised; e_c of Eq. 2 with e_c = 0 for a null crossing):
//   1. max_c e_c                       the paper's "smallest maximum deviation"
//   2. number of null crossings        ties prefer more interlocked crossings (more stability)
//   3. Σ_c e_c                         then the smallest total modification
//   4. number of two-hand steps        (only when single-wire steps cannot work, see below)
//   5. number of wires that do not balance in plane (in_plane.hpp; beyond the paper, only with
//      LayeringOptions::in_plane_tiebreak): among equal Eq. 2 costs, prefer hooks whose normal
//      forces can hold every wire within its own plane
// Floating-point keys are equal when within 1e-9. Among configurations equal in all keys the
// first one found is returned (deterministic).
//
// Exactness: the search returns a configuration and order whose objective is the minimum over
// every hook configuration (3^C, or those LayeringOptions::allowed_hooks allows) and every order of single-wire steps whose prefixes are all
// stable. Prunings used, all exact: (a) lower bound against the best complete structure;
// (b) dominance: a null crossing whose cheaper hook costs no more than the current maximum is
// never optimal (hooking it keeps every prefix stable, as pyramids only add columns, and lowers
// key 2), so such children are skipped; (c) an assembly state (wire set + hooks) reached again
// by another order is not expanded twice; (d) a step with 16 or more hook choices is skipped at
// once when even both hooks' pyramids together at all its new crossings leave it unstable (for
// fewer choices trying them one by one is cheaper); (e) before searching, the
// finished sculpture with both pyramids at every crossing must be stable, else no configuration
// is (the reason then names the wire that cannot be held); (f) a hook dearer than the best
// structure's maximum is never enumerated. Key 5 is counted for a wire once all its crossings
// are decided (a wire's verdict depends only on its own crossings' hooks), so the partial count
// is a lower bound and (a) stays exact. The search first follows the cheapest child of each
// step to reach a complete structure (and so a bound) quickly, then tries every other child
// that can still improve on the best.
//
// Beyond the paper (Sec. 6, the torus): when no single-wire order exists and
// LayeringOptions::two_wire_steps is set, the search is repeated allowing steps that add two
// wires at once (the prefix in between need not be stable); those steps are listed in
// LayeringResult::two_hand_steps. (A three-wire start never helps: if no pair has two crossings,
// three wires have at most three, 12 columns, fewer than the 13 needed to span the 12
// self-equilibrated loads of three wires; and, for 0 < contact_angle/2 - atan μ < π/2, any pair
// with two crossings is stable under forces only with opposite hooks.)
#include <array>
#include <numbers>
#include <string>
#include <vector>

#include "wiresculpt/contact.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/progress.hpp"

namespace wiresculpt {

struct LayeringOptions {
  ContactOptions contact;       ///< friction, contact angle, metric settings (contact.hpp)
  /// When no single-wire assembly order exists, search again allowing steps that add two wires
  /// at once (a second pair of hands). Needs at least 4 wires. Default true.
  bool two_wire_steps = true;
  /// Stop after this many search nodes (stability checks of candidate assemblies) and return the
  /// best found so far with a warning (LayeringResult::complete_search = false); 0 = no limit.
  /// The search is exponential in the worst case (a network whose finished form is stable but
  /// that has no stable order explores every order); the default bounds it to some seconds.
  /// Default 200000.
  long max_nodes = 200000;
  /// Steps with more new crossings than this are not enumerated (2^n hook choices each); a
  /// warning names the skipped wire. Default 20.
  int max_step_crossings = 20;
  /// Objective key 5: among hook patterns equal in keys 1-4, prefer those in which more wires
  /// balance in their own planes (in_plane.hpp). A second search after the first, seeded with
  /// its best. Off by default: on boxy models it costs up to ~1.2 s of layering (bench chair)
  /// against a 0.2 s target, and its gain was measured under the in-plane torque bound only
  /// (docs/method-layering.md). Default false.
  bool in_plane_tiebreak = false;
  /// Node budget of that second search (0 = no limit); when reached, the best found so far is
  /// kept (never worse than the first search's) with a warning and in_plane_complete = false.
  /// Default 300 (about 1.5 s on the bench chair; docs/method-layering.md).
  long in_plane_nodes = 300;
  /// Per crossing, which hooks the search may choose: [c][0] hook -1, [c][1] hook +1 (null is
  /// always allowed). A forbidden hook costs +inf, so it is never enumerated and every pruning
  /// above stays exact over the allowed configurations ((b) compares with the cheaper allowed
  /// hook; (d) and (e) put only the allowed hooks' pyramids). Used by the re-layering loop
  /// (pipeline.solve) to forbid what the target shape cannot realise. Empty (default): every hook
  /// allowed; otherwise one entry per crossing.
  std::vector<std::array<bool, 2>> allowed_hooks;
  /// Forbid (on top of allowed_hooks) every hook that too_close_hooks finds the target shape
  /// cannot realise, for crossings too close along a wire for a free bending point between them:
  /// every later stage would null them, so a structure that needs them is never stable through
  /// the pipeline, and with this set it fails here, in the hook-relaxed check (e) or the search.
  /// The plane search's screen sets it (plane_search.py), and so does the pipeline's re-layering
  /// loop (pipeline.relayer), unless its first layering so finds no stable assembly; with
  /// relayer_rounds 0 the pipeline layers once with every hook and lets the target shape null
  /// what it cannot realise. Default false.
  bool forbid_too_close = false;
  /// Radians: too_close_hooks' angle tolerance, at least the target shape's own
  /// (TargetShapeOptions::angle_tolerance; the pipeline's 0.1 deg). Default 0.1 deg.
  double too_close_angle_tolerance = std::numbers::pi / 1800.0;
};

struct LayeringStats {
  long lp_solves = 0;  ///< GLPK simplex calls
  long nodes = 0;      ///< candidate assemblies whose stability was checked
  double seconds = 0.0;
};

/// Why the layering finds no stable structure (LayeringResult::cause), each with the words the
/// reason gives for it.
enum class LayeringCause {
  none,               ///< stable (or a single wire)
  alone,              ///< a wire crosses no other wire: nothing can hold it
  disconnected,       ///< a group of wires crosses none of the others: the sculpture does not hang together
  no_crossings,       ///< no two wires cross
  no_stable_pair,     ///< no pair of wires is stable under forces only: no assembly can start
  no_assembly_order,  ///< no wire can be added stably to the largest stable partial assembly
  mechanism,          ///< not stable even with both hooks at every crossing (what_moves names what moves)
  search_incomplete,  ///< max_nodes stopped the search before a stable assembly was found
};

/// The snake_case name of a cause, as the binding hands it over: "no_assembly_order".
const char* cause_name(LayeringCause cause);

struct LayeringResult {
  /// Per crossing: -1, 0 or 1 (docs/formats.md `hook`). When unstable: the hooks of the largest stable
  /// partial assembly found, 0 elsewhere.
  std::vector<int> hooks;
  std::vector<double> metric;               ///< per crossing: e_c of the chosen hook (0 if null)
  std::vector<int> assembly_order;          ///< wire ids in the order a person adds them
  /// The same, grouped: steps[0] is the first pair, every later step one wire (or, with two
  /// hands, two).
  std::vector<std::vector<int>> steps;
  /// Indices into `steps` (never 0) of the steps that add two wires at once and need two hands.
  std::vector<int> two_hand_steps;
  bool stable = false;
  /// Empty when stable; otherwise a sentence naming the wire that cannot be added stably and
  /// the crossings involved.
  std::string reason;
  /// The cause `reason` gives (none when stable).
  LayeringCause cause = LayeringCause::none;
  /// The hooks the verdict left out (allowed_hooks' false entries, the too-close ones of
  /// forbid_too_close among them): a verdict over the allowed hooks only when not 0.
  int forbidden_hooks = 0;
  /// When not stable even with both hooks allowed at every crossing: the clause of `reason` that
  /// names what moves or what cannot be balanced (after "... allowed at every crossing, ", up to
  /// its first advice), for a program that shows or groups it; empty otherwise.
  std::string what_moves;
  std::vector<std::string> warnings;
  // The objective keys of the returned hooks (when unstable: max and sum over the partial
  // assembly's hooks, null_crossings 0).
  double max_metric = 0.0;  ///< objective key 1
  int null_crossings = 0;   ///< objective key 2
  double sum_metric = 0.0;  ///< objective key 3
  /// Objective key 5 of the returned hooks: wires that do not balance in plane (computed also
  /// when in_plane_tiebreak is off; 0 when unstable).
  int unbalanced_in_plane = 0;
  bool complete_search = true;  ///< false when max_nodes stopped the search (keys 1-4)
  bool in_plane_complete = true;  ///< false when in_plane_nodes stopped the key-5 search
  /// With LayeringOptions::forbid_too_close: the (crossing, hook -1 or +1) pairs it forbade
  /// (too_close_hooks; those allowed_hooks already forbade are not listed), by crossing; empty
  /// otherwise.
  std::vector<std::array<int, 2>> too_close_forbidden;
  LayeringStats stats;
};

/// Layering and assembly order of `net`. A two-wire network is its own first pair and is judged
/// under forces only (with a warning that it can turn about the planes' common line); a
/// one-wire network is trivially stable. Reports progress as stage "layering" and honours
/// cancellation (throws Cancelled). Throws InputError for an empty network, more than 64 wires or
/// invalid options.
LayeringResult layering(const Network& net, const LayeringOptions& options = {}, const ProgressFn& progress = {});

/// Per crossing, whether the target shape can realise each hook ([c][0] hook -1, [c][1] hook
/// +1) as far as the crossings' spacing decides it (target_shape.cpp, "too_close"): where two
/// crossings follow each other along a wire less than 2 net.min_segment apart, the piece between
/// them is one fixed straight segment, so
///   - when it is shorter than net.min_segment, neither hook of either crossing can be realised;
///   - otherwise a hook whose desired bisector on that wire (contact.hpp: +-d) lies more than
///     contact_angle / 2 + angle_tolerance from the segment's direction cannot (the target
///     shape's cone is contact_angle / 2 - atan(friction) wide, so this holds for any friction).
/// Borderline lengths and angles (within 1e-9 relative) count as realisable. Every entry is
/// true when the network was built without min_segment.
std::vector<std::array<bool, 2>> too_close_hooks(const Network& net, double contact_angle, double angle_tolerance);

/// The verdict of Eq. 1 for every prefix of a given assembly.
struct AssemblyCheck {
  bool stable = false;
  int failed_step = -1;  ///< index into `steps` of the first unstable prefix; -1 when stable
  /// The wire whose unit load could not be balanced in that prefix (-1 when stable or when the
  /// failing load was the negative sum of the basis loads).
  int failed_wire = -1;
  long lp_solves = 0;  ///< GLPK simplex calls
};

/// Eq. 1 for every prefix of the assembly `steps` (lists of wire ids added together) under
/// `hooks` (one of -1, 0, 1 per crossing of `net`): the check after a later stage changed
/// hooks. The first pair is judged under forces only (Sec. 4.2). Reports progress as stage
/// "check_assembly" once per step and honours cancellation (throws Cancelled). Throws
/// InputError for a wrong number of hooks or a bad wire id (check_stability's messages).
AssemblyCheck check_assembly(const Network& net, const std::vector<int>& hooks,
                             const std::vector<std::vector<int>>& steps, const ContactOptions& contact = {},
                             const ProgressFn& progress = {});

}  // namespace wiresculpt
