#include <elastolearn/observe/cloud_tracking.hpp>

#include <elastolearn/capture/cloud_index.hpp>
#include <elastolearn/capture/correspondence.hpp>
#include <elastolearn/capture/surface_distance.hpp>
#include <elastolearn/capture/surface_samples.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/observe/cloud_pull.hpp>
#include <elastolearn/sim/simulator.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

namespace elastolearn::observe {

namespace {

/// A constant force (full 3n) [N]: in frame 0's static fit, minus the net force of the scene's
/// initial state, so that the fit moves from that state only as far as the cloud pulls it.
class HoldingForce final : public fem::ForceTerm {
  public:
  VecX force;
  void add_force(const fem::ForceState&, VecX& f) override {
    if (force.size() == f.size())
      f += force;
  }
};

constexpr FieldErrors tracking_error("tracking");

/// Surface samples are spaced at most 3σ (a cloud point on the surface is then within
/// 3σ/√3 ≈ 1.7σ of a sample, well inside the 3.72σ reach of the default truncation) ...
constexpr double k_sample_spacing = 3;
/// ... with at most 16 lattice steps per edge (~150 samples per triangle); σ is floored so.
constexpr int k_max_subdivision = 16;
/// Coarse-to-fine levels σ·2^l, l < 7: a reach of 3.72·64 σ.
constexpr int k_max_levels = 7;

/// One σ of the coarse-to-fine schedule, with its samples and their pull.
struct Level {
  double sigma = 0;
  capture::SurfaceSamples samples;
  std::unique_ptr<CloudPull> pull;
  Positions positions; ///< sample positions (work buffer)
};

double face_area(ConstRef<Positions> x, const Faces& faces, Eigen::Index f) {
  const Vec3 a = x.row(faces(f, 0)).transpose();
  return 0.5
      * (x.row(faces(f, 1)).transpose() - a).cross(x.row(faces(f, 2)).transpose() - a).norm();
}

/// The q-quantile (0 ≤ q ≤ 1) of `values` (reordered).
double quantile(VecX& values, double q) {
  if (values.size() == 0)
    return 0;
  const auto k = static_cast<Eigen::Index>(q * double(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

} // namespace

double longitudinal_modulus(const fem::MaterialModel& material) {
  return material.elastic->principal_stress_derivative(Vec3::Ones())(0, 0);
}

void TrackingOptions::validate() const {
  if (!(sigma > 0) || !std::isfinite(sigma))
    tracking_error("sigma",
        "must be positive and finite (the scanner's accuracy in metres), got " + to_text(sigma));
  if (!(weight > 0) || !std::isfinite(weight))
    tracking_error("weight", "must be positive and finite, got " + to_text(weight));
  if (!(tangential_weight >= 0 && tangential_weight <= 1))
    tracking_error("tangential_weight", "must be in [0, 1], got " + to_text(tangential_weight));
  if (!(truncation > 0 && truncation < 1))
    tracking_error("truncation", "must be in (0, 1), got " + to_text(truncation));
  if (em_iterations < 1)
    tracking_error("em_iterations", "must be at least 1, got " + std::to_string(em_iterations));
  if (initial_em_iterations < 1)
    tracking_error("initial_em_iterations",
        "must be at least 1, got " + std::to_string(initial_em_iterations));
  if (!(em_tolerance >= 0) || !std::isfinite(em_tolerance))
    tracking_error("em_tolerance", "must be non-negative and finite, got " + to_text(em_tolerance));
}

double default_tracking_sigma(
    const capture::PointCloudSequence& clouds, double recorded_noise, const std::string& source) {
  if (recorded_noise > 0 && std::isfinite(recorded_noise))
    return recorded_noise;
  for (int t = 0; t < clouds.num_frames(); ++t)
    if (clouds.frame_size(t) >= 2) {
      const double spacing = capture::CloudIndex(clouds.frame_points(t)).median_spacing();
      if (spacing > 0)
        return 0.5 * spacing;
    }
  throw InputError(source,
      "records no scanner accuracy (noise_sigma) and has no frame with two distinct points to "
      "estimate σ from: give --sigma");
}

TrackingReport track_clouds(const sim::Scene& scene, const capture::PointCloudSequence& clouds,
    const std::string& clouds_source, const TrackingOptions& options, const sim::FrameSink& sink,
    const ProgressCallback& progress) {
  const auto start = Clock::now();
  options.validate();
  scene.validate();
  if (std::abs(clouds.dt - scene.dt) > 1e-6 * scene.dt)
    throw InputError(clouds_source + ": dt",
        to_text(clouds.dt) + " s between frames, but the scene's time step is " + to_text(scene.dt)
            + " s: tracking solves one step per frame");
  if (clouds.num_frames() != scene.frames + 1)
    throw InputError(clouds_source + ": /time",
        "has " + std::to_string(clouds.num_frames()) + " frames, but the scene simulates "
            + std::to_string(scene.frames) + " steps (" + std::to_string(scene.frames + 1)
            + " states): set the scene's time.frames to "
            + std::to_string(clouds.num_frames() - 1));

  TrackingReport report;
  HoldingForce holding; // before the simulator, which keeps a pointer to it
  sim::Simulator simulator(scene);
  const sim::NewtonReport initial = simulator.apply_initial_condition();
  if (!initial.converged) {
    report.message = "initial condition: " + initial.message;
    report.seconds = seconds_since(start);
    return report;
  }
  if (std::abs(simulator.time() - clouds.start_time) > 1e-6 * scene.dt)
    throw InputError(clouds_source + ": /time",
        "starts at " + to_text(clouds.start_time) + " s, but the scene starts at "
            + to_text(simulator.time()) + " s");

  const Faces& faces = scene.mesh.surface_faces();
  const Positions& rest = scene.mesh.rest_positions();
  const int n = scene.mesh.num_vertices();
  double longest = 0, edges = 0, area = 0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int j = 0; j < 3; ++j) {
      const double e = (rest.row(faces(f, j)) - rest.row(faces(f, (j + 1) % 3))).norm();
      longest = std::max(longest, e);
      edges += e;
    }
    area += face_area(rest, faces, f);
  }
  const double mean_edge = edges / double(3 * faces.rows());
  report.sigma = std::max(options.sigma, longest / (k_sample_spacing * k_max_subdivision));
  report.stiffness_per_area = options.weight * longitudinal_modulus(scene.material) / mean_edge;

  std::vector<Level> levels;
  for (int l = 0; l < k_max_levels; ++l) {
    Level level;
    level.sigma = report.sigma * std::ldexp(1.0, l);
    level.samples = capture::sample_surface(
        faces, capture::subdivision_for_spacing(rest, faces, k_sample_spacing * level.sigma));
    levels.push_back(std::move(level));
    if (levels.back().samples.num_samples()
        == static_cast<int>(scene.mesh.surface_vertices().size()))
      break; // vertices only: coarser levels would be the same samples
  }
  // The pulls point into `levels`, which no longer grows.
  for (Level& level : levels) {
    level.pull
        = std::make_unique<CloudPull>(level.samples, simulator.dofs(), simulator.system_matrix());
    simulator.add_force_term(level.pull.get());
  }
  // Frame 0: the initial state is whatever the scene says (at rest in its rest shape, held
  // against gravity; a static equilibrium; a velocity field), and the cloud may differ from it.
  // The fit solves f(x) − f(x₀) + pull(x) = 0: the forces that hold x₀ keep holding it, and the
  // mesh moves away from x₀ only as far as the cloud pulls it against its elasticity. (A plain
  // static solve would let a body released from its rest shape sag under gravity first.)
  simulator.add_force_term(&holding);
  holding.force = -simulator.total_force(
      simulator.positions(), VecX::Zero(simulator.positions().size()), simulator.time());
  report.samples = levels.front().samples.num_samples();
  report.levels = static_cast<int>(levels.size());
  const capture::SurfaceDistance distance(faces, n);

  const int T = clouds.num_frames();
  VecX x_start, v_start, guess, d;
  for (int t = 0; t < T; ++t) {
    TrackedFrame frame;
    const double t_start = simulator.time();
    x_start = simulator.positions();
    v_start = simulator.velocities();
    const bool dynamic = t > 0;
    const auto cloud = clouds.frame_points(t);
    frame.points = cloud.rows();
    const sim::NewtonReport* failed = nullptr;
    sim::NewtonReport solve;
    if (frame.points == 0) {
      if (dynamic) {
        solve = simulator.step();
        frame.newton_iterations = solve.iterations;
        if (!solve.converged)
          failed = &solve;
      }
    } else {
      guess = dynamic ? VecX(x_start + scene.dt * v_start) : x_start;
      const Eigen::Map<const Positions> predicted(guess.data(), n, 3);
      distance.distances(predicted, cloud, d);
      frame.rms_predicted = std::sqrt(d.squaredNorm() / double(d.size()));
      // Start at the finest σ ≥ half the 90th-percentile distance: its reach, 3.72σ, is then
      // ~1.9× the distance of all but the farthest tenth of the points (outliers among them).
      const double far = quantile(d, 0.9);
      int l = 0;
      while (l + 1 < static_cast<int>(levels.size()) && levels[l].sigma < 0.5 * far)
        ++l;
      const capture::CloudIndex index(cloud);
      int level_iterations = 0;
      bool have_converged = false;
      const int budget = dynamic ? options.em_iterations : options.initial_em_iterations;
      while (true) {
        Level& level = levels[l];
        const Eigen::Map<const Positions> x_guess(guess.data(), n, 3);
        level.samples.positions(x_guess, level.positions);
        capture::CorrespondenceOptions match;
        match.sigma = level.sigma;
        match.truncation = options.truncation;
        match.normalize_per_point = true;
        const auto pairs = capture::find_correspondences(index, level.positions, match);
        frame.pairs = static_cast<long>(pairs.size());
        if (!pairs.empty()) {
          // Observed area ≈ the share of samples with a partner; κ spreads λM/h over it.
          long active = 0;
          for (std::size_t i = 0; i < pairs.size(); ++i)
            active += (i == 0 || pairs[i].sample != pairs[i - 1].sample);
          const double observed = area * double(active) / level.samples.num_samples();
          // Coarser levels only acquire a far-off frame: they pull point to point.
          const double tangential = l == 0 ? options.tangential_weight : 1.0;
          level.pull->set_pairs(cloud, pairs,
              report.stiffness_per_area * observed / double(frame.points),
              tangential < 1 ? capture::sample_normals(level.samples, faces, x_guess) : Positions(),
              tangential);
        }
        simulator.set_state(x_start, v_start, t_start);
        solve = dynamic ? simulator.step() : simulator.solve_static(1);
        level.pull->clear();
        ++frame.em_iterations;
        frame.newton_iterations += solve.iterations;
        if (!solve.converged) {
          // Keep the last converged solve of this frame (for frame 0, at least the initial
          // state): a later frame's EM can still catch up. A frame with no such state fails.
          if (dynamic && !have_converged) {
            failed = &solve;
            break;
          }
          report.notes.push_back("frame " + std::to_string(t) + ": EM stopped after "
              + std::to_string(frame.em_iterations - 1) + " solves at σ = " + to_text(level.sigma)
              + " m, the next did not converge (" + solve.message
              + "); the frame keeps the last converged one");
          // Backward Euler: x₊ = x + h v₊, so the kept step's velocity is (x₊ − x) / h.
          if (dynamic)
            simulator.set_state(guess, (guess - x_start) / scene.dt, t_start + scene.dt);
          else
            simulator.set_state(guess, v_start, t_start);
          break;
        }
        have_converged = true;
        const VecX& x = simulator.positions();
        double moved = 0;
        for (int v = 0; v < n; ++v)
          moved = std::max(moved, (x.segment<3>(3 * v) - guess.segment<3>(3 * v)).norm());
        guess = x;
        // EM at this σ until the solve stays within em_tolerance·σ of where the pairs were
        // found (they would hardly change), or em_iterations; then the next finer σ.
        const bool settled = moved <= options.em_tolerance * level.sigma;
        if (settled || ++level_iterations >= budget) {
          if (l == 0)
            break;
          --l;
          level_iterations = 0;
        }
      }
      if (!dynamic && !failed) // the static fit keeps the initial condition's velocity
        simulator.set_state(simulator.positions(), v_start, t_start);
    }
    if (!dynamic)
      holding.force.resize(0); // the dynamic frames have the scene's own forces only
    if (failed) {
      report.message = "frame " + std::to_string(t)
          + " (t = " + to_text(t_start + (dynamic ? scene.dt : 0)) + " s): " + failed->message;
      break;
    }
    frame.time = simulator.time();
    if (frame.points > 0) {
      const VecX& x = simulator.positions();
      distance.distances(Eigen::Map<const Positions>(x.data(), n, 3), cloud, d);
      frame.rms = std::sqrt(d.squaredNorm() / double(d.size()));
      double inliers = 0;
      for (Eigen::Index i = 0; i < d.size(); ++i) {
        if (d[i] > k_inlier_distance * report.sigma)
          ++frame.outliers;
        else
          inliers += d[i] * d[i];
      }
      if (frame.outliers < frame.points)
        frame.rms_inliers = std::sqrt(inliers / double(frame.points - frame.outliers));
    }
    sink(t, frame.time, simulator.positions(), simulator.velocities());
    report.frames.push_back(frame);
    if (progress)
      progress(t + 1, T,
          "frame " + std::to_string(t) + ": rms " + to_text(frame.rms_inliers) + " m, "
              + std::to_string(frame.em_iterations) + " EM");
  }
  report.completed = report.message.empty();
  report.seconds = seconds_since(start);
  return report;
}

} // namespace elastolearn::observe
