#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/stress_reconstruction_lsqr.hpp>

#include <Eigen/IterativeLinearSolvers>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace elastolearn::learn {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

/// CGLS for one frame with B already assembled.
ElementStressResult solve_min_norm(
    const SparseMatrix& B, const VecX& f, const StressReconstructionOptions& options) {
  // No preconditioner: a diagonal one would give the minimum of a weighted norm instead.
  Eigen::LeastSquaresConjugateGradient<SparseMatrix, Eigen::IdentityPreconditioner> cgls;
  cgls.setTolerance(options.lsqr_tolerance);
  cgls.setMaxIterations(
      options.lsqr_max_iterations > 0 ? options.lsqr_max_iterations : int(2 * B.cols()));
  cgls.compute(B);
  ElementStressResult r;
  r.stresses = cgls.solve(f); // from p̂ = 0 (Eigen's solve starts from zero)
  r.iterations = int(cgls.iterations());
  r.relative_error = cgls.error();
  r.residual_norm = (B * r.stresses - f).norm();
  r.target_norm = f.norm();
  return r;
}

} // namespace

SparseMatrix assemble_stress_operator(const ReconstructionMesh& mesh, const fem::DofMap& dofs,
    const std::vector<ElementState>& states) {
  ELASTOLEARN_CHECK(states.size() == static_cast<size_t>(mesh.num_tets()),
      "assemble_stress_operator: one state per element expected");
  const int m = mesh.num_tets();
  SparseMatrix B(dofs.num_free(), 3 * Eigen::Index(m));
  B.reserve(Eigen::VectorXi::Constant(3 * m, 12));
  for (int e = 0; e < m; ++e) {
    const Eigen::Matrix<double, 12, 3> G = element_force_operator(mesh.rest[e], states[e].frame);
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 3; ++c) {
          const int row = dofs.free_index(3 * mesh.tets(e, a) + c);
          if (row >= 0)
            B.insert(row, 3 * e + k) = G(3 * a + c, k);
        }
  }
  B.makeCompressed();
  return B;
}

ElementStressResult reconstruct_element_stresses(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const VecX& x, const VecX& target_force,
    const StressReconstructionOptions& options) {
  options.validate();
  const std::vector<VecX> positions { x }, forces { target_force };
  detail::check_frames(mesh, &dofs, positions, nullptr, &forces);
  if (dofs.num_free() == 0)
    throw InputError("stress_reconstruction.dofs", "no free degree of freedom");
  std::vector<ElementState> states;
  compute_element_states(mesh, x, VecX::Zero(x.size()), states);
  return solve_min_norm(
      assemble_stress_operator(mesh, dofs, states), dofs.restrict(target_force), options);
}

StressReconstructionResult reconstruct_rbf_correction_via_lsqr(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const RbfDesign& design, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces,
    const StressReconstructionOptions& options) {
  const MatX none;
  const ReconstructionMotion motion { mesh, dofs, positions, velocities, target_forces, none };
  return reconstruct_rbf_correction_via_lsqr(std::span(&motion, 1), design, options);
}

StressReconstructionResult reconstruct_rbf_correction_via_lsqr(
    std::span<const ReconstructionMotion> motions, const RbfDesign& design,
    const StressReconstructionOptions& options) {
  options.validate();
  if (motions.empty())
    throw InputError("stress_reconstruction.motions", "no motion to reconstruct from");
  // Each motion's samples start at its offset: (frames used) × (its elements) rows.
  std::vector<std::vector<int>> frames;
  std::vector<Eigen::Index> offsets { 0 };
  for (const ReconstructionMotion& motion : motions) {
    detail::check_frames(
        motion.mesh, &motion.dofs, motion.positions, &motion.velocities, &motion.target_forces);
    if (motion.dofs.num_free() == 0)
      throw InputError("stress_reconstruction.dofs", "no free degree of freedom");
    frames.push_back(detail::selected_frames(int(motion.positions.size()), options.frame_stride));
    offsets.push_back(offsets.back() + Eigen::Index(frames.back().size()) * motion.mesh.num_tets());
  }
  const auto start = Clock::now();
  const Eigen::Index n = offsets.back();
  StressSamples samples;
  samples.stretches.resize(n, 3);
  samples.stretch_rates.resize(n, 3);
  samples.targets.resize(n, 3);
  int max_iterations = 0;
  double max_error = 0;
  for (size_t k = 0; k < motions.size(); ++k) {
    const ReconstructionMotion& motion = motions[k];
    const std::vector<int>& used = frames[k];
    const Eigen::Index m = motion.mesh.num_tets();
    std::vector<int> iterations(used.size());
    std::vector<double> errors(used.size());
    // One task per frame (its element pass is a nested parallel loop; `states` is task-local).
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, used.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
          std::vector<ElementState> states;
          for (size_t i = r.begin(); i < r.end(); ++i) {
            const int t = used[i];
            states.resize(m);
            compute_element_states(motion.mesh, motion.positions[t], motion.velocities[t], states);
            const ElementStressResult p
                = solve_min_norm(assemble_stress_operator(motion.mesh, motion.dofs, states),
                    motion.dofs.restrict(motion.target_forces[t]), options);
            iterations[i] = p.iterations;
            errors[i] = p.relative_error;
            for (Eigen::Index e = 0; e < m; ++e) {
              const Eigen::Index row = offsets[k] + Eigen::Index(i) * m + e;
              samples.stretches.row(row) = states[e].frame.stretches.transpose();
              samples.stretch_rates.row(row) = states[e].stretch_rates.transpose();
              samples.targets.row(row) = p.stresses.segment<3>(3 * e).transpose();
            }
          }
        });
    max_iterations
        = std::max(max_iterations, *std::max_element(iterations.begin(), iterations.end()));
    max_error = std::max(max_error, *std::max_element(errors.begin(), errors.end()));
  }
  const double assembly_seconds = seconds_since(start);

  const auto solve_start = Clock::now();
  RbfFitResult fit = fit_rbf_correction(design, samples);
  const double solve_seconds = seconds_since(solve_start);

  const auto misfit_start = Clock::now();
  const ForceMisfit misfit = correction_force_misfit(motions, fit.correction, options.frame_stride);
  int rows = 0;
  for (const ReconstructionMotion& motion : motions)
    rows += motion.dofs.num_free();
  StressReconstructionResult result { std::move(fit.correction), std::move(fit.unknowns), misfit, 0,
    rows };
  result.lsqr_max_iterations = max_iterations;
  result.lsqr_max_relative_error = max_error;
  result.stress_rms_residual = fit.rms_residual;
  result.assembly_seconds = assembly_seconds;
  result.solve_seconds = solve_seconds;
  result.misfit_seconds = seconds_since(misfit_start);
  return result;
}

} // namespace elastolearn::learn
