// Stress reconstruction (paper 000 §6.1, Eqs. 10–13): a known RBF correction (elastic + damping)
// is recovered from the nodal forces fem::ElasticForce gives it, and the LSQR option returns the
// minimum-norm least-squares element stresses. (correction_force and CorrectionForceJacobian
// themselves: test_correction_force.cpp.)
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/fem/elastic_force.hpp>
#include <elastolearn/learn/correction_force.hpp>
#include <elastolearn/learn/element_state.hpp>
#include <elastolearn/learn/kmeans.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>
#include <elastolearn/learn/stress_reconstruction_lsqr.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <Eigen/QR>
#include <gtest/gtest.h>

#include <cmath>
#include <ctime>
#include <iostream>
#include <random>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

std::shared_ptr<const material::CorotatedModel> nominal() {
  return std::make_shared<material::CorotatedModel>(material::Lame::from_young_poisson(5e4, 0.4));
}

/// Rayleigh α₁ = 0.1 s (default): large enough that α₁ + Δα₁ stays > 0 for the random Δα₁ of
/// the tests.
std::shared_ptr<const material::RayleighDamping> rayleigh(double alpha1 = 0.1) {
  return std::make_shared<material::RayleighDamping>(0.0, alpha1);
}

/// The nominal material of the reconstruction (elastic model and Rayleigh damping).
fem::MaterialModel nominal_material(double alpha1 = 0.1) {
  return { nominal(), nullptr, rayleigh(alpha1), 1000 };
}

/// Smoothly deformed, rotated and moving frames of `mesh`: x = R (X + A X + s(X)) + c with a
/// random affine part (|A_ij| ≤ 0.12) and a sine bend along x, v = W X + cos bend (|W_ij| ≤ 1/s).
/// Stretches stay within about [0.75, 1.3] (no inversion).
struct Frames {
  std::vector<VecX> positions, velocities;
};
Frames make_frames(const mesh::TetMesh& mesh, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Positions& X = mesh.rest_positions();
  const double length = mesh.bounding_box().sizes().maxCoeff();
  Frames frames;
  for (int t = 0; t < count; ++t) {
    Mat3 A, W;
    for (int k = 0; k < 9; ++k) {
      A.data()[k] = 0.12 * u(rng);
      W.data()[k] = u(rng);
    }
    const Eigen::Quaterniond q(1.0, 0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng));
    const Mat3 R = q.normalized().toRotationMatrix();
    const Vec3 bend(0.03 * u(rng), 0.05 * u(rng), 0.05 * u(rng)), phase(u(rng), u(rng), u(rng));
    VecX x(3 * X.rows()), v(3 * X.rows());
    for (Eigen::Index i = 0; i < X.rows(); ++i) {
      const Vec3 p = X.row(i).transpose();
      const double s = 3.0 * p[0] / length;
      Vec3 d = A * p, w = W * p;
      for (int c = 0; c < 3; ++c) {
        d[c] += length * bend[c] * std::sin(s + phase[c]);
        w[c] += 0.5 * std::cos(2 * s + phase[c]);
      }
      x.segment<3>(3 * i) = R * (p + d) + Vec3(0.1, -0.2, 0.05);
      v.segment<3>(3 * i) = w;
    }
    frames.positions.push_back(std::move(x));
    frames.velocities.push_back(std::move(v));
  }
  return frames;
}

/// Vertices on the face x = 0 (fixed in the tests, so some elements touch prescribed dofs).
std::vector<int> left_face(const mesh::TetMesh& mesh) {
  std::vector<int> ids;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.rest_positions()(i, 0) == 0.0)
      ids.push_back(i);
  return ids;
}

/// Nodal forces of `correction` through an independent path: ElasticForce with the correction
/// minus ElasticForce without (same nominal, Rayleigh α₁ = 0.1 s so that α₁ + Δα₁ stays > 0).
VecX elastic_force_difference(const mesh::TetMesh& mesh, const material::RbfCorrection& correction,
    const VecX& x, const VecX& v, double alpha1) {
  fem::ElasticForce with(mesh, { nominal(), correction.clone(), rayleigh(alpha1), 1000 });
  fem::ElasticForce without(mesh, { nominal(), nullptr, rayleigh(alpha1), 1000 });
  VecX f = VecX::Zero(x.size()), f0 = VecX::Zero(x.size());
  with.add_force({ x, v }, f);
  without.add_force({ x, v }, f0);
  return f - f0;
}

RbfFitOptions design_options(double regularization) {
  RbfFitOptions o;
  o.regularization = regularization;
  o.damping_regularization = regularization;
  return o;
}

/// Random unknowns of `design`: elastic weights up to `elastic` [Pa], damping weights up to 10 ms.
VecX random_unknowns(const RbfDesign& design, unsigned seed, double elastic) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX x(design.num_unknowns());
  const int qe = design.elastic_unknowns();
  for (int i = 0; i < x.size(); ++i)
    x[i] = (i < qe ? elastic : 1e-2) * u(rng);
  return x;
}

struct KnownAnswer {
  mesh::TetMesh mesh = mesh::make_box_bar(Vec3(0.4, 0.1, 0.1), { 6, 2, 2 });
  double alpha1;
  ReconstructionMesh geometry;
  fem::DofMap dofs { mesh.num_vertices(), left_face(mesh) };
  Frames frames = make_frames(mesh, 10, 7);
  RbfDesign design;
  VecX truth;
  std::vector<VecX> targets;

  /// `damped`: the truth has a Δα₁ part and the nominal Rayleigh α₁ = 0.1 s (else no damping).
  /// `elastic`: amplitude of the elastic unknowns [Pa] (the nominal's μ is 17.9 kPa).
  explicit KnownAnswer(double regularization, bool damped = true, double elastic = 2e3)
      : alpha1(damped ? 0.1 : 0.0)
      , geometry(mesh, nominal_material(alpha1))
      , design(centres(), design_options(regularization)) {
    truth = random_unknowns(design, 11, elastic);
    if (!damped)
      truth.tail(design.damping_unknowns()).setZero();
    const material::RbfCorrection n = design.correction(truth);
    for (size_t t = 0; t < frames.positions.size(); ++t)
      targets.push_back(
          elastic_force_difference(mesh, n, frames.positions[t], frames.velocities[t], alpha1));
  }
  MatX centres() const {
    KMeansOptions k;
    k.clusters = 4;
    return kmeans(collect_stretches(geometry, frames.positions), k).centres;
  }
};

} // namespace

TEST(StressReconstruction, CollectStretchesIsSortedAndCapped) {
  const KnownAnswer k(1e-12);
  const MatX all = collect_stretches(k.geometry, k.frames.positions);
  const int m = k.mesh.num_tets();
  ASSERT_EQ(all.rows(), 10 * m);
  // Row (frame 3, element 5) is that element's principal stretches.
  const Mat3 F = fem::deformation_gradient(
      fem::gather_tet(k.frames.positions[3], k.mesh.tets().row(5).transpose()), k.geometry.rest[5]);
  EXPECT_LE(
      (all.row(3 * m + 5).transpose() - material::principal_frame(F).stretches).norm(), 1e-14);
  for (Eigen::Index i = 0; i < all.rows(); ++i) {
    EXPECT_GE(all(i, 0), all(i, 1));
    EXPECT_GE(all(i, 1), all(i, 2));
  }
  StretchSampleOptions o;
  o.frame_stride = 3; // frames 0, 3, 6, 9
  o.max_samples = 100;
  const MatX capped = collect_stretches(k.geometry, k.frames.positions, o);
  EXPECT_LE(capped.rows(), 100);
  EXPECT_GE(capped.rows(), 50); // every ⌈4m/100⌉-th sample
  EXPECT_EQ(capped.row(1), all.row(6)); // step ⌈576/100⌉ = 6: sample 6 is frame 0, element 6
}

TEST(StressReconstruction, RecoversKnownRbfCorrectionFromNodalForces) {
  const KnownAnswer k(1e-13);
  const StressReconstructionResult r = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, k.targets);
  EXPECT_EQ(r.misfit.frames, 10);
  EXPECT_EQ(r.rows_per_frame, k.dofs.num_free());
  // The truth lies in the design and the targets are exact, so the only errors are round-off
  // amplified by the conditioning of the normal equations and the Tikhonov bias (λ = 1e-13).
  // Measured: 2e-10 (elastic), 5e-11 (damping), force misfit 4e-12. 1e-6 leaves room for other
  // summation orders; a wrong operator (sign, transposed frame, missing damping) gives O(1), and
  // so does leaving out the nominal α₁'s action on the correction's stiffness (measured: elastic
  // weights 680 % off).
  const int qe = k.design.elastic_unknowns();
  const auto relative = [&](Eigen::Index start, Eigen::Index size) {
    return (r.unknowns.segment(start, size) - k.truth.segment(start, size)).norm()
        / k.truth.segment(start, size).norm();
  };
  EXPECT_LT(relative(0, qe), 1e-6) << "elastic weights";
  EXPECT_LT(relative(qe, k.design.damping_unknowns()), 1e-6) << "damping weights";
  EXPECT_LT(r.misfit.rms_residual, 1e-8 * r.misfit.rms_target);
  EXPECT_GT(r.misfit.rms_target, 0.0);

  // Every second frame still determines the 35 unknowns (5 frames × 162 free dofs).
  StressReconstructionOptions o;
  o.frame_stride = 2;
  const StressReconstructionResult half = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, k.targets, o);
  EXPECT_EQ(half.misfit.frames, 5);
  EXPECT_LT((half.unknowns - k.truth).norm(), 1e-6 * k.truth.norm());
}

TEST(StressReconstruction, SmoothnessPenaltyEntersTheNormalEquations) {
  // A very strong smoothness penalty (RbfFitOptions::smoothness) leaves the elastic and damping
  // kernel weights only their means; the reconstruction without it recovers the truth's
  // (above). A penalty left out, or on the wrong block, keeps the truth's weights.
  const KnownAnswer k(1e-13);
  RbfFitOptions options = design_options(1e-13);
  options.smoothness = 1e6;
  const RbfDesign smooth(k.centres(), options);
  const StressReconstructionResult r = reconstruct_rbf_correction(
      k.geometry, k.dofs, smooth, k.frames.positions, k.frames.velocities, k.targets);
  const int m = smooth.num_centres(), qe = smooth.elastic_unknowns();
  const auto wiggle = [&](const VecX& x, int first) {
    const VecX w = x.segment(first, m);
    return (w.array() - w.mean()).matrix().norm();
  };
  EXPECT_LT(wiggle(r.unknowns, 0), 1e-3 * wiggle(k.truth, 0)) << "elastic weights";
  EXPECT_LT(wiggle(r.unknowns, qe), 1e-3 * wiggle(k.truth, qe)) << "damping weights";
}

TEST(StressReconstruction, RecoversACurvedDampingCurveWithTheQuadraticDampingTail) {
  // A Δα₁ of the largest stretch alone, s₁ − 1 + 20 (s₁ − 1)² [s] (bar-damping1's truth minus
  // its nominal α₁), lies in the span of the quadratic damping tail: reconstructed from nodal
  // forces it comes back exactly, curvature included; without the tail it does not, and its
  // value at a stretch beyond most of the samples' is off. KnownAnswer gives the bar, its frames
  // and centres (its own random truth is not used).
  const KnownAnswer known(1e-13);
  const mesh::TetMesh& mesh = known.mesh;
  const Frames& frames = known.frames;
  const MatX centres = known.centres();
  RbfFitOptions curved = design_options(1e-13), straight = curved;
  curved.damping_quadratic_tail = true;
  const RbfDesign design(centres, curved), linear_design(centres, straight);
  const int m = static_cast<int>(centres.rows()), qe = design.elastic_unknowns();
  ASSERT_EQ(design.damping_unknowns(), m + 7);
  VecX truth = VecX::Zero(design.num_unknowns());
  truth[qe + m] = 1.0; // slope along s₁
  truth[qe + m + 4] = 20.0; // curvature along s₁
  const material::RbfCorrection n = design.correction(truth);
  EXPECT_EQ(design.unknowns(n), truth);
  EXPECT_THROW(linear_design.unknowns(n), InputError); // a term that design cannot carry
  const Vec3 far(1.12, 0.97, 0.95);
  ASSERT_NEAR(n.stiffness_damping(far), 0.12 + 20 * 0.0144, 1e-14);
  std::vector<VecX> targets;
  for (size_t t = 0; t < frames.positions.size(); ++t)
    targets.push_back(
        elastic_force_difference(mesh, n, frames.positions[t], frames.velocities[t], known.alpha1));
  const auto reconstructed = [&](const RbfDesign& d) {
    return d.correction(reconstruct_rbf_correction(
        known.geometry, known.dofs, d, frames.positions, frames.velocities, targets)
                            .unknowns);
  };
  const material::RbfCorrection with_tail = reconstructed(design),
                                without_tail = reconstructed(linear_design);
  // Exact targets in the design's span: round-off and the 1e-13 Tikhonov bias only (measured
  // below 1e-9); a missing or misplaced column gives O(1).
  EXPECT_NEAR(with_tail.parameters().damping_quadratic[0], 20.0, 1e-6);
  EXPECT_NEAR(with_tail.stiffness_damping(far), n.stiffness_damping(far), 1e-8);
  const double off = std::abs(without_tail.stiffness_damping(far) - n.stiffness_damping(far))
      / n.stiffness_damping(far);
  std::cout << "[ damping  ] Δα₁ at s₁ = 1.12 without the quadratic tail: " << off * 100
            << " % off\n";
  EXPECT_GT(off, 0.05); // measured 17 %
}

TEST(StressReconstruction, ProjectedFitIgnoresTargetForcesOutsideTheProjection) {
  // Targets = the known correction's forces + forces orthogonal to span P (what a reduced
  // trajectory's strain errors leave outside the POD basis). The projected fit with μ = 0 must
  // recover the truth as if the targets were clean; the unprojected fit, and the projected one
  // with μ > 0, absorb part of the perturbation.
  const KnownAnswer k(1e-13);
  const int free = k.dofs.num_free();
  std::mt19937 random(5);
  std::normal_distribution<double> normal;
  MatX basis(free, 24); // 24 × 10 frames = 240 equations for 35 unknowns
  for (Eigen::Index i = 0; i < basis.size(); ++i)
    basis.data()[i] = normal(random);
  const MatX projection
      = Eigen::HouseholderQR<MatX>(basis).householderQ() * MatX::Identity(free, 24);
  std::vector<VecX> perturbed = k.targets;
  for (VecX& target : perturbed) {
    VecX noise(free);
    for (Eigen::Index i = 0; i < free; ++i)
      noise[i] = normal(random);
    noise -= projection * (projection.transpose() * noise); // ⟂ span P
    VecX full = VecX::Zero(k.dofs.num_dofs());
    for (int d = 0; d < k.dofs.num_dofs(); ++d)
      if (k.dofs.free_index(d) >= 0)
        full[d] = noise[k.dofs.free_index(d)];
    target += 0.5 * target.norm() / full.norm() * full;
  }
  const auto error = [&](const StressReconstructionResult& r) {
    return (r.unknowns - k.truth).norm() / k.truth.norm();
  };
  StressReconstructionOptions o;
  o.full_space_weight = 0;
  const auto projected = reconstruct_rbf_correction(k.geometry, k.dofs, k.design,
      k.frames.positions, k.frames.velocities, perturbed, o, projection);
  // Exact data within span P: round-off only (measured 3e-11; μ = 0.1: 0.49, unprojected: 0.99).
  EXPECT_LT(error(projected), 1e-6);
  const auto unprojected = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, perturbed);
  EXPECT_GT(error(unprojected), 1e-3);
  o.full_space_weight = 0.1;
  const auto mixed = reconstruct_rbf_correction(k.geometry, k.dofs, k.design, k.frames.positions,
      k.frames.velocities, perturbed, o, projection);
  std::printf(
      "[ measured ] relative unknowns error: projected %.2e, μ = 0.1 %.2e, unprojected %.2e\n",
      error(projected), error(mixed), error(unprojected));
  EXPECT_GT(error(mixed), error(projected));
  EXPECT_LT(error(mixed), error(unprojected));
  // The reported misfit is the unprojected one (the perturbation is in it).
  EXPECT_GT(projected.misfit.rms_residual, 0.1 * projected.misfit.rms_target);

  // A projection needs one row per free dof, and the lsqr method has none.
  EXPECT_THROW(reconstruct_rbf_correction(k.geometry, k.dofs, k.design, k.frames.positions,
                   k.frames.velocities, k.targets, o, projection.topRows(free - 1)),
      InputError);
  o.method = ReconstructionMethod::lsqr;
  EXPECT_THROW(reconstruct_rbf_correction(k.geometry, k.dofs, k.design, k.frames.positions,
                   k.frames.velocities, k.targets, o, projection),
      InputError);
  StressReconstructionOptions negative;
  negative.full_space_weight = -0.1;
  EXPECT_THROW(negative.validate(), InputError);
}

TEST(StressReconstruction, RejectsInconsistentFrames) {
  const KnownAnswer k(1e-12);
  std::vector<VecX> short_targets(k.targets.begin(), k.targets.end() - 1);
  EXPECT_THROW(reconstruct_rbf_correction(k.geometry, k.dofs, k.design, k.frames.positions,
                   k.frames.velocities, short_targets),
      InputError);
  std::vector<VecX> bad = k.targets;
  bad[2][4] = std::nan("");
  EXPECT_THROW(reconstruct_rbf_correction(
                   k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, bad),
      InputError);
  const fem::DofMap wrong(k.mesh.num_vertices() - 1, {});
  EXPECT_THROW(reconstruct_rbf_correction(
                   k.geometry, wrong, k.design, k.frames.positions, k.frames.velocities, k.targets),
      InputError);
  // Static frames leave the damping weights undetermined: singular without regularisation.
  const KnownAnswer unregularised(0.0);
  std::vector<VecX> still(10, VecX::Zero(3 * k.mesh.num_vertices()));
  EXPECT_THROW(reconstruct_rbf_correction(unregularised.geometry, unregularised.dofs,
                   unregularised.design, k.frames.positions, still, k.targets),
      InputError);
  // A stiffness scale must have one entry per tet (the reconstruction applies it per element).
  fem::MaterialModel scaled = nominal_material();
  scaled.stiffness_scale = std::make_shared<std::vector<double>>(k.mesh.num_tets() - 1, 1.0);
  EXPECT_THROW(ReconstructionMesh(k.mesh, scaled), InputError);
  EXPECT_THROW(ReconstructionMesh(k.geometry.rest, k.geometry.tets, k.mesh.num_vertices(), scaled),
      InputError);
}

TEST(StressReconstruction, SeveralMotionsFitOneCorrectionToAllTheirEquations) {
  // A training set's reconstruction sums every motion's equations. With targets that no
  // correction explains exactly (the known correction's forces plus 30 % noise), the fit depends
  // on which equations it sees: ten frames split into two motions of the same mesh must give the
  // fit of one motion of all ten (bit for bit here: with at most 16 frames each frame's sums
  // form their own block, added in the same order; 1e-10 allows for other block splits), while
  // a dropped or doubled frame moves it far more. A second motion of another mesh, with exact
  // targets of the same correction, is fitted jointly: the truth comes back, and the misfit
  // covers every motion's frames. The lsqr method joins the motions' samples.
  const KnownAnswer k(1e-13);
  std::mt19937 random(3);
  std::normal_distribution<double> normal;
  std::vector<VecX> noisy = k.targets;
  for (VecX& target : noisy) {
    VecX noise(target.size());
    for (Eigen::Index i = 0; i < noise.size(); ++i)
      noise[i] = normal(random);
    target += 0.3 * target.norm() / noise.norm() * noise;
  }
  const auto head = [](const std::vector<VecX>& v, size_t n) {
    return std::vector<VecX>(v.begin(), v.begin() + long(n));
  };
  const auto tail = [](const std::vector<VecX>& v, size_t n) {
    return std::vector<VecX>(v.begin() + long(n), v.end());
  };
  const std::vector<VecX> x0 = head(k.frames.positions, 4), x1 = tail(k.frames.positions, 4),
                          v0 = head(k.frames.velocities, 4), v1 = tail(k.frames.velocities, 4),
                          g0 = head(noisy, 4), g1 = tail(noisy, 4);
  const MatX none;
  const std::vector<ReconstructionMotion> split { { k.geometry, k.dofs, x0, v0, g0, none },
    { k.geometry, k.dofs, x1, v1, g1, none } };
  const StressReconstructionResult whole = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, noisy);
  const StressReconstructionResult joint = reconstruct_rbf_correction(split, k.design);
  const auto distance = [&](const StressReconstructionResult& r) {
    return (r.unknowns - whole.unknowns).norm() / whole.unknowns.norm();
  };
  EXPECT_LT(distance(joint), 1e-10);
  EXPECT_EQ(joint.misfit.frames, 10);
  EXPECT_NEAR(
      joint.misfit.rms_residual, whole.misfit.rms_residual, 1e-12 * whole.misfit.rms_residual);
  EXPECT_NEAR(joint.misfit.rms_target, whole.misfit.rms_target, 1e-12 * whole.misfit.rms_target);
  EXPECT_EQ(joint.rows_per_frame, 2 * k.dofs.num_free());
  const std::vector<VecX> x1_doubled = tail(k.frames.positions, 3),
                          v1_doubled = tail(k.frames.velocities, 3), g1_doubled = tail(noisy, 3);
  const std::vector<ReconstructionMotion> overlapping { { k.geometry, k.dofs, x0, v0, g0, none },
    { k.geometry, k.dofs, x1_doubled, v1_doubled, g1_doubled, none } };
  const double doubled = distance(reconstruct_rbf_correction(overlapping, k.design));
  const double dropped = distance(reconstruct_rbf_correction(std::span(split).first(1), k.design));
  std::printf("[ measured ] fit moved by a doubled frame %.1e, by dropping a motion %.1e\n",
      doubled, dropped);
  EXPECT_GT(doubled, 1e-2); // measured 0.11
  EXPECT_GT(dropped, 1e-2); // measured 0.58
  // One motion through the span is the single-motion fit, bit for bit.
  const StressReconstructionResult one = reconstruct_rbf_correction(
      std::span(split).first(1), k.design, StressReconstructionOptions {});
  const StressReconstructionResult first
      = reconstruct_rbf_correction(k.geometry, k.dofs, k.design, x0, v0, g0);
  EXPECT_EQ(one.unknowns, first.unknowns);
  EXPECT_EQ(one.misfit.rms_residual, first.misfit.rms_residual);

  // Another mesh, the same correction.
  const mesh::TetMesh other = mesh::make_box_bar(Vec3(0.3, 0.08, 0.06), { 4, 2, 1 });
  const ReconstructionMesh other_geometry(other, nominal_material(k.alpha1));
  const fem::DofMap other_dofs(other.num_vertices(), left_face(other));
  const Frames other_frames = make_frames(other, 6, 9);
  const material::RbfCorrection truth = k.design.correction(k.truth);
  std::vector<VecX> other_targets;
  for (size_t t = 0; t < other_frames.positions.size(); ++t)
    other_targets.push_back(elastic_force_difference(
        other, truth, other_frames.positions[t], other_frames.velocities[t], k.alpha1));
  const std::vector<VecX> exact0 = head(k.targets, 4);
  const std::vector<ReconstructionMotion> meshes { { k.geometry, k.dofs, x0, v0, exact0, none },
    { other_geometry, other_dofs, other_frames.positions, other_frames.velocities, other_targets,
        none } };
  const StressReconstructionResult both = reconstruct_rbf_correction(meshes, k.design);
  EXPECT_LT((both.unknowns - k.truth).norm(), 1e-6 * k.truth.norm());
  EXPECT_EQ(both.misfit.frames, 10);
  EXPECT_LT(both.misfit.rms_residual, 1e-8 * both.misfit.rms_target);
  // A misfit over both meshes: each motion's mean square weighted by its frames × free vertices.
  const ForceMisfit a = correction_force_misfit(k.geometry, k.dofs, truth, x0, v0, exact0),
                    b = correction_force_misfit(other_geometry, other_dofs, truth,
                        other_frames.positions, other_frames.velocities, other_targets);
  const double wa = 4.0 * k.dofs.num_free(), wb = 6.0 * other_dofs.num_free();
  EXPECT_NEAR(both.misfit.rms_target,
      std::sqrt((wa * a.rms_target * a.rms_target + wb * b.rms_target * b.rms_target) / (wa + wb)),
      1e-12 * both.misfit.rms_target);

  // The lsqr method fits one RBF to every motion's element-stress samples, in motion then frame
  // order: split into two motions, the samples are those of the whole, and so is the fit.
  StressReconstructionOptions lsqr;
  lsqr.method = ReconstructionMethod::lsqr;
  const StressReconstructionResult lsqr_whole = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, noisy, lsqr);
  const StressReconstructionResult lsqr_joint = reconstruct_rbf_correction(split, k.design, lsqr);
  EXPECT_EQ(lsqr_joint.unknowns, lsqr_whole.unknowns);
  EXPECT_EQ(lsqr_joint.stress_rms_residual, lsqr_whole.stress_rms_residual);
  EXPECT_EQ(lsqr_joint.lsqr_max_iterations, lsqr_whole.lsqr_max_iterations);
  EXPECT_EQ(lsqr_joint.misfit.frames, 10);
  EXPECT_EQ(reconstruct_rbf_correction(meshes, k.design, lsqr).misfit.frames, 10);

  // No motion is refused.
  EXPECT_THROW(
      reconstruct_rbf_correction(std::span<const ReconstructionMotion>(), k.design), InputError);
}

TEST(StressReconstructionLsqr, MinimumNormLeastSquaresStresses) {
  // 12 tets (36 stresses) and 12 vertices, 2 fixed: 30 free dofs, so B has a null space. No
  // nominal model: correction_force is then the elastic part B p̂ alone.
  const mesh::TetMesh mesh = mesh::make_box_bar(Vec3(0.2, 0.1, 0.1), { 2, 1, 1 });
  const ReconstructionMesh geometry(mesh);
  const fem::DofMap dofs(mesh.num_vertices(), { 0, 3 });
  const Frames frames = make_frames(mesh, 1, 3);
  std::vector<ElementState> states;
  compute_element_states(geometry, frames.positions[0], frames.velocities[0], states);
  const MatX B = MatX(assemble_stress_operator(geometry, dofs, states));
  ASSERT_EQ(B.rows(), 30);
  ASSERT_EQ(B.cols(), 36);

  // B applied to a correction's element stresses is that correction's nodal force.
  const KnownAnswer k(1e-12);
  const material::RbfCorrection n = k.design.correction(k.truth);
  VecX p(36);
  for (int e = 0; e < 12; ++e)
    p.segment<3>(3 * e) = n.correction(states[e].frame.stretches, states[e].stretch_rates);
  const VecX f_n
      = dofs.restrict(correction_force(geometry, n, frames.positions[0], frames.velocities[0]));
  EXPECT_LE((B * p - f_n).norm(), 1e-12 * f_n.norm());

  // An arbitrary (inconsistent) force: CGLS from zero gives the pseudo-inverse solution.
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0.0, 1.0);
  VecX full = VecX::Zero(3 * mesh.num_vertices());
  for (Eigen::Index i = 0; i < full.size(); ++i)
    full[i] = g(rng);
  StressReconstructionOptions o;
  o.lsqr_tolerance = 1e-13;
  const ElementStressResult r
      = reconstruct_element_stresses(geometry, dofs, frames.positions[0], full, o);
  const VecX reference = Eigen::CompleteOrthogonalDecomposition<MatX>(B).solve(dofs.restrict(full));
  // B has rank 27 of 30 (zero net force/torque directions) with condition ≈ 2e2 on its range;
  // CGLS runs to 1e-13 on the normal equations. Measured difference 3e-13; 1e-8 is loose but
  // far below the O(1) gap to any non-minimum-norm solution (the null space is 9-dimensional).
  EXPECT_LT((r.stresses - reference).norm(), 1e-8 * reference.norm());
  EXPECT_LT((B.transpose() * (B * r.stresses - dofs.restrict(full))).norm(),
      1e-10 * (B.transpose() * dofs.restrict(full)).norm());

  // A consistent force is reproduced, and by a stress no larger than the one that made it.
  VecX consistent = VecX::Zero(full.size());
  for (int i = 0; i < dofs.num_free(); ++i)
    consistent[dofs.free_dofs()[i]] = f_n[i];
  const ElementStressResult c
      = reconstruct_element_stresses(geometry, dofs, frames.positions[0], consistent, o);
  EXPECT_LT(c.residual_norm, 1e-9 * c.target_norm);
  EXPECT_LE(c.stresses.norm(), p.norm() * (1 + 1e-12));
}

TEST(StressReconstructionLsqr, PipelineFitsButDirectMethodIsOptimal) {
  // An elastic truth: the LSQR pipeline fits element stresses, which carry no Δα₁.
  const KnownAnswer k(1e-10, false);
  StressReconstructionOptions o;
  o.method = ReconstructionMethod::lsqr;
  const StressReconstructionResult lsqr = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, k.targets, o);
  const StressReconstructionResult direct = reconstruct_rbf_correction(
      k.geometry, k.dofs, k.design, k.frames.positions, k.frames.velocities, k.targets);
  EXPECT_LE(lsqr.lsqr_max_relative_error, 1e-8);
  EXPECT_GT(lsqr.lsqr_max_iterations, 0);
  // The direct method minimises the force misfit over the same unknowns, so the LSQR pipeline
  // (which fits min-norm stresses, Fig. 4) cannot do better; it still explains part of the force.
  EXPECT_GE(lsqr.misfit.rms_residual, direct.misfit.rms_residual);
  EXPECT_LT(lsqr.misfit.rms_residual, lsqr.misfit.rms_target);
  std::cout << "[ lsqr     ] force misfit " << lsqr.misfit.rms_residual / lsqr.misfit.rms_target
            << " of the target (direct " << direct.misfit.rms_residual / direct.misfit.rms_target
            << "), max CGLS iterations " << lsqr.lsqr_max_iterations << "\n";
  EXPECT_EQ(reconstruction_method_from_name(reconstruction_method_name(ReconstructionMethod::lsqr)),
      ReconstructionMethod::lsqr);
  EXPECT_THROW(reconstruction_method_from_name("qr"), InputError);
}

// Timing for docs/learning.md (not part of the suite: run with --gtest_also_run_disabled_tests).
TEST(StressReconstruction, DISABLED_TimingLargeProblem) {
  const mesh::TetMesh mesh = mesh::make_box_bar(Vec3(0.5, 0.25, 0.2), { 10, 5, 4 });
  const ReconstructionMesh geometry(mesh, nominal_material());
  const fem::DofMap dofs(mesh.num_vertices(), left_face(mesh));
  const Frames frames = make_frames(mesh, 400, 5);
  KMeansOptions km;
  km.clusters = 50;
  StretchSampleOptions so;
  so.max_samples = 100000;
  const auto t0 = Clock::now();
  const RbfDesign design(
      kmeans(collect_stretches(geometry, frames.positions, so), km).centres, design_options(1e-9));
  const double kmeans_seconds = seconds_since(t0);
  const material::RbfCorrection n = design.correction(random_unknowns(design, 2, 2e3));
  std::vector<VecX> targets;
  for (int t = 0; t < 400; ++t)
    targets.push_back(correction_force(geometry, n, frames.positions[t], frames.velocities[t]));
  const std::clock_t cpu0 = std::clock(); // process CPU time: meaningful on a busy machine
  const StressReconstructionResult r = reconstruct_rbf_correction(
      geometry, dofs, design, frames.positions, frames.velocities, targets);
  const double cpu_seconds = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  std::cout << mesh.num_tets() << " tets, " << dofs.num_free() << " free dofs, 400 frames, "
            << design.num_unknowns() << " unknowns: k-means " << kmeans_seconds << " s, assembly "
            << r.assembly_seconds << " s, solve " << r.solve_seconds << " s, misfit "
            << r.misfit_seconds << " s (CPU time of all three " << cpu_seconds
            << " s), relative misfit " << r.misfit.rms_residual / r.misfit.rms_target << "\n";
  StressReconstructionOptions o;
  o.method = ReconstructionMethod::lsqr;
  o.frame_stride = 10;
  const StressReconstructionResult l = reconstruct_rbf_correction(
      geometry, dofs, design, frames.positions, frames.velocities, targets, o);
  std::cout << "lsqr, 40 frames: CGLS " << l.assembly_seconds << " s (max " << l.lsqr_max_iterations
            << " iterations), fit " << l.solve_seconds << " s, relative misfit "
            << l.misfit.rms_residual / l.misfit.rms_target << "\n";
}
