#pragma once
// A figure said against the limit it breaks (internal to the core): "turns 60.01 deg, more than the
// machine's maximum reliable bend of 60.00 deg". Both are written with the same precision, and with
// as many digits as it takes for the two to read differently, so that a violation never reads
// "60.0 deg, more than 60.0 deg" or "60.01 deg, more than 60.0 deg". The add-on's own messages do
// the same (addon/wiresculpt/core/figures.py).
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace wiresculpt::detail {

/// A double has at most 17 significant digits: with that many, two different numbers print differently.
inline constexpr int kMostDigits = 17;

/// `value` printed with `style` 'f' (`digits` decimals) or 'g' (`digits` significant digits).
inline std::string figure(double value, int digits, char style = 'f') {
  char buf[400];  // "%.17f" of the largest double: 309 digits, the point and 17 decimals
  std::snprintf(buf, sizeof buf, style == 'g' ? "%.*g" : "%.*f", digits, value);
  return buf;
}

/// (value text, limit text): `value` and the `limit` it breaks written alike (figure), with one
/// digit more at a time while |value| and |limit| would read the same, up to kMostDigits. `value`
/// keeps its sign (a bend to the right is negative); like the checks, the comparison is of
/// magnitudes. Equal or non-finite figures keep `digits`.
inline std::pair<std::string, std::string> versus(double value, double limit, int digits, char style = 'f') {
  int d = digits;
  while (d < kMostDigits && std::isfinite(value) && std::isfinite(limit) && std::abs(value) != std::abs(limit) &&
         figure(std::abs(value), d, style) == figure(std::abs(limit), d, style))
    ++d;
  return {figure(value, d, style), figure(limit, d, style)};
}

/// The one scale rule (docs/user-guide.md, "Scale advice"): two crossings `arc` metres apart along a
/// wire need room for a free bending point between them, two straight pieces of at least
/// `min_segment` each, so the model must grow by 2 min_segment / arc (1e300 for arc <= 0). The
/// network's close crossings and the target shape's too-close ones both say this factor.
inline double gap_scale(double arc, double min_segment) { return arc > 0 ? 2.0 * min_segment / arc : 1e300; }

/// The words of a scale advice, as the add-on's core/sizes.scale_advice makes them: "scale the model
/// up at least 2.51 times (largest side 0.214 m -> 0.538 m)"; without the sizes when `size` <= 0.
inline std::string scale_words(double factor, double size) {
  std::string out = "scale the model up at least " + figure(factor, 2) + " times";
  if (size > 0) out += " (largest side " + figure(size, 4, 'g') + " m -> " + figure(size * factor, 4, 'g') + " m)";
  return out;
}

}  // namespace wiresculpt::detail
