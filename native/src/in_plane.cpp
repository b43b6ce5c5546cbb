#include "wiresculpt/in_plane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lp.hpp"
#include "wiresculpt/contact.hpp"

namespace wiresculpt {

bool balances_in_plane(const Network& net, int wire, const std::vector<int>& hooks) {
  const Plane& pl = net.wires[wire].plane;
  // Feasibility LP: columns N_c >= 1, rows (force u, force v, torque / size) fixed at 0. The
  // torque row is divided by the wire's extent so that all rows are forces.
  detail::LinearProgram lp;
  lp.maximise = false;
  lp.row_lo.assign(3, 0.0);
  lp.row_hi.assign(3, 0.0);
  std::vector<Vec3> points, dirs;
  for (int c : net.crossings_of(wire)) {
    if (hooks[c] == 0) continue;
    const Crossing& x = net.crossings[c];
    const double side = x.wires[0] == wire ? -1.0 : 1.0;
    points.push_back(x.point);
    dirs.push_back(side * hooks[c] * crossing_direction(net, c));
  }
  if (points.empty()) return true;
  double extent = 0.0;
  for (const Vec3& p : net.wires[wire].points) extent = std::max(extent, (p - pl.origin).norm());
  if (!(extent > 0.0)) extent = 1.0;
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < points.size(); ++k) {
    const int j = static_cast<int>(k);
    const double row[3] = {dirs[k].dot(pl.u), dirs[k].dot(pl.v),
                           pl.normal.dot((points[k] - pl.origin).cross(dirs[k])) / extent};
    for (int r = 0; r < 3; ++r) {
      if (std::abs(row[r]) < 1e-12) continue;
      lp.tri_row.push_back(r);
      lp.tri_col.push_back(j);
      lp.tri_val.push_back(row[r]);
    }
    lp.obj.push_back(1.0);
    lp.col_lo.push_back(1.0);
    lp.col_hi.push_back(inf);
  }
  return detail::solve_lp(lp).status == detail::LpSolution::optimal;
}

int unbalanced_in_plane(const Network& net, const std::vector<int>& hooks) {
  int count = 0;
  for (int w = 0; w < static_cast<int>(net.wires.size()); ++w) count += balances_in_plane(net, w, hooks) ? 0 : 1;
  return count;
}

}  // namespace wiresculpt
