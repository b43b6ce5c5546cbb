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

}  // namespace wiresculpt::detail
