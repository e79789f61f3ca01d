#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/material/principal_stress.hpp>
#include <elastolearn/sim/forward_run.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cstdio>

namespace elastolearn::learn {

StretchCoverage::StretchCoverage(
    const mesh::TetMesh& mesh, std::optional<material::StretchRange> trained, double tolerance)
    : m_tets(mesh.tets())
    , m_dofs(3 * Eigen::Index(mesh.num_vertices()))
    , m_rest(fem::precompute_rest_data(mesh))
    , m_trained(std::move(trained))
    , m_tolerance(tolerance) {
  if (!(tolerance >= 0))
    throw InputError("stretch coverage", "tolerance must be ≥ 0");
}

void StretchCoverage::add_frame(const VecX& x) {
  if (x.size() != m_dofs)
    throw InputError("stretch coverage",
        "a frame has " + std::to_string(x.size()) + " coordinates, the mesh "
            + std::to_string(m_dofs));
  struct Partial {
    material::StretchRange range;
    long outside = 0;
  };
  const int m = static_cast<int>(m_tets.rows());
  const Partial frame = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, m, 512), Partial {},
      [&](const tbb::blocked_range<int>& r, Partial p) {
        for (int e = r.begin(); e < r.end(); ++e) {
          const Mat3 F
              = fem::deformation_gradient(fem::gather_tet(x, m_tets.row(e).transpose()), m_rest[e]);
          const Vec3 s = material::principal_frame(F).stretches; // sorted s₁ ≥ s₂ ≥ s₃
          p.range.include(s);
          if (m_trained && !m_trained->contains(s, m_tolerance))
            ++p.outside;
        }
        return p;
      },
      [](Partial a, const Partial& b) {
        a.range.include(b.range);
        a.outside += b.outside;
        return a;
      });
  m_visited.include(frame.range);
  m_outside += frame.outside;
  m_samples += m;
}

material::StretchRange trajectory_stretch_range(
    const mesh::TetMesh& mesh, const std::vector<VecX>& frames) {
  StretchCoverage coverage(mesh);
  for (const VecX& x : frames)
    coverage.add_frame(x);
  return coverage.visited();
}

std::optional<material::StretchRange> training_stretch_range(
    const sim::Scene& training, std::shared_ptr<const material::Correction> correction) {
  if (!correction)
    return std::nullopt;
  const sim::ForwardRun run
      = sim::simulate_positions(sim::with_correction(training, std::move(correction)));
  if (!run.completed)
    return std::nullopt;
  return trajectory_stretch_range(training.mesh, run.positions);
}

std::string describe(const material::StretchRange& range) {
  if (range.empty())
    return "(no samples)";
  char text[160];
  std::snprintf(text, sizeof text, "s₁ %.3f–%.3f, s₂ %.3f–%.3f, s₃ %.3f–%.3f", range.min[0],
      range.max[0], range.min[1], range.max[1], range.min[2], range.max[2]);
  return text;
}

std::string extrapolation_note(const StretchCoverage& coverage) {
  ELASTOLEARN_CHECK(coverage.trained().has_value(), "extrapolation_note needs a training range");
  if (coverage.samples_outside() == 0)
    return "";
  const material::StretchRange& trained = *coverage.trained();
  const material::StretchRange& visited = coverage.visited();
  static constexpr const char* subscripts[] = { "₁", "₂", "₃" };
  std::string beyond;
  char text[200];
  for (int k = 0; k < 3; ++k) {
    if (visited.max[k] > trained.max[k] + coverage.tolerance()) {
      std::snprintf(text, sizeof text, "%ss%s up to %.3f (trained ≤ %.3f)",
          beyond.empty() ? "" : ", ", subscripts[k], visited.max[k], trained.max[k]);
      beyond += text;
    }
    if (visited.min[k] < trained.min[k] - coverage.tolerance()) {
      std::snprintf(text, sizeof text, "%ss%s down to %.3f (trained ≥ %.3f)",
          beyond.empty() ? "" : ", ", subscripts[k], visited.min[k], trained.min[k]);
      beyond += text;
    }
  }
  std::snprintf(text, sizeof text,
      "%ld of %ld (element, frame) samples (%.2g %%) leave the learned correction's "
      "training stretches, where it extrapolates: ",
      coverage.samples_outside(), coverage.samples(), 100 * coverage.fraction_outside());
  return text + beyond;
}

std::string coverage_report(const StretchCoverage& coverage, const std::string& indent) {
  std::string report = indent + "stretches: " + describe(coverage.visited())
      + " (the correction was trained on " + describe(*coverage.trained()) + ")\n";
  if (const std::string note = extrapolation_note(coverage); !note.empty())
    report += indent + "note: " + note + "\n";
  return report;
}

} // namespace elastolearn::learn
