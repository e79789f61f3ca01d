#pragma once
// The random cases of `bench_learning --random N --seed S` (issue 19, "a benchmark nobody can
// tune to"): each case draws a shape, a ground-truth material, a nominal guess, training and test
// motions, an observed fraction and a noise level, all from std::mt19937_64 streams seeded by
// (S, case index), so case I of seed S is the same whether it runs alone (--random-case I) or
// among others. The draw and its reasoning: docs/benchmarks_learning.md, "Random cases".
#include "learning_cases.hpp"

#include <elastolearn/sim/simulator.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace bench_learning {

/// Uniform draws from a std::mt19937_64 computed here, not by <random>'s distributions (whose
/// algorithms differ between standard libraries), so that a seed draws the same case everywhere.
class Draw {
  public:
  /// The stream of (seed, case index, stream number): independent streams for the object and
  /// for each attempt at its motions.
  Draw(std::uint64_t seed, int index, int stream) {
    std::seed_seq seq { static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
      static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(stream) };
    m_rng.seed(seq);
  }
  /// Uniform in [0, 1).
  double unit() { return static_cast<double>(m_rng() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  /// 0 .. n−1.
  int index(int n) { return static_cast<int>(unit() * n); }
  /// An index drawn with the given (non-negative) weights.
  template <std::size_t N> int weighted(const std::array<double, N>& weights) {
    double total = 0;
    for (double w : weights)
      total += w;
    double u = unit() * total;
    for (std::size_t i = 0; i < N; ++i)
      if ((u -= weights[i]) < 0)
        return static_cast<int>(i);
    return static_cast<int>(N - 1);
  }
  bool chance(double p) { return unit() < p; }
  /// Uniform on the unit sphere.
  Vec3 direction() {
    const double z = uniform(-1, 1), phi = uniform(0, 2 * std::numbers::pi);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  std::uint64_t bits() { return m_rng(); }

  private:
  std::mt19937_64 m_rng;
};

/// Real surfaces of libcgal-demo's data/meshes that TetGen meshes at min_tets–3000 tets (smallest
/// dihedral angle ≥ 2.6°, ≥ 14 base vertices held), with the axis that is up and whether holes
/// must be closed. Tried and left out: elephant, cow, dino and elk (self-intersecting faces make
/// TetGen abort at some sizes), camel (cannot reach 3000 tets; 1.4° slivers at 2500), mushroom
/// (open), bull (0.4° slivers at 500 tets).
struct RealSurface {
  const char* file;
  int up;
  bool fill_holes;
  int min_tets; ///< below it the base holds too few vertices or TetGen fails
};
inline constexpr std::array<RealSurface, 6> kRealSurfaces = { {
    { "bear.off", 1, false, 500 },
    { "ChineseDragon-10kv.off", 0, true, 500 },
    { "bunny00.off", 1, false, 500 },
    { "armadillo.off", 1, false, 700 },
    { "triceratops.off", 1, false, 1500 },
    { "pig.off", 1, true, 1800 },
} };

enum class RandomShape { Bar, Ball, Real };
enum class RandomTruth {
  NeoHookean,
  StVK,
  SplineTension,
  SplineCompression,
  StretchDamping, ///< corotated with α₁ a function of the largest stretch
  Corotated, ///< corotated with constant Rayleigh damping: the nominal's family
};
enum class RandomMotion { Droop, Swing, Keyframed, ReleasedLoad };

inline const char* to_string(RandomMotion m) {
  switch (m) {
  case RandomMotion::Droop:
    return "droop";
  case RandomMotion::Swing:
    return "swing";
  case RandomMotion::Keyframed:
    return "keyframed";
  case RandomMotion::ReleasedLoad:
    return "released load";
  }
  return "?";
}

/// An object drawn with its truth and nominal materials, observation set-up and time step; the
/// motions come separately (draw_random_motions), redrawn if the truth cannot follow them.
struct RandomObject {
  std::uint64_t seed = 0;
  int index = 0;
  std::string shape_label, truth_label, nominal_label, setup_label;
  mesh::TetMesh mesh;
  std::vector<int> fixed; ///< held at rest
  std::vector<int> cap; ///< keyframed or loaded by the motions (the free end / the top)
  Vec3 swing_center = Vec3::Zero(); ///< the base, where swings turn about
  Vec3 out = Vec3::UnitY(); ///< from the base outwards (swings turn about an axis ⊥ to it)
  fem::MaterialModel truth, nominal;
  learn::NominalParameters nominal_parameters;
  bool truth_in_family = false; ///< corotated truth with constant Rayleigh damping
  double visible_fraction = 1;
  double noise_percent = 0; ///< σ of the observation noise, % of the rest bounding-box diagonal
  std::uint64_t observation_seed = 0;
  double dt = 0;
  int frames = 0;
  // What the calibration measured (nominal material, static equilibrium under gravity):
  double diagonal = 0; ///< rest bounding-box diagonal [m]
  double droop = 0; ///< largest static displacement [m]
  double omega = 0; ///< Rayleigh-quotient estimate of the lowest angular frequency [rad/s]
  double weight = 0; ///< [N]
};

/// Training and test scenes (nominal material) of one attempt.
struct RandomMotions {
  sim::Scene train, test;
  std::string train_label, test_label;
};

namespace detail {

inline std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

inline std::string vec(const Vec3& v) {
  return format("(%.3g, %.3g, %.3g)", v.x(), v.y(), v.z());
}

/// The nominal's largest static displacement under gravity and the Rayleigh quotient of that
/// shape, ω² = gᵀM u / uᵀM u (exact for the lowest mode when u is its shape; above ω₁
/// otherwise), at Young's modulus `young`.
inline void calibrate(RandomObject& o, double young, double& droop, double& omega) {
  sim::Scene s = base_scene(o.mesh,
      make_material(
          material::ElasticModelType::Corotated, young, o.nominal_parameters.poisson, 0, 0),
      1e-3, 1);
  s.fixed_vertices = o.fixed;
  s.initial.kind = sim::InitialCondition::Kind::StaticLoad;
  sim::Simulator simulator(s);
  const auto report = simulator.apply_initial_condition();
  if (!report.converged)
    throw InputError("random case", "the calibration's static solve did not converge");
  const VecX u = simulator.positions() - flatten(o.mesh.rest_positions());
  const VecX& m = simulator.dof_masses();
  double work = 0, inertia = 0;
  droop = 0;
  for (Eigen::Index v = 0; v < u.size() / 3; ++v) {
    work += m(3 * v + 1) * 9.81 * -u(3 * v + 1);
    inertia += m(3 * v) * u.segment<3>(3 * v).squaredNorm();
    droop = std::max(droop, u.segment<3>(3 * v).norm());
  }
  omega = std::sqrt(work / inertia);
  o.weight = m.sum() / 3 * 9.81;
}

/// The cap load along `direction` whose static displacement (nominal, no gravity) is
/// `amplitude` at its largest: a first guess (a tip load deflects a cantilever as far as its
/// weight would at 8/3 of it: 3/8 · weight · amplitude / droop), rescaled by one static solve,
/// the response being nearly linear at a few % of the size. A compact object rocking on a small
/// base moves much more under a sideways cap load than its droop says (seed 2's ball: 22 % of
/// the diagonal instead of ~8 % with the guess alone).
inline Vec3 cap_load(const RandomObject& o, double amplitude, const Vec3& direction) {
  double guess = 0.375 * o.weight * amplitude / o.droop;
  for (int tries = 0; tries < 4; ++tries, guess /= 4) {
    sim::Scene s = base_scene(o.mesh, o.nominal, 1e-3, 1);
    s.fixed_vertices = o.fixed;
    s.gravity = Vec3::Zero();
    s.initial.kind = sim::InitialCondition::Kind::StaticLoad;
    s.initial.static_loads = { { o.cap, guess * direction } };
    sim::Simulator simulator(s);
    if (!simulator.apply_initial_condition().converged)
      continue; // too large to be linear: a quarter of it
    const VecX u = simulator.positions() - flatten(o.mesh.rest_positions());
    double largest = 0;
    for (Eigen::Index v = 0; v < u.size() / 3; ++v)
      largest = std::max(largest, u.segment<3>(3 * v).norm());
    if (largest > 0)
      return guess * amplitude / largest * direction;
  }
  return guess * direction;
}

} // namespace detail

/// Draw case `index` of `seed` (shape, materials, observation, time step); meshes from `data`
/// (cgal_mesh). Runs TetGen for real surfaces and one static solve (the calibration).
inline RandomObject draw_random_object(std::uint64_t seed, int index, const fs::path& data) {
  using detail::format;
  Draw d(seed, index, 0);
  RandomObject o;
  o.seed = seed;
  o.index = index;
  const double size = d.uniform(0.1, 1.0); // largest extent [m]
  const int tets = static_cast<int>(d.log_uniform(500, 3000));

  // Shape.
  const auto shape = static_cast<RandomShape>(d.weighted(std::array { 1.0, 1.0, 2.0 }));
  if (shape == RandomShape::Bar) {
    const double aspect = d.log_uniform(3, 8), section = d.uniform(0.7, 1.4);
    const Vec3 dims(size, size / aspect, size / aspect * section);
    const double cell = std::cbrt(6 * dims.prod() / tets);
    const std::array<int, 3> cells { std::max(4, static_cast<int>(std::lround(dims.x() / cell))),
      std::max(2, static_cast<int>(std::lround(dims.y() / cell))),
      std::max(2, static_cast<int>(std::lround(dims.z() / cell))) };
    o.mesh = mesh::make_box_bar(dims, cells);
    o.fixed = mesh::vertices_with_min_coordinate(o.mesh, 0, 1e-9);
    o.cap = mesh::vertices_with_max_coordinate(o.mesh, 0, 1e-9);
    o.swing_center = Vec3(0, dims.y() / 2, dims.z() / 2);
    o.out = Vec3::UnitX();
    o.shape_label = format("box bar %.3g×%.3g×%.3g m", dims.x(), dims.y(), dims.z()) + " ("
        + std::to_string(cells[0]) + "×" + std::to_string(cells[1]) + "×" + std::to_string(cells[2])
        + " cells)" + " clamped at x = 0, free end = the cap";
  } else if (shape == RandomShape::Ball) {
    const double r = size / 2;
    o.mesh = mesh::make_sphere(r, tets);
    o.fixed = mesh::vertices_with_min_coordinate(o.mesh, 1, 0.15 * r);
    o.cap = mesh::vertices_with_max_coordinate(o.mesh, 1, 0.15 * r);
    o.swing_center = Vec3(0, -r, 0);
    o.shape_label = format("ball r %.3g m, bottom cap (0.15 r) fixed, top cap = the cap", r);
  } else {
    const RealSurface& s
        = kRealSurfaces[static_cast<std::size_t>(d.index(static_cast<int>(kRealSurfaces.size())))];
    std::string label;
    o.mesh = real_mesh(
        cgal_mesh(data, s.file), s.up, size, std::max(tets, s.min_tets), s.fill_holes, label);
    o.fixed = base_vertices(o.mesh, 0.08);
    const auto box = o.mesh.bounding_box();
    o.cap = mesh::vertices_with_max_coordinate(o.mesh, 1, 0.1 * (box.max().y() - box.min().y()));
    o.swing_center = Vec3::Zero(); // real_mesh stands it on y = 0, centred in x and z
    o.shape_label = label + format(", %.3g m, lowest 8 %% fixed, top 10 %% = the cap", size);
  }
  o.shape_label += " → " + std::to_string(o.mesh.num_tets()) + " tets, "
      + std::to_string(o.mesh.num_vertices()) + " vertices";
  o.diagonal = o.mesh.bounding_box_diagonal();

  // Materials. The nominal's E puts its static droop under gravity at `droop` of the diagonal;
  // the truth's stiffness is the nominal's times a ratio in [0.5, 2].
  const double droop_target = d.log_uniform(0.01, 0.03);
  const double ratio = d.log_uniform(0.5, 2);
  const double nu_truth = d.uniform(0.3, 0.45), nu_nominal = d.uniform(0.3, 0.45);
  o.nominal_parameters.poisson = nu_nominal;
  const double young_ref = 1e4 * 1000 * 9.81 * size; // strain ρgL/E = 10⁻⁴: linear
  double droop_ref = 0, omega_ref = 0;
  detail::calibrate(o, young_ref, droop_ref, omega_ref);
  const double young = young_ref * droop_ref / (droop_target * o.diagonal);
  o.droop = droop_target * o.diagonal;
  o.omega = omega_ref * std::sqrt(young / young_ref);
  const double young_truth = ratio * young;
  // Damping: α₁ = 2ζ₁/ω, α₀ = 2ζ₀ω (damping ratios ζ of the lowest mode), each zero or small;
  // the nominal guesses each nonzero one within a factor of 2.
  const double alpha1 = d.chance(1.0 / 3) ? 0 : 2 * d.log_uniform(0.005, 0.05) / o.omega;
  const double alpha0 = d.chance(0.5) ? 0 : 2 * d.log_uniform(0.005, 0.03) * o.omega;
  o.nominal_parameters
      = { young, nu_nominal, alpha0 * d.log_uniform(0.5, 2), alpha1 * d.log_uniform(0.5, 2) };
  o.nominal = make_material(material::ElasticModelType::Corotated, young, nu_nominal,
      o.nominal_parameters.alpha0, o.nominal_parameters.alpha1);
  o.nominal_label = format("corotated E %.4g Pa, ν %.3f, α₀ %.3g /s, α₁ %.3g s", young, nu_nominal,
      o.nominal_parameters.alpha0, o.nominal_parameters.alpha1);

  const auto truth
      = static_cast<RandomTruth>(d.weighted(std::array { 2.0, 2.0, 1.0, 1.0, 2.0, 1.0 }));
  const auto lame = material::Lame::from_young_poisson(young_truth, nu_truth);
  o.truth
      = make_material(material::ElasticModelType::Corotated, young_truth, nu_truth, alpha0, alpha1);
  const std::string common
      = format(" E %.4g Pa (%.3g × nominal), ν %.3f", young_truth, ratio, nu_truth);
  const std::string damping = format(", α₀ %.3g /s, α₁ %.3g s", alpha0, alpha1);
  switch (truth) {
  case RandomTruth::NeoHookean:
  case RandomTruth::StVK:
    o.truth.elastic = material::make_elastic_model(truth == RandomTruth::StVK
            ? material::ElasticModelType::StVK
            : material::ElasticModelType::NeoHookean,
        lame);
    o.truth_label = (truth == RandomTruth::StVK ? "StVK" : "neo-Hookean") + common + damping;
    break;
  case RandomTruth::SplineTension:
  case RandomTruth::SplineCompression: {
    // Knots at the strains the motions reach (a few %); the edit stiffens by a factor v per
    // knot. Knots 1–4 % apart were too sharp for the truth's Newton (seed 1's case 1: a
    // compression edit s(0.966, 0.986) = 0.37, 0.61 failed the first step of a keyframed cap).
    const bool tension = truth == RandomTruth::SplineTension;
    const bool neo = d.chance(0.5);
    const double s = d.log_uniform(0.02, 0.06), v = d.uniform(1.5, 2.5);
    // For the neo-Hookean base in compression, s < 1 stiffens (f′ = μσ > 0, see
    // SplineEditedModel); everywhere else s > 1 does.
    const double k = tension || !neo ? v : 1 / v;
    auto spline = tension ? material::CubicSpline({ 1.0, 1 + s, 1 + 2.5 * s }, { 1.0, k, k * k })
                          : material::CubicSpline({ 1 - 2.5 * s, 1 - s, 1.0 }, { k * k, k, 1.0 });
    o.truth.elastic = std::make_shared<material::SplineEditedModel>(
        neo ? material::ElasticModelType::NeoHookean : material::ElasticModelType::Corotated, lame,
        tension ? material::SplineEditRegion::Tension : material::SplineEditRegion::Compression,
        spline);
    o.truth_label = std::string("spline-edited ") + (neo ? "neo-Hookean" : "corotated") + common
        + (tension ? format(
               ", tension edit s(1, %.3f, %.3f) = 1, %.3g, %.3g", 1 + s, 1 + 2.5 * s, k, k * k)
                   : format(", compression edit s(%.3f, %.3f, 1) = %.3g, %.3g, 1", 1 - 2.5 * s,
                       1 - s, k * k, k))
        + damping;
    break;
  }
  case RandomTruth::StretchDamping: {
    // α₁(σ₁) = a + c (σ₁ − 1)², rising k-fold from its rest value a by σ₁ = 1.03.
    const double a = alpha1 > 0 ? alpha1 : 2 * d.log_uniform(0.005, 0.05) / o.omega;
    const double k = d.uniform(3, 10), c = (k - 1) * a / (0.03 * 0.03);
    o.truth.damping = std::make_shared<material::StretchDependentRayleigh>(
        material::StretchCurve::constant(alpha0), material::StretchPolynomial({ a, 0.0, c }));
    o.truth_label = "corotated" + common
        + format(
            ", α₀ %.3g /s, α₁(σ₁) = %.3g + %.4g (σ₁ − 1)² s (×%.2g at σ₁ = 1.03)", alpha0, a, c, k);
    break;
  }
  case RandomTruth::Corotated:
    o.truth_in_family = true;
    o.truth_label = "corotated" + common + damping + " (the nominal's family)";
    break;
  }

  // Observation and time step.
  const std::array fractions { 1.0, 0.13, 0.06 };
  const std::array noises { 0.0, 0.1, 0.5 };
  o.visible_fraction = fractions[static_cast<std::size_t>(d.index(3))];
  o.noise_percent = noises[static_cast<std::size_t>(d.index(3))];
  o.observation_seed = d.bits();
  o.frames = 100 + d.index(101);
  const double periods = d.uniform(1.5, 3); // of the lowest mode over the motion
  o.dt = periods * 2 * std::numbers::pi / o.omega / o.frames;
  o.setup_label = format("observed %.0f %% of the surface vertices, noise σ %.1f %% of the "
                         "diagonal; dt %.3g ms, ",
                      100 * o.visible_fraction, o.noise_percent, 1e3 * o.dt)
      + std::to_string(o.frames)
      + format(" frames (%.2g lowest periods, ω ≈ %.3g rad/s); nominal droop %.2g %% of the "
               "diagonal %.3g m",
          periods, o.omega, 100 * droop_target, o.diagonal);
  return o;
}

/// Training and test motions of `o`, attempt `attempt` (0, 1, ...): each attempt draws from its
/// own stream, with the amplitudes times `scale` (the caller makes a redraw gentler after the
/// truth failed a motion). Amplitudes are fractions a of the diagonal D: a swing's initial angular
/// velocity (about an axis across the object) moves the fastest vertex at a·D·ω; a keyframed cap
/// moves a·D at 0.5–1.5 ω; a released cap load deflects the nominal a·D statically
/// (detail::cap_load). The test motion is 1.3–2× the training's
/// amplitude, of the same kind or another; gravity acts in every motion, so a droop is never the
/// larger test of itself.
inline RandomMotions draw_random_motions(const RandomObject& o, int attempt, double scale = 1) {
  using detail::format;
  Draw d(o.seed, o.index, 1 + attempt);
  sim::Scene base = base_scene(o.mesh, o.nominal, o.dt, o.frames);
  base.fixed_vertices = o.fixed;

  auto make = [&](RandomMotion kind, double a, std::string& label) {
    sim::Scene s = base;
    const double amplitude = a * o.diagonal;
    switch (kind) {
    case RandomMotion::Droop:
      label = "droop from rest under gravity";
      break;
    case RandomMotion::Swing: {
      // About an axis across the object (a bending swing, not a twist about its own axis).
      Vec3 axis = d.direction();
      axis = (axis - axis.dot(o.out) * o.out).normalized();
      double fastest = 0; // at unit angular velocity
      const auto& rest = o.mesh.rest_positions();
      for (Eigen::Index v = 0; v < rest.rows(); ++v)
        fastest = std::max(fastest, axis.cross(rest.row(v).transpose() - o.swing_center).norm());
      s.initial.kind = sim::InitialCondition::Kind::Velocity;
      s.initial.angular_velocity = axis * (amplitude * o.omega / fastest);
      s.initial.center = o.swing_center;
      label = "swing ω = " + detail::vec(s.initial.angular_velocity) + " rad/s about "
          + detail::vec(o.swing_center) + format(" (a %.2g %%)", 100 * a);
      break;
    }
    case RandomMotion::Keyframed: {
      sim::KeyframeMotion cap;
      cap.vertices = o.cap;
      cap.kind = sim::KeyframeMotion::Kind::Sinusoid;
      cap.amplitude = amplitude * d.direction();
      // Held at its cap the object is stiffer than the free one ω describes (a clamped–pinned
      // beam's lowest mode is ~4× the cantilever's): 0.5–1.5 ω stays below that resonance and
      // above the quasi-static regime where the keyframes prescribe the shape whatever the
      // material (seed 1's case 1 at 0.3–0.8 ω: the nominal fitted the training to the noise).
      cap.frequency = d.uniform(0.5, 1.5) * o.omega / (2 * std::numbers::pi);
      s.keyframes = { cap };
      label = "cap keyframed A sin 2πft, A = " + detail::vec(cap.amplitude)
          + format(" m, f %.3g Hz (a %.2g %%)", cap.frequency, 100 * a);
      break;
    }
    case RandomMotion::ReleasedLoad: {
      const Vec3 force = detail::cap_load(o, amplitude, d.direction());
      s.initial.kind = sim::InitialCondition::Kind::StaticLoad;
      s.initial.static_loads = { { o.cap, force } };
      label = "released from a static cap load " + detail::vec(force)
          + format(" N (a %.2g %%)", 100 * a);
      break;
    }
    }
    return s;
  };

  RandomMotions m;
  const auto train_kind = static_cast<RandomMotion>(d.index(4));
  const double a_train = scale * d.log_uniform(0.02, 0.05);
  const double growth = d.uniform(1.3, 2);
  // The test: the training's kind (unless a droop) or another, never a droop (gravity acts in
  // every motion: a droop test would be the smallest motion of all).
  auto test_kind = train_kind;
  if (train_kind == RandomMotion::Droop || d.chance(0.5))
    do
      test_kind = static_cast<RandomMotion>(1 + d.index(3));
    while (test_kind == train_kind);
  m.train = make(train_kind, a_train, m.train_label);
  m.test = make(test_kind, growth * a_train, m.test_label);
  if (train_kind != RandomMotion::Droop)
    m.test_label += format(" (%.2g × the training's a)", growth);
  return m;
}

} // namespace bench_learning
