// Physics-based tracking of point clouds (issue 20: "tracking 400 frames of ~20k points per frame
// on a ~1.2k-tet mesh: ≤ 60 s on 2 cores"). The cantilever of examples/01_cantilever (0.4 × 0.1 ×
// 0.1 m, 12 × 4 × 4 cells: 1152 tets; E = 300 kPa, ν = 0.4, Rayleigh damping 0.2 / 0.005, held
// up by a 40 N tip load and released, 400 steps of 1 ms) is the truth; one 640 × 480 depth
// camera (45° vertical field of view) looks at it from 0.9 m, 45° above its side, (~20k points per
// frame) with 1 mm depth noise. Tracking runs with the nominal material E 2× too stiff (600 kPa),
// the scene's CG solver, σ = 1 mm and the default options. Printed: wall time of the tracking alone
// (not the truth's simulation or the scan), per frame, and the error of the tracked and of the
// untracked nominal run against the truth (surface vertices; RMS over frames and vertices, and
// the largest), and the RMS cloud → surface distance.
//
//   bench_track [--frames N] [--distance D] [--weight λ] [--em-iterations K]
//
// A plain program (not Google Benchmark): one run takes tens of seconds. Measured numbers:
// docs/performance.md ("Tracking point clouds").
#include <elastolearn/capture/virtual_scanner.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/observe/cloud_tracking.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <support/bar_scene.hpp>

#include <tbb/info.h>

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace elastolearn;

namespace {

/// CPU time of the process so far, all threads [s].
double cpu_seconds() {
  rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec)
      + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

sim::Scene cantilever(double young, int frames) {
  sim::Scene scene = test::bar_scene({ .size = Vec3(0.4, 0.1, 0.1),
      .cells = { 12, 4, 4 },
      .young = young,
      .alpha0 = 0.2,
      .alpha1 = 0.005,
      .dt = 1e-3,
      .frames = frames });
  scene.initial.kind = sim::InitialCondition::Kind::StaticLoad;
  scene.initial.static_loads.push_back(
      { mesh::vertices_with_max_coordinate(scene.mesh, 0, 1e-9), Vec3(0, 40, 0) });
  scene.initial.load_steps = 4;
  scene.linear_solver = sim::LinearSolverType::ConjugateGradient;
  return scene;
}

capture::DepthCamera side_camera(double distance) {
  capture::DepthCamera c;
  c.name = "side";
  c.width = 640;
  c.height = 480;
  c.set_field_of_view(45);
  // From above the side, 45° up: it sees the top face (the bending moves it along its normal)
  // and the side face (which bending only slides in its plane: a side view alone hardly sees
  // the motion).
  c.position = Vec3(0.2, 0.05, 0.05) + distance * Vec3(0, std::sqrt(0.5), std::sqrt(0.5));
  c.look_at(Vec3(0.2, 0.05, 0.05), Vec3(0, 1, 0), "bench");
  return c;
}

/// (RMS, max) over frames and surface vertices of the distance between two runs.
std::pair<double, double> surface_error(
    const sim::Scene& scene, const std::vector<VecX>& a, const std::vector<VecX>& b) {
  double sum = 0, worst = 0;
  long count = 0;
  for (std::size_t t = 0; t < a.size(); ++t)
    for (int v : scene.mesh.surface_vertices()) {
      const double d = (a[t].segment<3>(3 * v) - b[t].segment<3>(3 * v)).norm();
      sum += d * d;
      worst = std::max(worst, d);
      ++count;
    }
  return { std::sqrt(sum / double(count)), worst };
}

} // namespace

int main(int argc, char** argv) {
  int frames = 400;
  double distance = 0.9, sigma = 1e-3;
  observe::TrackingOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--frames" && has_value)
      frames = std::atoi(argv[++i]);
    else if (arg == "--distance" && has_value)
      distance = std::atof(argv[++i]);
    else if (arg == "--weight" && has_value)
      options.weight = std::atof(argv[++i]);
    else if (arg == "--em-iterations" && has_value)
      options.em_iterations = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr,
          "usage: bench_track [--frames N] [--distance D] [--weight L] [--em-iterations K]\n");
      return 2;
    }
  }
  options.sigma = sigma;

  const sim::Scene truth = cantilever(3e5, frames);
  const sim::Scene nominal = cantilever(6e5, frames);
  const sim::ForwardRun truth_run = sim::simulate_positions(truth);
  const sim::ForwardRun nominal_run = sim::simulate_positions(nominal);
  if (!truth_run.completed || !nominal_run.completed) {
    std::fprintf(stderr, "simulation failed: %s %s\n", truth_run.message.c_str(),
        nominal_run.message.c_str());
    return 1;
  }

  capture::ScanOptions scan;
  scan.noise = sigma;
  scan.seed = 5;
  capture::VirtualScanner scanner(
      truth.mesh.surface_faces(), truth.mesh.num_vertices(), { side_camera(distance) }, scan);
  std::vector<capture::CloudFrame> cloud_frames;
  long long points = 0;
  for (std::size_t t = 0; t < truth_run.positions.size(); ++t) {
    const VecX& x = truth_run.positions[t];
    scanner.update(Eigen::Map<const Positions>(x.data(), x.size() / 3, 3));
    cloud_frames.push_back(scanner.scan(static_cast<long>(t)));
    points += cloud_frames.back().points.rows();
  }
  const auto clouds
      = capture::PointCloudSequence::from_frames(cloud_frames, truth.dt, 0, "bench clouds");
  cloud_frames.clear();

  std::vector<VecX> tracked;
  const double cpu_start = cpu_seconds();
  const auto report = observe::track_clouds(nominal, clouds, "bench clouds", options,
      [&](int, double, const VecX& x, const VecX&) { tracked.push_back(x); });
  const double cpu = cpu_seconds() - cpu_start;
  if (!report.completed) {
    std::fprintf(stderr, "tracking failed: %s\n", report.message.c_str());
    return 1;
  }

  for (const std::string& note : report.notes)
    std::printf("note: %s\n", note.c_str());
  long em = 0, newton = 0;
  double rms2 = 0;
  for (const auto& f : report.frames) {
    em += f.em_iterations;
    newton += f.newton_iterations;
    rms2 += f.rms_inliers * f.rms_inliers;
  }
  const int n = static_cast<int>(report.frames.size());
  const auto [tracked_rms, tracked_max] = surface_error(truth, tracked, truth_run.positions);
  const auto [nominal_rms, nominal_max]
      = surface_error(truth, nominal_run.positions, truth_run.positions);
  std::printf("mesh: %d tets, %d vertices (%zu on the surface); %d frames of dt = %g s\n",
      truth.mesh.num_tets(), truth.mesh.num_vertices(), truth.mesh.surface_vertices().size(), n,
      truth.dt);
  std::printf("clouds: %.0f points per frame on average (camera at %.2f m), σ = %g m\n",
      double(points) / n, distance, sigma);
  std::printf("threads: %d (oneTBB default concurrency)\n", tbb::info::default_concurrency());
  std::printf("tracking: %.2f s wall (%.2f s CPU, all threads), %.1f ms/frame; %.2f solves and "
              "%.1f Newton iterations per "
              "frame; σ used %g m, λ = %g, %d samples, %d levels\n",
      report.seconds, cpu, 1e3 * report.seconds / n, double(em) / n, double(newton) / n,
      report.sigma, options.weight, report.samples, report.levels);
  std::printf("surface vertices vs truth: tracked RMS %.3g m (max %.3g m); untracked nominal RMS "
              "%.3g m (max %.3g m)\n",
      tracked_rms, tracked_max, nominal_rms, nominal_max);
  std::printf("cloud → surface RMS over frames (points within %g σ): %.3g m (frame 0: %.3g m "
              "predicted, %.3g m tracked)\n",
      observe::k_inlier_distance, std::sqrt(rms2 / n), report.frames[0].rms_predicted,
      report.frames[0].rms_inliers);
  std::printf("frame   tracked RMS / max [mm]   nominal RMS / max [mm]   cloud → surface [mm]\n");
  for (int t = 0; t < n; t += std::max(1, n / 8)) {
    const std::vector<VecX> a { tracked[t] }, b { truth_run.positions[t] },
        c { nominal_run.positions[t] };
    const auto [tr, tm] = surface_error(truth, a, b);
    const auto [nr, nm] = surface_error(truth, c, b);
    std::printf("%5d   %8.2f / %6.2f        %8.2f / %6.2f        %8.2f\n", t, 1e3 * tr, 1e3 * tm,
        1e3 * nr, 1e3 * nm, 1e3 * report.frames[t].rms_inliers);
  }
  return 0;
}
