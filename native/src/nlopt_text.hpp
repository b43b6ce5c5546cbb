#pragma once
// NLopt's result codes as the text reports show. Private to the core.
#include <nlopt.hpp>
#include <string>

namespace wiresculpt::detail {

inline std::string nlopt_result_text(nlopt::result r) {
  switch (r) {
    case nlopt::FAILURE: return "NLOPT_FAILURE";
    case nlopt::INVALID_ARGS: return "NLOPT_INVALID_ARGS";
    case nlopt::OUT_OF_MEMORY: return "NLOPT_OUT_OF_MEMORY";
    case nlopt::ROUNDOFF_LIMITED: return "NLOPT_ROUNDOFF_LIMITED";
    case nlopt::FORCED_STOP: return "NLOPT_FORCED_STOP";
    case nlopt::SUCCESS: return "NLOPT_SUCCESS";
    case nlopt::STOPVAL_REACHED: return "NLOPT_STOPVAL_REACHED";
    case nlopt::FTOL_REACHED: return "NLOPT_FTOL_REACHED";
    case nlopt::XTOL_REACHED: return "NLOPT_XTOL_REACHED";
    case nlopt::MAXEVAL_REACHED: return "NLOPT_MAXEVAL_REACHED";
    case nlopt::MAXTIME_REACHED: return "NLOPT_MAXTIME_REACHED";
    default: return "NLOPT_UNKNOWN";
  }
}

}  // namespace wiresculpt::detail
