// The virtual depth scanner and the point-cloud correspondence on the cantilever bar of
// examples/01_cantilever (0.4 × 0.1 × 0.1 m, 12 × 4 × 4 cells: 1152 tets, 448 surface
// triangles), bent as by its tip load. One 640 × 480 camera, 45° vertical field of view, looking
// at the bar's side: "side" from 0.8 m (the bar covers ~9 % of the pixels, as in a real capture
// with background), "close" from 0.3 m (it covers ~65 %). Counters: rays/s (pixels ray-cast),
// frames/s, points per frame. Run: ./build/bench/bench_scan [--benchmark_filter=...].
#include <elastolearn/capture/cloud_index.hpp>
#include <elastolearn/capture/correspondence.hpp>
#include <elastolearn/capture/virtual_scanner.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

using namespace elastolearn;
using namespace elastolearn::capture;

namespace {

struct BarCase {
  mesh::TetMesh bar = mesh::make_box_bar(Vec3(0.4, 0.1, 0.1), { 12, 4, 4 });
  /// The bar bent upward by up to 4 cm at the tip (a cubic, as a cantilever's static deflection).
  Positions bent(double amplitude) const {
    Positions x = bar.rest_positions();
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const double s = x(i, 0) / 0.4;
      x(i, 1) += amplitude * s * s * (3 - s) / 2;
    }
    return x;
  }
};

DepthCamera side_camera(double distance) {
  DepthCamera c;
  c.name = "side";
  c.width = 640;
  c.height = 480;
  c.set_field_of_view(45);
  c.position = Vec3(0.2, 0.05, 0.05 + distance);
  c.look_at(Vec3(0.2, 0.05, 0.05), Vec3(0, 1, 0), "bench");
  return c;
}

/// range(0): threads; range(1): camera distance [cm].
void BM_ScanFrame(benchmark::State& bench) {
  tbb::global_control threads(
      tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(bench.range(0)));
  const BarCase scene;
  ScanOptions options;
  options.noise = 1e-3;
  VirtualScanner scanner(scene.bar.surface_faces(), scene.bar.num_vertices(),
      { side_camera(0.01 * double(bench.range(1))) }, options);
  long frame = 0;
  Eigen::Index points = 0;
  for (auto _ : bench) {
    // A different shape each frame, so every frame refits the tree, as a real sequence does.
    scanner.update(scene.bent(0.04 * double(frame % 16) / 16));
    const CloudFrame cloud = scanner.scan(frame++);
    points = cloud.points.rows();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  bench.counters["rays/s"] = benchmark::Counter(
      double(scanner.num_pixels()) * double(bench.iterations()), benchmark::Counter::kIsRate);
  bench.counters["frames/s"]
      = benchmark::Counter(double(bench.iterations()), benchmark::Counter::kIsRate);
  bench.counters["points"] = double(points);
}

/// The tree refit alone (update() with new positions), per frame.
void BM_Refit(benchmark::State& bench) {
  const BarCase scene;
  VirtualScanner scanner(
      scene.bar.surface_faces(), scene.bar.num_vertices(), { side_camera(0.8) }, ScanOptions {});
  long frame = 0;
  const Positions a = scene.bent(0.0), b = scene.bent(0.04);
  for (auto _ : bench)
    scanner.update(frame++ % 2 ? a : b);
}

/// Correspondences (Eq. 9) of one scanned frame with the bar's surface: range(0) = subdivision
/// of the surface samples (1: vertices only), range(1) = threads. σ = 1 mm, truncation 1e-3.
void BM_Correspondence(benchmark::State& bench) {
  tbb::global_control threads(
      tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(bench.range(1)));
  const BarCase scene;
  ScanOptions options;
  options.noise = 1e-3;
  VirtualScanner scanner(
      scene.bar.surface_faces(), scene.bar.num_vertices(), { side_camera(0.3) }, options);
  scanner.update(scene.bent(0.02));
  const CloudFrame cloud = scanner.scan(0);
  const CloudIndex index(cloud.points);
  const SurfaceSamples samples
      = sample_surface(scene.bar.surface_faces(), static_cast<int>(bench.range(0)));
  const Positions s = samples.positions(scene.bent(0.021));
  CorrespondenceOptions correspondence;
  correspondence.sigma = 1e-3;
  std::size_t pairs = 0;
  for (auto _ : bench) {
    const auto found = find_correspondences(index, s, correspondence);
    pairs = found.size();
    benchmark::DoNotOptimize(found.data());
  }
  bench.counters["points"] = double(cloud.points.rows());
  bench.counters["samples"] = samples.num_samples();
  bench.counters["pairs"] = double(pairs);
}

/// The k-d tree build of one frame's cloud (once per frame).
void BM_CloudIndex(benchmark::State& bench) {
  const BarCase scene;
  VirtualScanner scanner(
      scene.bar.surface_faces(), scene.bar.num_vertices(), { side_camera(0.3) }, ScanOptions {});
  scanner.update(scene.bent(0.02));
  const CloudFrame cloud = scanner.scan(0);
  for (auto _ : bench) {
    const CloudIndex index(cloud.points);
    benchmark::DoNotOptimize(&index);
  }
  bench.counters["points"] = double(cloud.points.rows());
}

} // namespace

BENCHMARK(BM_ScanFrame)
    ->ArgsProduct({ { 1, 2 }, { 80, 30 } })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Refit)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Correspondence)
    ->ArgsProduct({ { 1, 4 }, { 1, 2 } })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CloudIndex)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
