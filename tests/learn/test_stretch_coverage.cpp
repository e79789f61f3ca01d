// Stretch coverage (where a motion leaves a learned correction's training stretches): exact
// ranges under homogeneous deformations, counting against a training range with its tolerance,
// and the note for users.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// The bar's vertices mapped by x = F X (flat 3n): every element's deformation gradient is F.
VecX deformed(const mesh::TetMesh& mesh, const Mat3& F) {
  VecX x(3 * mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v)
    x.segment<3>(3 * v) = F * mesh.rest_positions().row(v).transpose();
  return x;
}

/// A rotation times diag(s): its principal stretches are s, whatever the order of s.
Mat3 rotated_stretch(const Vec3& s) {
  return Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix() * s.asDiagonal();
}

const mesh::TetMesh& bar() {
  static const mesh::TetMesh m = mesh::make_box_bar(Vec3(0.4, 0.1, 0.1), { 4, 1, 1 });
  return m;
}

} // namespace

TEST(StretchCoverage, RangeOfHomogeneousDeformationsIsTheirSortedStretches) {
  // Stretches given unsorted: the range is over sorted s₁ ≥ s₂ ≥ s₃.
  const std::vector<VecX> frames = { deformed(bar(), Mat3::Identity()),
    deformed(bar(), rotated_stretch(Vec3(0.97, 1.1, 1.0))) };
  const material::StretchRange r = trajectory_stretch_range(bar(), frames);
  EXPECT_NEAR((r.min - Vec3(1.0, 1.0, 0.97)).cwiseAbs().maxCoeff(), 0, 1e-12);
  EXPECT_NEAR((r.max - Vec3(1.1, 1.0, 1.0)).cwiseAbs().maxCoeff(), 0, 1e-12);
}

TEST(StretchCoverage, CountsSamplesOutsideTheTrainingRangeBeyondTheTolerance) {
  material::StretchRange trained;
  trained.include(Vec3(1.05, 1.0, 0.98));
  trained.include(Vec3(1.0, 0.99, 0.95));
  StretchCoverage coverage(bar(), trained, 1e-3);
  const long m = bar().num_tets();
  coverage.add_frame(deformed(bar(), rotated_stretch(Vec3(1.02, 1.0, 0.97)))); // inside
  coverage.add_frame(deformed(
      bar(), rotated_stretch(Vec3(1.0505, 0.995, 0.96)))); // s₁ 0.0005 over: within tolerance
  EXPECT_EQ(coverage.samples(), 2 * m);
  EXPECT_EQ(coverage.samples_outside(), 0);
  EXPECT_EQ(extrapolation_note(coverage), "");

  coverage.add_frame(deformed(bar(), rotated_stretch(Vec3(1.0, 0.99, 0.94)))); // s₃ 0.01 below
  coverage.add_frame(deformed(bar(), rotated_stretch(Vec3(1.1, 0.99, 0.96)))); // s₁ 0.05 above
  EXPECT_EQ(coverage.samples(), 4 * m);
  EXPECT_EQ(coverage.samples_outside(), 2 * m);
  EXPECT_DOUBLE_EQ(coverage.fraction_outside(), 0.5);
  const std::string note = extrapolation_note(coverage);
  EXPECT_NE(note.find("s₁ up to 1.100 (trained ≤ 1.050)"), std::string::npos) << note;
  EXPECT_NE(note.find("s₃ down to 0.940 (trained ≥ 0.950)"), std::string::npos) << note;
  EXPECT_EQ(note.find("s₂"), std::string::npos) << "s₂ stayed inside: " << note;
}

TEST(StretchCoverage, RefusesAFrameOfAnotherMesh) {
  StretchCoverage coverage(bar());
  EXPECT_THROW(coverage.add_frame(VecX::Zero(3 * bar().num_vertices() + 3)), InputError);
  EXPECT_TRUE(coverage.visited().empty());
}

TEST(StretchCoverage, NoCorrectionHasNoTrainingRange) {
  // The nominal model extrapolates nothing learned. (With a correction:
  // tests/app/test_cli_learn.cpp.)
  sim::Scene scene;
  scene.mesh = bar();
  EXPECT_FALSE(training_stretch_range(scene, nullptr).has_value());
}
