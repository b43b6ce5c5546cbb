#include "wiresculpt/fab/template_wire.hpp"

#include <cmath>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {

void validate(const TemplateWire& wire, std::size_t index) {
  const std::string who = "wire " + std::to_string(index) + " ('" + wire.name + "')";
  if (wire.points.empty()) throw InputError(who + " has no points");
  for (std::size_t i = 0; i < wire.points.size(); ++i)
    if (!wire.points[i].allFinite())
      throw InputError(who + ": point " + std::to_string(i) + " has a non-finite coordinate");
  const std::size_t n = wire.points.size();
  for (std::size_t i : wire.bend_points)
    if (i >= n)
      throw InputError(who + ": bend point index " + std::to_string(i) + " is outside 0.." + std::to_string(n - 1));
  for (std::size_t i : wire.crossing_points)
    if (i >= n)
      throw InputError(who + ": crossing point index " + std::to_string(i) + " is outside 0.." +
                       std::to_string(n - 1));
  for (std::size_t i = 0; i < wire.self_crossings.size(); ++i)
    if (!wire.self_crossings[i].allFinite())
      throw InputError(who + ": self-crossing " + std::to_string(i) + " has a non-finite coordinate");
  if (!(std::isfinite(wire.overlap) && wire.overlap >= 0.0))
    throw InputError(who + ": the overlap must be a finite, non-negative length");
  for (std::size_t i = 0; i < wire.preview.size(); ++i)
    if (!wire.preview[i].allFinite())
      throw InputError(who + ": preview point " + std::to_string(i) + " has a non-finite coordinate");
}

}  // namespace wiresculpt::fab
