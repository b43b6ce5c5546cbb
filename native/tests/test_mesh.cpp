// Mesh preparation: welding against a brute-force clustering, degenerate and duplicate removal.
#include <catch2/catch.hpp>
#include <random>

#include "wiresculpt/error.hpp"
#include "wiresculpt/mesh.hpp"

using namespace wiresculpt;

TEST_CASE("mesh: welding matches brute force, including clusters on grid-cell faces") {
  const double tol = 1e-6;
  const double h = 64 * tol;  // the weld grid's cell size
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3 * tol, 0.3 * tol);
  std::uniform_int_distribution<int> cell(-50, 50);
  // Cluster centres exactly on cell faces, edges and corners, far apart from each other.
  std::vector<Eigen::RowVector3d> centres;
  for (int c = 0; c < 60; ++c)
    centres.emplace_back(h * 10 * cell(rng), h * 10 * cell(rng) + (c % 2) * 0.5 * h, h * 10 * cell(rng));
  MatrixX3d V(centres.size() * 4, 3);
  std::vector<int> truth;
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t c = 0; c < centres.size(); ++c) {
      V.row(static_cast<Eigen::Index>(k * centres.size() + c)) = centres[c] + Eigen::RowVector3d(jitter(rng), jitter(rng), jitter(rng));
      truth.push_back(static_cast<int>(c));
    }
  // Brute force: each vertex joins the first earlier vertex within tol.
  std::vector<int> cluster(static_cast<std::size_t>(V.rows()));
  int clusters = 0;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    cluster[static_cast<std::size_t>(i)] = -1;
    for (Eigen::Index j = 0; j < i && cluster[static_cast<std::size_t>(i)] < 0; ++j)
      if ((V.row(i) - V.row(j)).norm() <= tol) cluster[static_cast<std::size_t>(i)] = cluster[static_cast<std::size_t>(j)];
    if (cluster[static_cast<std::size_t>(i)] < 0) cluster[static_cast<std::size_t>(i)] = clusters++;
  }
  REQUIRE(clusters == static_cast<int>(centres.size()));  // the construction is unambiguous
  // One triangle per cluster triple so every vertex is used.
  MatrixX3i F(static_cast<Eigen::Index>(centres.size()), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t) F.row(t) << static_cast<int>(t), static_cast<int>((t + 1) % F.rows()), static_cast<int>((t + 2) % F.rows());
  const TriMesh m = prepare_mesh(V, F, MeshOptions{tol});
  CHECK(m.V.rows() == clusters);
  CHECK(m.welded_vertices == static_cast<std::size_t>(V.rows() - clusters));
  CHECK(m.weld_tolerance == tol);
}

TEST_CASE("mesh: vertices farther apart than the tolerance stay apart") {
  MatrixX3d V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1.5e-6, 0, 0;
  MatrixX3i F(2, 3);
  F << 0, 1, 2, 3, 1, 2;
  CHECK(prepare_mesh(V, F, MeshOptions{1e-6}).V.rows() == 4);
  const TriMesh merged = prepare_mesh(V, F, MeshOptions{2e-6});
  CHECK(merged.V.rows() == 3);
  CHECK(merged.F.rows() == 1);  // the second triangle became a duplicate of the first
  CHECK(merged.dropped_duplicate == 1);
}

TEST_CASE("mesh: the automatic tolerance is 1e-7 of the bounding-box diagonal") {
  MatrixX3d V(3, 3);
  V << 0, 0, 0, 3, 0, 0, 0, 4, 0;
  MatrixX3i F(1, 3);
  F << 0, 1, 2;
  CHECK(prepare_mesh(V, F).weld_tolerance == Approx(5e-7));
  CHECK_THROWS_AS(prepare_mesh(V, F, MeshOptions{std::nan("")}), InputError);
}
