#pragma once
/// \file The LSQR option of the stress reconstruction (paper 000 §6.1 and Fig. 4): per frame, the
/// minimum-norm element principal stresses p̂ with B p̂ = f in the least-squares sense, then an RBF
/// fit to those (stretch, stretch rate, p̂) samples. The paper prefers the direct RBF
/// reconstruction (stress_reconstruction.hpp) because these min-norm stresses need not match the
/// true ones; this path is kept for comparison.
#include <elastolearn/learn/element_force_operator.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>

#include <Eigen/SparseCore>

#include <span>

namespace elastolearn::learn {

/// The paper's B of one frame (§4.1, "B p̂ = f"), restricted to the free dofs: a sparse
/// num_free × 3m matrix whose column 3e + k is element e's element_force_operator column k
/// scattered to the free rows (principal stress k of element e is in its frame's σ order).
/// `states` from compute_element_states (only the frames are used).
Eigen::SparseMatrix<double> assemble_stress_operator(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const std::vector<ElementState>& states);

struct ElementStressResult {
  VecX stresses; ///< p̂ (3m): element e's principal stresses [Pa] at 3e..3e+2
  int iterations = 0; ///< CGLS iterations
  double relative_error = 0; ///< ‖Bᵀ(f − B p̂)‖ / ‖Bᵀ f‖ at exit (Eigen's estimate)
  double residual_norm = 0; ///< ‖B p̂ − f‖ over the free dofs [N]
  double target_norm = 0; ///< ‖f‖ over the free dofs [N]
};

/// Minimum-norm least-squares element stresses of one frame (Fig. 4): min ‖p̂‖ subject to
/// Bᵀ B p̂ = Bᵀ f, with f = restrict_free(target_force). Solved by Eigen's
/// LeastSquaresConjugateGradient (CGLS) without preconditioner from p̂ = 0: its iterates stay in
/// range(Bᵀ), so it converges to the minimum-norm solution. Uses options.lsqr_tolerance and
/// lsqr_max_iterations. `x` and `target_force` are flat 3n; throws InputError as
/// reconstruct_rbf_correction does.
ElementStressResult reconstruct_element_stresses(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const VecX& x, const VecX& target_force,
    const StressReconstructionOptions& options = {});

/// The LSQR pipeline: for every selected frame, element stresses (reconstruct_element_stresses)
/// → StressSamples (sorted stretches, stretch rates, p̂ as target) → fit_rbf_correction(design).
/// Frames run in parallel (oneTBB); the samples are stored in frame order, so the result does
/// not depend on the thread count. `misfit` is the nodal-force misfit of the fitted correction,
/// as for the direct method. Element stresses carry no stiffness-damping information, so this
/// method fits the elastic part only (Δα₁ = 0) and leaves out the nominal α₁'s action on the
/// correction's stiffness. Same inputs and throws as
/// reconstruct_rbf_correction.
StressReconstructionResult reconstruct_rbf_correction_via_lsqr(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const RbfDesign& design, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces,
    const StressReconstructionOptions& options = {});

/// The same over several motions: every motion's samples (motion by motion, each in frame
/// order) in one RBF fit; `misfit` over all their frames. Projections are ignored (the caller
/// refuses them). Throws InputError as above, and for no motion.
StressReconstructionResult reconstruct_rbf_correction_via_lsqr(
    std::span<const ReconstructionMotion> motions, const RbfDesign& design,
    const StressReconstructionOptions& options = {});

} // namespace elastolearn::learn
