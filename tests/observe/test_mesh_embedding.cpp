// Observing a motion through another mesh: points embedded in a host tet mesh follow its tets'
// affine motion exactly, a nested grid's vertices reproduce the host's vertex positions bit for
// bit, and a point outside the host is an error naming it.
#include <elastolearn/core/error.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/observe/mesh_embedding.hpp>

#include <gtest/gtest.h>

#include <random>
#include <string>

using namespace elastolearn;
using namespace elastolearn::observe;

namespace {

const Vec3 kSize(0.17, 0.04, 0.04);

/// Host rest positions moved by a smooth non-affine field (bend + twist), deterministic.
Positions bent(const Positions& rest) {
  Positions x = rest;
  for (Eigen::Index v = 0; v < rest.rows(); ++v) {
    const double s = rest(v, 0);
    x(v, 1) += 0.3 * s * s;
    x(v, 2) += 0.1 * s * rest(v, 1) + 0.05 * std::sin(20 * s);
  }
  return x;
}

} // namespace

TEST(MeshEmbedding, APointInsideADeformedTetGetsItsAffineImage) {
  // Each tet's motion is affine, so a point inside it moves to A p + b of that tet's affine map.
  // Under a global affine map every tet's map is that map: every embedded point must land on
  // A p + b (round-off only: 1e-15 m on positions of 0.1 m). Under a non-affine motion the image
  // is the barycentric combination, whose weights reproduce the rest point.
  const mesh::TetMesh host = mesh::make_box_bar(kSize, { 6, 3, 3 });
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  Positions points(200, 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    points.row(i) = Vec3(u(rng) * kSize.x(), u(rng) * kSize.y(), u(rng) * kSize.z()).transpose();
  const MeshEmbedding embedding = embed_points(host, points, 0.0);
  ASSERT_EQ(embedding.num_points(), 200);
  EXPECT_EQ(embedding.largest_outside, 0.0);
  Mat3 A;
  A << 1.1, 0.2, -0.3, 0.05, 0.9, 0.4, -0.2, 0.1, 1.3;
  const Vec3 b(0.3, -0.1, 0.02);
  const Positions moved = (host.rest_positions() * A.transpose()).rowwise() + b.transpose();
  const Positions image = embedding.map(host.tets(), moved);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Vec3 expected = A * points.row(i).transpose() + b;
    EXPECT_LT((image.row(i).transpose() - expected).norm(), 1e-15 * 100) << "point " << i;
    const Eigen::Vector4d& w = embedding.weights[i];
    EXPECT_GE(w.minCoeff(), 0.0);
    EXPECT_NEAR(w.sum(), 1.0, 1e-15);
  }
  const Positions at_rest = embedding.map(host.tets(), host.rest_positions());
  EXPECT_LT((at_rest - points).cwiseAbs().maxCoeff(), 1e-15);
  // Non-affine: the image is Σ w_a x_a of the containing tet's deformed vertices.
  const Positions deformed = bent(host.rest_positions());
  const Positions curved = embedding.map(host.tets(), deformed);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    Vec3 expected = Vec3::Zero();
    for (int a = 0; a < 4; ++a)
      expected
          += embedding.weights[i][a] * deformed.row(host.tets()(embedding.tets[i], a)).transpose();
    EXPECT_LT((curved.row(i).transpose() - expected).norm(), 1e-15);
  }
}

TEST(MeshEmbedding, ANestedGridsVerticesGetTheHostVertexPositionsBitForBit) {
  // The coarse bar's vertices (17 × 4 × 4 cells) are vertices of the fine one (34 × 8 × 8):
  // observed through the fine mesh's motion they must be exactly the fine vertices' positions
  // (weight 1 on that vertex), so observations of a coarse mesh carry no interpolation error.
  const mesh::TetMesh fine = mesh::make_box_bar(kSize, { 34, 8, 8 });
  const mesh::TetMesh coarse = mesh::make_box_bar(kSize, { 17, 4, 4 });
  const MeshEmbedding embedding
      = embed_points(fine, coarse.rest_positions(), 1e-6 * fine.bounding_box_diagonal());
  const Positions deformed = bent(fine.rest_positions());
  const Positions image = embedding.map(fine.tets(), deformed);
  for (int v = 0; v < coarse.num_vertices(); ++v) {
    // The fine vertex at the coarse vertex's rest position (grid indices doubled).
    int match = -1;
    for (int w = 0; w < fine.num_vertices() && match < 0; ++w)
      if ((fine.rest_positions().row(w) - coarse.rest_positions().row(v)).norm() < 1e-12)
        match = w;
    ASSERT_GE(match, 0) << "coarse vertex " << v;
    EXPECT_EQ(image(v, 0), deformed(match, 0)) << "coarse vertex " << v;
    EXPECT_EQ(image(v, 1), deformed(match, 1)) << "coarse vertex " << v;
    EXPECT_EQ(image(v, 2), deformed(match, 2)) << "coarse vertex " << v;
  }
}

TEST(MeshEmbedding, APointOutsideTheHostIsAnErrorNamingIt) {
  const mesh::TetMesh host = mesh::make_box_bar(kSize, { 4, 2, 2 });
  Positions points(3, 3);
  points << 0.05, 0.02, 0.02, //
      0.17 + 1e-9, 0.01, 0.03, // 1 nm outside the end face: round-off, accepted
      0.1, 0.02, 0.041; // 1 mm above the top face
  try {
    embed_points(host, points, 1e-7, "coarse.json: vertex");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("coarse.json: vertex 2"), std::string::npos) << message;
    EXPECT_NE(message.find("outside the mesh"), std::string::npos) << message;
  }
  const MeshEmbedding near = embed_points(host, points.topRows(2), 1e-7);
  EXPECT_NEAR(near.largest_outside, 1e-9, 1e-12);
  // Far outside the host's bounding box.
  Positions far(1, 3);
  far << 2.0, 0.0, 0.0;
  EXPECT_THROW(embed_points(host, far, 1e-7), InputError);
  EXPECT_THROW(embed_points(host, points, -1.0), InputError);
}
