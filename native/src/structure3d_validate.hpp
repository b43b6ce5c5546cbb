#pragma once
// Input checks of solve_structure3d (structure3d.hpp). Private to the core.
#include "wiresculpt/structure3d.hpp"

namespace wiresculpt::detail {

/// Throws one InputError naming the option, wire, tie, load, support or table node at fault.
void validate(const Structure3dInput& input, const Structure3dOptions& options);

}  // namespace wiresculpt::detail
