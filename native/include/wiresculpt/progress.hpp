#pragma once
// Progress reporting for long stages: a callback receiving the stage name and a fraction in
// [0, 1]; it returns false to request cancellation, which the stage honours by throwing
// wiresculpt::Cancelled at the next safe point.
#include <functional>
#include <string_view>

#include "wiresculpt/error.hpp"

namespace wiresculpt {

using ProgressFn = std::function<bool(std::string_view stage, double fraction)>;

/// Calls `progress` if set and throws Cancelled when it asks to stop.
inline void report_progress(const ProgressFn& progress, std::string_view stage, double fraction) {
  if (progress && !progress(stage, fraction)) throw Cancelled();
}

}  // namespace wiresculpt
