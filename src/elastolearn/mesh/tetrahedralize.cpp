#include <elastolearn/mesh/tetrahedralize.hpp>

#include <elastolearn/config.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/mesh/external_program.hpp>
#include <elastolearn/mesh/surface_repair.hpp>
#include <elastolearn/mesh/surface_simplification.hpp>
#include <elastolearn/mesh/tetgen_io.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <regex>
#include <unistd.h>

namespace elastolearn::mesh {

namespace {

/// TetGen at quality bound ~1.5 makes roughly this many tets per surface triangle when the
/// surface, not the volume bound, limits the size (measured: elephant 7.8, bear 6.8).
constexpr double kTetsPerSurfaceFace = 7.0;

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// Runs TetGen in one private directory; each call meshes one surface with one volume bound.
class TetgenRunner {
  public:
  TetgenRunner(
      const TetrahedralizeOptions& options, TetrahedralizeReport& report, std::string source)
      : m_options(options)
      , m_report(report)
      , m_source(std::move(source)) { }

  /// The mesh, or nullopt if TetGen failed (the reason is kept for error messages).
  std::optional<TetMesh> run(
      const SurfaceMesh& surface, double max_volume, bool preserve_surface = false) {
    const std::string stem = "s" + std::to_string(m_count++);
    const auto off = m_dir.path() / (stem + ".off");
    write_off(off, surface);
    std::string switches = "-pq" + short_number(m_options.min_radius_edge_ratio);
    if (m_options.min_dihedral_deg > 0)
      switches += "/" + short_number(m_options.min_dihedral_deg);
    if (max_volume > 0)
      switches += "a" + short_number(max_volume);
    if (preserve_surface)
      switches += "Y";
    switches += m_options.verbose ? "zV" : "zQ";
    const auto start = Clock::now();
    const ProgramResult result
        = run_program(m_report.tetgen, { switches, off.string() }, m_dir.path() / (stem + ".log"));
    TetgenRun record { switches, max_volume, static_cast<int>(surface.faces.rows()), 0,
      seconds_since(start) };
    if (m_options.verbose)
      std::fprintf(stderr, "%s", result.output.c_str());
    std::optional<TetMesh> mesh;
    if (result.ok() && std::filesystem::exists(m_dir.path() / (stem + ".1.ele"))) {
      mesh = read_tetgen(m_dir.path() / (stem + ".1"));
      record.num_tets = mesh->num_tets();
    } else {
      m_failure = result.signal ? "TetGen was killed by signal " + std::to_string(result.signal)
                                : "TetGen exited with code " + std::to_string(result.exit_code);
      m_failed_surface = surface;
    }
    m_report.runs.push_back(record);
    return mesh;
  }

  /// Like run(), retrying with `-Y` (no Steiner points on the surface) when TetGen fails.
  std::optional<TetMesh> run_with_fallback(const SurfaceMesh& surface, double max_volume) {
    if (auto m = run(surface, max_volume))
      return m;
    return run(surface, max_volume, /*preserve_surface=*/true);
  }

  /// Throws the error for the last failure, diagnosing self-intersections with `tetgen -d` (not
  /// quiet: -Q would hide the count).
  [[noreturn]] void fail() {
    std::string message = m_failure;
    const auto off = m_dir.path() / "check.off";
    write_off(off, m_failed_surface);
    const ProgramResult check
        = run_program(m_report.tetgen, { "-pdz", off.string() }, m_dir.path() / "check.log");
    std::smatch match;
    if (std::regex_search(
            check.output, match, std::regex(R"(Found (\d+) pairs of faces are intersecting)")))
      message += "; the surface has " + match[1].str()
          + " pairs of intersecting faces (TetGen -d): repair the self-intersections and retry";
    else if (check.output.find("No faces are intersecting") != std::string::npos)
      message += "; TetGen -d finds no intersecting faces — try a looser quality bound (--quality)";
    throw InputError(m_source, message);
  }

  private:
  const TetrahedralizeOptions& m_options;
  TetrahedralizeReport& m_report;
  std::string m_source;
  TemporaryDirectory m_dir { "elastolearn-tetgen" };
  int m_count = 0;
  std::string m_failure;
  SurfaceMesh m_failed_surface;
};

/// Meshes `surface` near `target` tets (≤ 1.1·target), adjusting the -a bound: tets ∝ a^slope with
/// the slope estimated from the last two runs (clamped), starting from -1.
std::optional<TetMesh> mesh_near_target(TetgenRunner& runner, const SurfaceMesh& surface,
    double volume, int target, double user_max_volume, int iterations, double& chosen_volume) {
  const double limit = 1.1 * target;
  std::optional<TetMesh> best;
  const auto better = [&](int count) {
    if (count > limit)
      return false;
    return !best || std::abs(count - target) < std::abs(best->num_tets() - target);
  };
  const double cap
      = user_max_volume > 0 ? user_max_volume : std::numeric_limits<double>::infinity();
  double a = std::min(cap, 2.5 * volume / target);
  double prev_a = 0, prev_count = 0;
  for (int it = 0; it < iterations; ++it) {
    auto mesh = runner.run_with_fallback(surface, a);
    if (!mesh)
      return best;
    const int count = mesh->num_tets();
    if (better(count)) {
      best = std::move(mesh);
      chosen_volume = a;
    }
    if (count >= 0.9 * target && count <= 1.03 * target)
      break;
    if (count < target && a >= cap)
      break; // cannot coarsen past the user's bound
    double slope = -1.0;
    if (prev_a > 0 && prev_a != a && prev_count != count)
      slope = std::clamp(std::log(count / prev_count) / std::log(a / prev_a), -1.5, -0.3);
    prev_a = a;
    prev_count = count;
    a = std::min(cap, a * std::pow(0.97 * target / count, 1.0 / slope));
  }
  return best;
}

} // namespace

void TetrahedralizeOptions::validate() const {
  if (max_tets < 0)
    throw InputError("max_tets", "must be >= 0, got " + std::to_string(max_tets));
  if (!(std::isfinite(max_volume) && max_volume >= 0))
    throw InputError("max_volume", "must be >= 0, got " + std::to_string(max_volume));
  if (!(std::isfinite(min_radius_edge_ratio) && min_radius_edge_ratio >= 1.0))
    throw InputError(
        "min_radius_edge_ratio", "must be >= 1.0, got " + std::to_string(min_radius_edge_ratio));
  if (!(min_dihedral_deg >= 0 && min_dihedral_deg < 70))
    throw InputError(
        "min_dihedral_deg", "must be in [0, 70), got " + std::to_string(min_dihedral_deg));
  if (max_iterations < 1)
    throw InputError("max_iterations", "must be >= 1, got " + std::to_string(max_iterations));
}

std::string tetgen_executable(const TetrahedralizeOptions& options) {
  if (!options.tetgen_executable.empty())
    return options.tetgen_executable;
  if (const char* env = std::getenv("ELASTOLEARN_TETGEN"); env && *env)
    return env;
  return ELASTOLEARN_TETGEN_EXECUTABLE;
}

bool tetgen_available(const TetrahedralizeOptions& options) {
  const std::string exe = tetgen_executable(options);
  return !exe.empty() && exe.find("NOTFOUND") == std::string::npos
      && ::access(exe.c_str(), X_OK) == 0;
}

TetMesh tetrahedralize(const SurfaceMesh& surface_in, const TetrahedralizeOptions& options,
    TetrahedralizeReport* report_out, const std::string& source) {
  const auto start = Clock::now();
  options.validate();
  int holes_filled = 0;
  const SurfaceMesh surface = remove_unreferenced_vertices(
      options.fill_holes && !is_closed(surface_in) ? fill_holes(surface_in, &holes_filled)
                                                   : surface_in);
  if (!is_closed(surface)) {
    const EdgeDefects d = edge_defects(surface);
    throw InputError(source,
        "surface is not closed: " + std::to_string(d.boundary_edges)
            + " edges belong to one face (holes) and " + std::to_string(d.non_manifold_edges)
            + " to more than two; TetGen needs a closed surface"
            + (options.fill_holes ? "" : " (filling holes is an option)"));
  }
  const double volume = std::abs(enclosed_volume(surface));
  if (!(volume > 0))
    throw InputError(source, "surface encloses no volume");

  TetrahedralizeReport report;
  report.tetgen = tetgen_executable(options);
  if (!tetgen_available(options))
    throw InputError(report.tetgen.empty() ? "tetgen" : report.tetgen,
        "TetGen program not found or not executable; install it (Debian package "
        "'tetgen') or set ELASTOLEARN_TETGEN to its path");
  report.input_faces = static_cast<int>(surface.faces.rows());
  report.holes_filled = holes_filled;
  TetgenRunner runner(options, report, source);

  std::optional<TetMesh> mesh;
  SurfaceMesh meshed = surface;
  if (options.max_tets == 0) {
    mesh = runner.run_with_fallback(meshed, options.max_volume);
    report.max_volume = options.max_volume;
  } else {
    const int target = options.max_tets;
    // A surface too detailed for the target is simplified first (tets grow ~7× the faces), and
    // again with a face budget scaled by (target / tets)^(2/3) while the unbounded mesh is too big.
    double face_budget = target / kTetsPerSurfaceFace;
    // Only a clearly too fine surface is simplified before trying it as it is.
    if (surface.faces.rows() <= 2 * face_budget)
      face_budget = static_cast<double>(surface.faces.rows());
    int failures = 0;
    for (int attempt = 0; attempt < 6; ++attempt) {
      if (surface.faces.rows() > face_budget) {
        meshed = simplify_surface(surface, std::max(16, static_cast<int>(face_budget)));
        report.simplified = true;
      }
      auto unbounded = runner.run_with_fallback(meshed, options.max_volume);
      if (!unbounded) {
        // A different simplification may avoid the defect (typically faces of thin parts that
        // cross after collapses): alternate slightly finer and coarser budgets.
        const double factors[] = { 1.2, 0.8, 1.45, 0.65, 1.7 };
        face_budget = std::min(face_budget, static_cast<double>(meshed.faces.rows()))
            * factors[std::min(failures++, 4)];
        continue;
      }
      const int count = unbounded->num_tets();
      if (count <= 1.1 * target) {
        report.max_volume = options.max_volume;
        mesh = std::move(unbounded);
        if (count < 0.9 * target) {
          double chosen = 0;
          if (auto refined = mesh_near_target(runner, meshed, volume, target, options.max_volume,
                  options.max_iterations, chosen);
              refined && std::abs(refined->num_tets() - target) < std::abs(count - target)) {
            mesh = std::move(refined);
            report.max_volume = chosen;
          }
        }
        break;
      }
      face_budget = std::min<double>(face_budget, static_cast<double>(meshed.faces.rows()))
          * std::pow(0.9 * target / count, 2.0 / 3.0);
    }
    if (!mesh && report.runs.back().num_tets > 0)
      throw InputError(source,
          "cannot reach max_tets = " + std::to_string(target)
              + ": the smallest mesh TetGen made has " + std::to_string(report.runs.back().num_tets)
              + " tets");
  }
  if (!mesh)
    runner.fail();
  report.surface_faces = static_cast<int>(meshed.faces.rows());
  report.num_tets = mesh->num_tets();
  report.num_vertices = mesh->num_vertices();
  report.seconds = seconds_since(start);
  if (report_out)
    *report_out = std::move(report);
  return std::move(*mesh);
}

} // namespace elastolearn::mesh
