#pragma once
// What a 1:1 template (SVG, DXF) shows of one wire.
#include <cstddef>
#include <string>
#include <vector>

#include "wiresculpt/geometry.hpp"

namespace wiresculpt::fab {

struct TemplateWire {
  std::string name;                           ///< label, e.g. "A/0"
  Polyline2 points;                           ///< #P by 2, metres, in the wire's own 2D frame
  std::vector<std::size_t> bend_points;       ///< indices into points: tick marks (see bend_vertices())
  std::vector<std::size_t> crossing_points;   ///< indices into points: crossing marks
  /// Metres, in the wire's frame: where the wire crosses itself (the rest shape must pass over
  /// itself on the bender), marked so the maker sees it before bending.
  Polyline2 self_crossings;
  /// Metres, in the wire's frame: the wire the machine is predicted to make (predict_polyline),
  /// drawn dashed over the rest shape and named in the legend; empty: none drawn.
  Polyline2 preview;
  /// m, the preview's largest distance from the rest shape (arclength_distance), for the legend;
  /// negative: not given.
  double preview_distance = -1.0;
  /// m, the last stretch of `points` fed past a closed wire's cut so its ends overlap (the
  /// profile's closed_overlap): drawn as a wide band labelled with its length; 0: none.
  double overlap = 0.0;
};

/// Throws InputError naming the wire (`index`, name) when it has no point, a non-finite point
/// or a bend/crossing index outside 0..#P-1.
void validate(const TemplateWire& wire, std::size_t index);

}  // namespace wiresculpt::fab
