// Mesh placement (scale, rotation, translation): the documented rotation convention, exact
// inversion, and that a placed mesh keeps every tet positively oriented with volume s³·V.
#include "mesh_test_util.hpp"

#include <elastolearn/mesh/placement.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <cmath>

using namespace elastolearn;
using namespace elastolearn::mesh;

namespace {

Placement awkward_placement() {
  Placement p;
  p.scale = 2.5;
  p.rotate_deg = Vec3(30, -47, 123); // no axis-aligned shortcut
  p.translate = Vec3(1.25, -2, 3.5);
  return p;
}

} // namespace

TEST(Placement, RotatesAboutWorldXThenYThenZ) {
  // Extrinsic x-y-z: e_y turns into e_z about x, then e_z into e_x about y. Another order or
  // intrinsic axes would leave e_y at e_z or send it elsewhere.
  Placement p;
  p.rotate_deg = Vec3(90, 90, 0);
  EXPECT_LT((p.rotation() * Vec3::UnitY() - Vec3::UnitX()).norm(), 1e-15);
  // Right-hand rule: +90° about z sends e_x to e_y.
  p.rotate_deg = Vec3(0, 0, 90);
  EXPECT_LT((p.rotation() * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-15);
  // Order of operations: scale, rotate, then translate.
  p.scale = 2;
  p.translate = Vec3(10, 0, 0);
  const Positions x = Positions(Vec3::UnitX().transpose());
  EXPECT_LT((place(x, p).row(0).transpose() - Vec3(10, 2, 0)).norm(), 1e-14);
}

TEST(Placement, InverseGivesBackTheRestPositions) {
  const TetMesh box = make_box_bar(Vec3(0.4, 0.1, 0.2), { 4, 2, 3 });
  const Placement p = awkward_placement();
  const Positions back = unplace(place(box.rest_positions(), p), p);
  // Two 3×3 products and a translation by ~4 m: round-off of a few ulps of the placed
  // coordinates (|x| ≲ 5 m), divided back by s = 2.5.
  EXPECT_LT((back - box.rest_positions()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(Placement, KeepsOrientationAndScalesVolumesByScaleCubed) {
  const TetMesh box = make_box_bar(Vec3(0.4, 0.1, 0.2), { 4, 2, 3 });
  const Placement p = awkward_placement();
  const TetMesh placed = place(box, p); // the constructor rejects inverted or degenerate tets
  ASSERT_EQ(placed.num_tets(), box.num_tets());
  const VecX before = box.element_volumes(), after = placed.element_volumes();
  const double s3 = std::pow(p.scale, 3);
  for (Eigen::Index e = 0; e < before.size(); ++e) {
    EXPECT_GT(signed_volume(placed.rest_positions().row(placed.tets()(e, 0)),
                  placed.rest_positions().row(placed.tets()(e, 1)),
                  placed.rest_positions().row(placed.tets()(e, 2)),
                  placed.rest_positions().row(placed.tets()(e, 3))),
        0)
        << "tet " << e;
    // A determinant of edge vectors of size ~0.1·s: relative round-off ~1e-15.
    EXPECT_NEAR(after[e], s3 * before[e], 1e-12 * s3 * before[e]) << "tet " << e;
  }
}

TEST(Placement, RefusesAScaleThatIsNotPositive) {
  const TetMesh box = make_box_bar(Vec3(1, 1, 1), { 1, 1, 1 });
  for (double s : { -1.0, 0.0, std::nan("") }) {
    Placement p;
    p.scale = s;
    test::expect_input_error([&] { place(box, p); }, { "scale", "positive" });
  }
}
