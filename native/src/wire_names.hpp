#pragma once
// How messages name wires and crossings (internal to the core): 'A/0', "a, b and c".
#include <string>
#include <vector>

#include "wiresculpt/network.hpp"

namespace wiresculpt::detail {

inline std::string quoted(const Network& net, int w) { return "'" + net.wires[w].name + "'"; }

/// "a", "a and b", "a, b and c".
inline std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t k = 0; k < items.size(); ++k)
    out += (k == 0 ? "" : (k + 1 == items.size() ? " and " : ", ")) + items[k];
  return out;
}

inline std::string wire_list(const Network& net, const std::vector<int>& wires) {
  std::vector<std::string> names;
  for (int w : wires) names.push_back(quoted(net, w));
  return join(names);
}

inline std::string crossing_list(const std::vector<int>& crossings) {
  std::vector<std::string> ids;
  for (int c : crossings) ids.push_back(std::to_string(c));
  return join(ids);
}

}  // namespace wiresculpt::detail
