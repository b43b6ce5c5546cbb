// The energy of the target shape (Eq. 3-5): the IMLS distance over the target's point grid, the
// nearest-point distance over its edge grid where the kernel thins out, and the regulariser.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "wiresculpt/target_shape.hpp"

namespace wiresculpt {
namespace {
// Kernel mass below which E_d blends from the IMLS into the nearest-point distance. A point on a
// densely sampled target has Φ ≈ 1.63 (h = 2 × spacing); Φ = 0.5 is reached about 0.45 h off it.
constexpr double kernel_mass_full = 0.5;

// Closest point of segment [a, b] to q.
Vec2 closest_on_segment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double l2 = d.squaredNorm();
  if (l2 <= 0.0) return a;
  const double t = std::clamp((q - a).dot(d) / l2, 0.0, 1.0);
  return a + t * d;
}
}  // namespace

double TargetShapeProblem::nearest_squared(const Vec2& q, Vec2* grad) const {
  const int m = static_cast<int>(target_.size());
  const int m_edges = closed_ ? m : m - 1;
  double best = std::numeric_limits<double>::infinity();
  Vec2 best_point = target_[0];
  int best_edge = -1;
  // Equally near edges (two edges meeting at the nearest vertex: one ends there at a + 1·(b - a),
  // the other starts there, points that can differ in the last bit) are decided as the search by
  // target points would decide them: the edge it would test first, in its order of rings, rows,
  // cells, points and, per point k, edge k before edge k - 1; or the lower index when q was
  // outside the points' grid. So the gradient, hence every solve, keeps that search's answers.
  using Rank = std::array<long long, 5>;
  auto rank = [&](int k) {
    const double fx = (q.x() - grid_origin_.x()) / cell_, fy = (q.y() - grid_origin_.y()) / cell_;
    if (fx < 0 || fy < 0 || fx >= grid_nx_ || fy >= grid_ny_) return Rank{0, 0, 0, k, 0};
    const int cx = static_cast<int>(fx), cy = static_cast<int>(fy);
    auto from_point = [&](int v, int sub) {
      const Vec2& p = target_[v];
      const int ix = std::clamp(static_cast<int>((p.x() - grid_origin_.x()) / cell_), 0, grid_nx_ - 1);
      const int iy = std::clamp(static_cast<int>((p.y() - grid_origin_.y()) / cell_), 0, grid_ny_ - 1);
      return Rank{std::max(std::abs(ix - cx), std::abs(iy - cy)), iy, ix, v, sub};
    };
    return std::min(from_point(k, 0), from_point((k + 1) % m, 1));
  };
  auto try_edge = [&](int k) {
    const Vec2 c = closest_on_segment(q, target_[k], target_[(k + 1) % m]);
    const double d2 = (q - c).squaredNorm();
    if (d2 < best || (d2 == best && best_edge >= 0 && k != best_edge && rank(k) < rank(best_edge))) best = d2, best_point = c, best_edge = k;
  };
  if (m_edges == 0) {
    best = (q - target_[0]).squaredNorm();
  } else {
    const double fx = (q.x() - grid_origin_.x()) / edge_cell_, fy = (q.y() - grid_origin_.y()) / edge_cell_;
    if (!std::isfinite(fx) || !std::isfinite(fy)) {
      for (int k = 0; k < m_edges; ++k) try_edge(k);  // no distance to compare: as every edge says
    } else {
      // Rings of grid cells around q's cell, each cell holding the edges that meet it. A cell of
      // ring r is at least (r - 1) cells from q, and a cell farther from q than the best distance
      // so far cannot hold a nearer point: both are skipped, with a picometre of slack for the
      // rounding of the cell bounds, so the minimum is that of every edge (an edge tested twice,
      // from two cells, changes nothing: only a strictly nearer point replaces the best).
      constexpr double slack = 1e-12;  // m
      // q's cell, or the cell of the grid nearest it when q is outside the target's box (kink
      // neighbours pushed beyond the contour's extremes): a cell r rings from it is still at least
      // r - 1 cells from q.
      const int cx = static_cast<int>(std::clamp(fx, 0.0, edge_nx_ - 1.0));
      const int cy = static_cast<int>(std::clamp(fy, 0.0, edge_ny_ - 1.0));
      const int max_ring = std::max(edge_nx_, edge_ny_);
      double reach2 = std::numeric_limits<double>::infinity();  // (sqrt(best) + slack)^2
      auto visit = [&](int ix, int iy) {
        const double x0 = grid_origin_.x() + ix * edge_cell_, y0 = grid_origin_.y() + iy * edge_cell_;
        const double dx = std::max({0.0, x0 - q.x(), q.x() - (x0 + edge_cell_)});
        const double dy = std::max({0.0, y0 - q.y(), q.y() - (y0 + edge_cell_)});
        if (dx * dx + dy * dy > reach2) return;
        const int cell = iy * edge_nx_ + ix;
        for (int it = edge_start_[cell]; it < edge_start_[cell + 1]; ++it) {
          const double before = best;
          try_edge(edge_items_[it]);
          if (best < before) reach2 = (std::sqrt(best) + slack) * (std::sqrt(best) + slack);
        }
      };
      for (int ring = 0; ring <= max_ring; ++ring) {
        const double gap = (ring - 1) * edge_cell_;
        if (ring > 1 && gap * gap > reach2) break;
        for (int iy = std::max(cy - ring, 0); iy <= std::min(cy + ring, edge_ny_ - 1); ++iy) {
          const bool edge_row = iy == cy - ring || iy == cy + ring;
          if (edge_row) {
            for (int ix = std::max(cx - ring, 0); ix <= std::min(cx + ring, edge_nx_ - 1); ++ix) visit(ix, iy);
          } else {
            if (cx - ring >= 0) visit(cx - ring, iy);
            if (cx + ring < edge_nx_) visit(cx + ring, iy);
          }
        }
      }
    }
  }
  if (grad) *grad = 2.0 * (q - best_point);
  return best;
}

double TargetShapeProblem::distance_to_contour(const Vec2& q) const { return std::sqrt(nearest_squared(q, nullptr)); }

double TargetShapeProblem::imls(const Vec2& q, Vec2* grad) const {
  const double h2 = h_ * h_;
  double Phi = 0.0, N = 0.0;
  Vec2 dPhi = Vec2::Zero(), dN = Vec2::Zero();
  // The cell of q; a point far outside the grid (or not finite, as an optimiser's trial point can
  // be) maps to -2, so the loops below visit no cell (and no double is cast out of int's range).
  const auto cell_of = [](double t, int n) {
    const double f = std::floor(t);
    return f >= -2.0 && f <= static_cast<double>(n) + 1.0 ? static_cast<int>(f) : -2;
  };
  const int cx = cell_of((q.x() - grid_origin_.x()) / cell_, grid_nx_);
  const int cy = cell_of((q.y() - grid_origin_.y()) / cell_, grid_ny_);
  for (int iy = std::max(cy - 1, 0); iy <= std::min(cy + 1, grid_ny_ - 1); ++iy)
    for (int ix = std::max(cx - 1, 0); ix <= std::min(cx + 1, grid_nx_ - 1); ++ix) {
      const int cell = iy * grid_nx_ + ix;
      for (int it = grid_start_[cell]; it < grid_start_[cell + 1]; ++it) {
        const int k = grid_items_[it];
        const Vec2 d = q - target_[k];
        const double r2 = d.squaredNorm();
        if (r2 >= h2) continue;
        const double a = 1.0 - r2 / h2;
        const double a3 = a * a * a;
        const double phi = a3 * a;
        const double nd = normals_[k].dot(d);
        const double f = nd * nd;
        Phi += phi;
        N += phi * f;
        if (grad) {
          const Vec2 dphi = (-8.0 * a3 / h2) * d;
          dPhi += dphi;
          dN += f * dphi + (2.0 * phi * nd) * normals_[k];
        }
      }
    }
  if (Phi >= kernel_mass_full) {
    const double I = N / Phi;
    if (grad) *grad = (dN - I * dPhi) / Phi;
    return I;
  }
  // Blend into the squared distance to the nearest target point: D = s I + (1 - s) g, with the
  // C¹ smoothstep s(Φ/Φ0) that vanishes (with its derivative) where no kernel reaches q.
  Vec2 dg;
  const double g = nearest_squared(q, grad ? &dg : nullptr);
  if (Phi <= 0.0) {
    if (grad) *grad = dg;
    return g;
  }
  const double t = Phi / kernel_mass_full;
  const double s = t * t * (3.0 - 2.0 * t);
  const double ds = 6.0 * t * (1.0 - t) / kernel_mass_full;
  const double I = N / Phi;
  if (grad) {
    const Vec2 dI = (dN - I * dPhi) / Phi;
    *grad = ds * (I - g) * dPhi + s * dI + (1.0 - s) * dg;
  }
  return s * I + (1.0 - s) * g;
}

double TargetShapeProblem::distance_term(const Polyline2& p, int i, Polyline2* grad, ImlsSample* sample) const {
  const int m = static_cast<int>(p.size());
  Vec2 dD;
  const double D = imls(p[i], grad ? &dD : nullptr);
  if (grad && sample) *sample = {p[i], D, dD};
  // w_i = |p_i - p_{i-1}| + |p_{i+1} - p_i| (one term at an open end).
  double wi = 0.0;
  for (int side : {-1, 1}) {
    const int j = i + side;
    if (!closed_ && (j < 0 || j >= m)) continue;
    const int jj = (j + m) % m;
    const Vec2 e = p[i] - p[jj];
    const double len = e.norm();
    wi += len;
    if (grad && len > 0.0) {
      const Vec2 de = (D / len) * e;
      (*grad)[i] += de;
      (*grad)[jj] -= de;
    }
  }
  if (grad) (*grad)[i] += wi * dD;
  return wi * D;
}

double TargetShapeProblem::regularization_term(const Polyline2& p, int i, double weight, Polyline2* grad) const {
  const int m = static_cast<int>(p.size());
  if (!closed_ && (i == 0 || i == m - 1)) return 0.0;
  const int a = (i + m - 1) % m, b = (i + 1) % m;
  const Vec2 L = (p[i] - initial_[i]) - 0.5 * ((p[a] - initial_[a]) + (p[b] - initial_[b]));
  if (grad) {
    (*grad)[i] += (2.0 * weight) * L;
    (*grad)[a] -= weight * L;
    (*grad)[b] -= weight * L;
  }
  return weight * L.squaredNorm();
}

double TargetShapeProblem::distance_energy(const Polyline2& p, Polyline2* grad) const {
  if (grad) grad->resize(p.size(), Vec2::Zero());
  double E = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) E += distance_term(p, i, grad);
  return E;
}

double TargetShapeProblem::regularization_energy(const Polyline2& p, Polyline2* grad) const {
  if (grad) grad->resize(p.size(), Vec2::Zero());
  double E = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) E += regularization_term(p, i, 1.0, grad);
  return E;
}

double TargetShapeProblem::energy(const Polyline2& p, Polyline2* grad) const {
  if (grad) grad->resize(p.size(), Vec2::Zero());
  double E = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) {
    const double d = distance_term(p, i, grad);  // first: both add into grad, in this order
    E += d + regularization_term(p, i, options_.regularization, grad);
  }
  return E;
}

double TargetShapeProblem::energy_terms(const Polyline2& p, const std::vector<int>& terms, Polyline2* grad,
                                        std::vector<ImlsSample>* samples) const {
  double E = 0.0;
  if (grad && samples) samples->resize(terms.size());
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const int i = terms[k];
    const double d = distance_term(p, i, grad, grad && samples ? &(*samples)[k] : nullptr);  // first, as in energy
    E += d + regularization_term(p, i, options_.regularization, grad);
  }
  return E;
}

}  // namespace wiresculpt
