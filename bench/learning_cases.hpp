#pragma once
// The scenes of bench_learning (the learning benchmark of issue 3, paper 000's Table 1): for each
// case a training and a test motion with the nominal material, the ground-truth material and the
// observed fraction. Every case learns with the one default recipe (learn/learning_recipe.hpp):
// cases differ in what is observed, never in how it is learned. Set-up per case:
// docs/benchmarks_learning.md.
#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/learning_recipe.hpp>
#include <elastolearn/learn/parameter_fit.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/spline_edited.hpp>
#include <elastolearn/material/stretch_dependent_rayleigh.hpp>
#include <elastolearn/mesh/external_program.hpp>
#include <elastolearn/mesh/primitives.hpp>
#include <elastolearn/mesh/surface_mesh.hpp>
#include <elastolearn/mesh/tetrahedralize.hpp>
#include <elastolearn/mesh/vertex_selection.hpp>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace bench_learning {

using namespace elastolearn;
namespace fs = std::filesystem;

/// One row of the table: everything the runner needs.
struct LearningCase {
  std::string name;
  std::string mesh_label; ///< e.g. "bear.off → 1187 tets"
  std::string truth_label; ///< ground-truth material, short
  std::string nominal_label;
  std::string motion_label; ///< training / test motions
  sim::Scene train; ///< nominal material
  sim::Scene test; ///< nominal material, a different and larger motion
  fem::MaterialModel truth;
  double visible_fraction = 1.0;
  double target_err_l = 0; ///< issue 3's target [% of the rest bounding-box diagonal]
};

inline fem::MaterialModel make_material(material::ElasticModelType type, double young,
    double poisson, double alpha0, double alpha1, double density = 1000) {
  fem::MaterialModel m;
  m.elastic
      = material::make_elastic_model(type, material::Lame::from_young_poisson(young, poisson));
  m.damping = std::make_shared<material::RayleighDamping>(alpha0, alpha1);
  m.density = density;
  return m;
}

/// `data/meshes/<name>` of Debian's libcgal-demo data archive, extracted (once) under `dir`.
inline fs::path cgal_mesh(const fs::path& dir, const std::string& name) {
  const fs::path file = dir / "data" / "meshes" / name;
  if (fs::exists(file))
    return file;
  const fs::path archive = "/usr/share/doc/libcgal-demo/data.tar.gz";
  if (!fs::exists(archive))
    throw InputError(archive.string(), "missing: install Debian's libcgal-demo");
  fs::create_directories(dir);
  const auto result = mesh::run_program("/usr/bin/tar",
      { "xzf", archive.string(), "-C", dir.string(), "data/meshes/" + name }, dir / "tar.log");
  if (!result.ok() || !fs::exists(file))
    throw InputError(archive.string(), "could not extract " + name + ": " + result.output);
  return file;
}

/// A real surface, turned so that its axis `up` (0, 1, 2) becomes y (a cyclic permutation of the
/// coordinates, which keeps the orientation), moved to stand on y = 0 centred in x, z, scaled so
/// that its largest extent is `size` [m], and tetrahedralized to at most ~`tets` tets.
inline mesh::TetMesh real_mesh(
    const fs::path& file, int up, double size, int tets, bool fill_holes, std::string& label) {
  mesh::SurfaceMesh surface = mesh::read_surface_mesh(file);
  for (int k = 0; k < (up == 1 ? 0 : up == 0 ? 1 : 2); ++k) // (x, y, z) → (z, x, y): x becomes y
    for (Eigen::Index i = 0; i < surface.vertices.rows(); ++i)
      surface.vertices.row(i) = Eigen::RowVector3d(
          surface.vertices(i, 2), surface.vertices(i, 0), surface.vertices(i, 1));
  const Vec3 lo = surface.vertices.colwise().minCoeff(), hi = surface.vertices.colwise().maxCoeff();
  const double scale = size / (hi - lo).maxCoeff();
  const Vec3 anchor(0.5 * (lo.x() + hi.x()), lo.y(), 0.5 * (lo.z() + hi.z()));
  for (Eigen::Index i = 0; i < surface.vertices.rows(); ++i)
    surface.vertices.row(i) = (surface.vertices.row(i).transpose() - anchor).transpose() * scale;
  mesh::TetrahedralizeOptions options;
  options.max_tets = tets;
  options.fill_holes = fill_holes;
  mesh::TetrahedralizeReport report;
  mesh::TetMesh out = mesh::tetrahedralize(surface, options, &report, file.string());
  char quality[64];
  std::snprintf(quality, sizeof quality, ", dihedral angles %.1f–%.1f°",
      out.quality().min_dihedral_deg, out.quality().max_dihedral_deg);
  label = file.filename().string() + " (" + std::to_string(surface.faces.rows()) + " triangles"
      + (report.simplified ? ", simplified" : "") + ") → " + std::to_string(out.num_tets())
      + " tets" + quality;
  return out;
}

/// The vertices within `fraction` of the height above the lowest one (the base, held fixed).
inline std::vector<int> base_vertices(const mesh::TetMesh& mesh, double fraction) {
  const auto box = mesh.bounding_box();
  return mesh::vertices_with_min_coordinate(mesh, 1, fraction * (box.max().y() - box.min().y()));
}

inline sim::Scene base_scene(
    mesh::TetMesh mesh, const fem::MaterialModel& nominal, double dt, int frames) {
  sim::Scene s;
  s.mesh = std::move(mesh);
  s.material = nominal;
  s.dt = dt;
  s.frames = frames;
  s.gravity = Vec3(0, -9.81, 0);
  s.linear_solver = sim::LinearSolverType::ConjugateGradient;
  // Learned corrections' Jacobians omit some terms (fem/elastic_force.hpp), so Newton can need
  // more than the default 50 iterations in a step; a real divergence still fails.
  s.newton.max_iterations = 150;
  // Newton's automatic absolute tolerance (a round-off floor, ~1e-12 of the stiffness scale) is
  // below what steps with a learned RBF correction reach: measured, Newton stalls at residuals
  // of ~1e-5 N (turtle test motion, frame 2) where the floor asks for 2e-6 N. Accept 1e-6 of the
  // object's weight instead (1e-5–1e-4 N here), far below any force that moves it visibly.
  s.newton.absolute_tolerance = 1e-6 * nominal.density * s.mesh.total_volume() * 9.81;
  return s;
}

/// Turtle-like: Debian's bear.off standing on its fixed feet. Training: released from rest under
/// gravity (droop and rebound); test: gravity plus a sideways swing (initial angular velocity
/// about the base), a larger deformation.
inline LearningCase turtle(const fs::path& data, bool quick, double fraction) {
  LearningCase c;
  c.name = fraction >= 1 ? "turtle"
                         : "sparse-" + std::to_string(static_cast<int>(100 * fraction + 0.5));
  const double height = 0.3;
  auto mesh
      = real_mesh(cgal_mesh(data, "bear.off"), 1, height, quick ? 600 : 1200, false, c.mesh_label);
  c.truth = make_material(material::ElasticModelType::NeoHookean, 2e4, 0.43, 0, 0);
  const auto nominal = make_material(material::ElasticModelType::Corotated, 3.5e4, 0.43, 0, 0);
  c.train = base_scene(std::move(mesh), nominal, 4e-3, 200);
  c.train.fixed_vertices = base_vertices(c.train.mesh, 0.08);
  c.test = c.train;
  c.test.initial.kind = sim::InitialCondition::Kind::Velocity;
  c.test.initial.angular_velocity = Vec3(0, 0, 1.0);
  c.test.initial.center = Vec3::Zero();
  c.truth_label = "neo-Hookean E 2e4, ν 0.43";
  c.nominal_label = "corotated E 3.5e4, ν 0.43";
  c.motion_label
      = "train: droop from rest under gravity; test: gravity + swing ω_z = 1 rad/s about the base";
  c.visible_fraction = fraction;
  c.target_err_l = fraction >= 1 ? 1.0 : (fraction < 0.1 ? 1.5 : 1.0);
  return c;
}

/// Dragon: Debian's ChineseDragon-10kv.off (2 holes closed), base fixed, StVK truth.
inline LearningCase dragon(const fs::path& data, bool quick) {
  LearningCase c;
  c.name = "dragon";
  auto mesh = real_mesh(
      cgal_mesh(data, "ChineseDragon-10kv.off"), 0, 0.12, quick ? 1300 : 2800, true, c.mesh_label);
  c.truth = make_material(material::ElasticModelType::StVK, 1e5, 0.40, 0, 0);
  const auto nominal = make_material(material::ElasticModelType::Corotated, 1.2e5, 0.40, 0, 0);
  c.train = base_scene(std::move(mesh), nominal, 3e-3, 200);
  c.train.fixed_vertices = base_vertices(c.train.mesh, 0.08);
  c.test = c.train;
  c.test.initial.kind = sim::InitialCondition::Kind::Velocity;
  // Test swing: deforms more than the training droop (7.3 % vs 5.4 % of the diagonal) but keeps
  // the StVK truth's elements uninverted (smallest stretch 0.59). A faster swing, ω = (5, 0, 5),
  // inverts some (smallest stretch −0.62), a regime where StVK itself collapses: there even the
  // correction reconstructed from the *true* training trajectory diverges, while at (3, 0, 3) it
  // reaches 0.069 % (docs/benchmarks_learning.md).
  c.test.initial.angular_velocity = Vec3(3.0, 0, 3.0);
  c.truth_label = "StVK E 1e5, ν 0.40";
  c.nominal_label = "corotated E 1.2e5, ν 0.40";
  c.motion_label = "train: droop from rest under gravity; test: gravity + swing ω = (3, 0, 3) "
                   "rad/s about the base";
  c.target_err_l = 0.2;
  return c;
}

/// Sphere with its top cap keyframed up and down (sinusoid), its bottom cap fixed; the truth is a
/// spline-edited neo-Hookean (tension or compression edited), α₁ 0.2 as in paper 000 Table 1.
/// Radius 1.5 m: at 0.2 m the keyframes prescribe the shape and any stiffness gives nearly the
/// same motion (nominal test err_L 0.63 / 0.37 %, under the target without learning); at 1.5 m
/// gravity and inertia let the stiffness show (quick mesh: 3.73 / 2.25 %). At 2 m the
/// compression case learned nothing (its first correction overshot). docs/benchmarks_learning.md.
inline LearningCase sphere(bool compression, bool quick) {
  LearningCase c;
  c.name = compression ? "sphere-compression" : "sphere-tension";
  const double radius = 1.5;
  auto mesh = mesh::make_sphere(radius, quick ? 2000 : 12712);
  c.mesh_label = "ball r 1.5 m → " + std::to_string(mesh.num_tets()) + " tets";
  const auto lame = material::Lame::from_young_poisson(1e5, 0.43);
  auto spline = compression
      ? material::CubicSpline({ 0.7, 0.85, 1.0 }, { 0.3, 0.6, 1.0 }, "compression edit")
      : material::CubicSpline({ 1.0, 1.1, 1.25 }, { 1.0, 1.8, 3.0 }, "tension edit");
  c.truth.elastic = std::make_shared<material::SplineEditedModel>(
      material::ElasticModelType::NeoHookean, lame,
      compression ? material::SplineEditRegion::Compression : material::SplineEditRegion::Tension,
      spline);
  c.truth.damping = std::make_shared<material::RayleighDamping>(0.0, 0.2);
  c.truth.density = 1000;
  const auto nominal = make_material(material::ElasticModelType::Corotated, 1.2e5, 0.43, 0, 0.2);
  c.train = base_scene(std::move(mesh), nominal, 5e-3, 200);
  c.train.fixed_vertices = mesh::vertices_with_min_coordinate(c.train.mesh, 1, 0.15 * radius);
  sim::KeyframeMotion top;
  top.vertices = mesh::vertices_with_max_coordinate(c.train.mesh, 1, 0.15 * radius);
  top.kind = sim::KeyframeMotion::Kind::Sinusoid;
  c.test = c.train;
  top.amplitude = Vec3(0, 0.2 * radius, 0);
  top.frequency = 1.0;
  c.train.keyframes = { top };
  top.amplitude = Vec3(0, 0.3 * radius, 0);
  top.frequency = 1.25;
  c.test.keyframes = { top };
  c.truth_label = std::string("spline-edited neo-Hookean E 1e5, ν 0.43 (")
      + (compression ? "compression: s(0.7, 0.85, 1) = 0.3, 0.6, 1"
                     : "tension: s(1, 1.1, 1.25) = 1, 1.8, 3")
      + "), α₁ 0.2";
  c.nominal_label = "corotated E 1.2e5, ν 0.43, α₁ 0.2";
  c.motion_label
      = "top cap keyframed y = A sin 2πft; train A 0.2 r, f 1 Hz; test A 0.3 r, f 1.25 Hz";
  c.target_err_l = 2.0;
  return c;
}

/// Bar damping: a 0.4 × 0.1 × 0.1 m bar clamped at x = 0 (16×4×4 cells, 1536 tets), no gravity;
/// the truth's α₁ is a quadratic polynomial of the largest stretch σ₁ (paper §7.2.2: "a
/// polynomial function of principal stretch"), ≥ the nominal 0.2 s wherever σ₁ ≥ 1 (σ₁ < 1 needs
/// all three stretches compressed: the motions' σ₁ stays ≥ 0.996; docs/benchmarks_learning.md).
inline LearningCase bar_damping(int variant, bool quick) {
  LearningCase c;
  c.name = "bar-damping" + std::to_string(variant);
  auto mesh = mesh::make_box_bar(Vec3(0.4, 0.1, 0.1),
      quick ? std::array<int, 3> { 8, 2, 2 } : std::array<int, 3> { 16, 4, 4 });
  c.mesh_label = "box bar 0.4×0.1×0.1 m → " + std::to_string(mesh.num_tets()) + " tets";
  c.truth = make_material(material::ElasticModelType::Corotated, 4e4, 0.43, 0, 0.2);
  // The quadratics in σ₁ − 1 through (1, 0.2), (1.05, 0.3), (1.1, 0.5) and through (1, 0.2),
  // (1.03, 0.6), (1.08, 1.2) [s].
  const auto alpha1 = variant == 1 ? material::StretchPolynomial({ 0.2, 1.0, 20.0 })
                                   : material::StretchPolynomial({ 0.2, 83.0 / 6, -50.0 / 3 });
  c.truth.damping = std::make_shared<material::StretchDependentRayleigh>(
      material::CubicSpline({ 1.0 }, { 0.0 }), alpha1);
  const auto nominal = make_material(material::ElasticModelType::Corotated, 4e4, 0.43, 0, 0.2);
  c.train = base_scene(std::move(mesh), nominal, 5e-3, 300);
  c.train.gravity = Vec3::Zero();
  c.train.fixed_vertices = mesh::vertices_with_min_coordinate(c.train.mesh, 0, 1e-9);
  const auto tip = mesh::vertices_with_max_coordinate(c.train.mesh, 0, 1e-9);
  c.test = c.train;
  c.test.initial.kind = sim::InitialCondition::Kind::StaticLoad;
  c.test.initial.static_loads = { { tip, Vec3(0, -2.5, 0.8) } };
  // Trained from rest with a twisting and bending velocity about the bar's axis at the clamp, not
  // released from a load: released, the heavily damped bar creeps back with its velocity nearly
  // proportional to its displacement, and extra damping looks like an elastic softening; from
  // rest the displacement peaks while the velocity changes sign, which separates the two. The
  // twist strains the bar about twice as much per displacement as bending, so the training
  // reaches σ₁ ≈ 1.09–1.10 (the test: 1.12) within 15 % deformation; bending alone stays below
  // σ₁ ≈ 1.05 there, and beyond what it saw no learner knows the truth's curve
  // (docs/benchmarks_learning.md, "Reaching the test's stretches").
  // The more damped bar-damping2 needs the faster twist for the same stretches.
  c.train.initial.kind = sim::InitialCondition::Kind::Velocity;
  c.train.initial.angular_velocity = variant == 1 ? Vec3(30, 0, 0.8) : Vec3(70, 0, 0.6);
  c.train.initial.center = Vec3(0, 0.05, 0.05);
  c.truth_label = std::string("corotated E 4e4, ν 0.43, α₁(σ₁) the quadratic in σ₁ − 1 through ")
      + (variant == 1 ? "(1, 0.2) (1.05, 0.3) (1.1, 0.5)" : "(1, 0.2) (1.03, 0.6) (1.08, 1.2)");
  c.nominal_label = "corotated E 4e4, ν 0.43, α₁ 0.2";
  c.motion_label = std::string("no gravity; train: from rest with ω = ")
      + (variant == 1 ? "(30, 0, 0.8)" : "(70, 0, 0.6)")
      + " rad/s about the clamp; test: released from a static tip load (0, −2.5, 0.8) N";
  c.target_err_l = variant == 1 ? 0.1 : 0.4;
  return c;
}

} // namespace bench_learning
