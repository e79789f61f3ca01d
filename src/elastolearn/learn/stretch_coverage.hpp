#pragma once
/// \file Where a trajectory takes the material, in sorted principal stretches s₁ ≥ s₂ ≥ s₃ per
/// element and frame, against the range a learned correction was trained on. A correction is
/// fitted to the stretches of its training motion; beyond them it extrapolates (its kernels
/// fade into their linear tails), and a test motion that reaches far beyond can be much worse
/// than the training's error suggests (docs/learning.md, "Training range").
#include <elastolearn/fem/tet_element.hpp>
#include <elastolearn/material/stretch_range.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>
#include <elastolearn/sim/scene.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace elastolearn::learn {

/// Accumulates, frame by frame, the stretch range a trajectory visits and, given a training
/// range, how many (element, frame) samples leave it.
class StretchCoverage {
  public:
  /// \param trained    the training range to compare with (none: only the visited range)
  /// \param tolerance  a sample counts as outside when a sorted stretch leaves `trained` by
  ///                   more than this [-] (default 10⁻³: 0.1 % strain, far above round-off)
  explicit StretchCoverage(const mesh::TetMesh& mesh,
      std::optional<material::StretchRange> trained = std::nullopt, double tolerance = 1e-3);

  /// One frame of positions, flat 3n. Elements in parallel, no allocation per element.
  /// Throws InputError if x is not 3n long.
  void add_frame(const VecX& x);

  const material::StretchRange& visited() const { return m_visited; }
  const std::optional<material::StretchRange>& trained() const { return m_trained; }
  double tolerance() const { return m_tolerance; }
  long samples() const { return m_samples; }
  long samples_outside() const { return m_outside; }
  /// samples_outside / samples (0 before any frame).
  double fraction_outside() const {
    return m_samples > 0 ? double(m_outside) / double(m_samples) : 0.0;
  }

  private:
  Tets m_tets; ///< a copy: the coverage may outlive the mesh it was built from
  Eigen::Index m_dofs; ///< 3n
  std::vector<fem::TetRestData> m_rest;
  std::optional<material::StretchRange> m_trained;
  double m_tolerance;
  material::StretchRange m_visited;
  long m_samples = 0, m_outside = 0;
};

/// The stretch range of a whole trajectory (frames flat 3n).
material::StretchRange trajectory_stretch_range(
    const mesh::TetMesh& mesh, const std::vector<VecX>& frames);

/// The training range of a learned correction: the stretch range of the training scene
/// simulated with it (the model that fits the observations; the observed vertices alone cannot
/// give the interior's stretches). Nothing if `correction` is null or that simulation does not
/// complete (it did when the loop chose the correction; a caller must not lose a learned
/// correction over its metadata).
std::optional<material::StretchRange> training_stretch_range(
    const sim::Scene& training, std::shared_ptr<const material::Correction> correction);

/// "s₁ 0.978–1.022, s₂ 0.990–1.010, s₃ 0.973–1.000" (three decimals).
std::string describe(const material::StretchRange& range);

/// For users: empty if no sample left the training range, else one sentence saying how many
/// did, how far (per sorted stretch beyond its trained bound) and that the correction
/// extrapolates there. Requires coverage.trained().
std::string extrapolation_note(const StretchCoverage& coverage);

/// What simulate, evaluate and demo print, each line starting with `indent`:
/// "stretches: <visited> (the correction was trained on <trained>)" and, if any sample left
/// the training range, "note: <extrapolation_note>". Requires coverage.trained().
std::string coverage_report(const StretchCoverage& coverage, const std::string& indent = "");

} // namespace elastolearn::learn
