#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/stability_cuts.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>
#include <elastolearn/learn/stress_reconstruction_lsqr.hpp>

#include <Eigen/Cholesky>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors stress_reconstruction_error("stress_reconstruction");

/// Per-thread work space of the normal-equation assembly.
struct AssemblyScratch {
  CorrectionForceJacobian jacobian;
  VecX target;
  MatX projected_jt; ///< Jᵀ P: unknowns × r (with a projection)
  VecX projected_target; ///< Pᵀ g (with a projection)
};

/// Per-block sums (a block is a fixed range of frames, so the result is thread-count independent).
struct BlockSums {
  MatX normal; ///< lower triangle of Σ JᵀJ
  VecX rhs; ///< Σ Jᵀ g
};

constexpr int k_frame_blocks = 16;

} // namespace

std::string reconstruction_method_name(ReconstructionMethod method) {
  return method == ReconstructionMethod::lsqr ? "lsqr" : "normal_equations";
}

ReconstructionMethod reconstruction_method_from_name(
    const std::string& name, const std::string& where) {
  if (name == "normal_equations")
    return ReconstructionMethod::normal_equations;
  if (name == "lsqr")
    return ReconstructionMethod::lsqr;
  throw InputError(where, "unknown method '" + name + "' (expected normal_equations or lsqr)");
}

void StressReconstructionOptions::validate() const {
  if (frame_stride < 1)
    stress_reconstruction_error("frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  if (!std::isfinite(lsqr_tolerance) || lsqr_tolerance <= 0)
    stress_reconstruction_error(
        "lsqr_tolerance", "must be finite and > 0, got " + to_text(lsqr_tolerance));
  if (lsqr_max_iterations < 0)
    stress_reconstruction_error(
        "lsqr_max_iterations", "must be ≥ 0, got " + to_text(lsqr_max_iterations));
  if (!std::isfinite(full_space_weight) || full_space_weight < 0)
    stress_reconstruction_error(
        "full_space_weight", "must be finite and ≥ 0, got " + to_text(full_space_weight));
}

namespace {

/// Checks one motion's inputs for the normal-equation method (throws InputError).
void check_motion(const ReconstructionMotion& motion, const RbfDesign& design) {
  detail::check_frames(
      motion.mesh, &motion.dofs, motion.positions, &motion.velocities, &motion.target_forces);
  const int rows = motion.dofs.num_free();
  if (rows == 0)
    stress_reconstruction_error("dofs", "no free degree of freedom");
  const Eigen::Ref<const MatX>& projection = motion.projection;
  if (projection.size() > 0 && (projection.rows() != rows || !projection.allFinite()))
    stress_reconstruction_error("projection",
        "must have one finite row per free dof (" + to_text(rows) + "), got "
            + to_text(projection.rows()));
  if (design.damping_unknowns() > 0 && motion.mesh.nominal.elastic == nullptr)
    stress_reconstruction_error(
        "nominal", "fitting the damping correction needs the nominal elastic model");
}

/// Adds one motion's lower-triangular Σ JᵀJ and Σ Jᵀ g (each projected and/or μ-weighted) at
/// `frames` to `normal` and `rhs`. Frames in k_frame_blocks contiguous blocks; each block's sums
/// are formed serially in frame order on one thread, and the blocks are added in block order.
void accumulate_normal_equations(const ReconstructionMotion& motion, const RbfDesign& design,
    const std::vector<int>& frames, double full_space_weight, MatX& normal, VecX& rhs) {
  const Eigen::Ref<const MatX>& projection = motion.projection;
  const bool projected = projection.size() > 0;
  const double full_weight = projected ? full_space_weight : 1.0; // of the unprojected misfit
  const int u = design.num_unknowns();
  const int blocks = std::min<int>(k_frame_blocks, int(frames.size()));
  std::vector<BlockSums> sums(blocks);
  tbb::enumerable_thread_specific<AssemblyScratch> scratch([&] {
    AssemblyScratch s { CorrectionForceJacobian(motion.mesh, motion.dofs, design), VecX(),
      MatX(u, projection.cols()), VecX(projection.cols()) };
    return s;
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 1), [&](const tbb::blocked_range<int>& r) {
    AssemblyScratch& s = scratch.local();
    for (int b = r.begin(); b < r.end(); ++b) {
      BlockSums& sum = sums[b];
      sum.normal = MatX::Zero(u, u);
      sum.rhs = VecX::Zero(u);
      const size_t first = frames.size() * b / blocks, last = frames.size() * (b + 1) / blocks;
      for (size_t i = first; i < last; ++i) {
        const int t = frames[i];
        const MatX& jt = s.jacobian.transposed(motion.positions[t], motion.velocities[t]);
        motion.dofs.restrict_into(motion.target_forces[t], s.target);
        if (projected) {
          s.projected_jt.noalias() = jt * projection;
          s.projected_target.noalias() = projection.transpose() * s.target;
          sum.normal.selfadjointView<Eigen::Lower>().rankUpdate(s.projected_jt);
          sum.rhs.noalias() += s.projected_jt * s.projected_target;
        }
        if (full_weight > 0) {
          sum.normal.selfadjointView<Eigen::Lower>().rankUpdate(jt, full_weight);
          sum.rhs.noalias() += full_weight * (jt * s.target);
        }
      }
    }
  });
  for (const BlockSums& sum : sums) {
    normal += sum.normal;
    rhs += sum.rhs;
  }
}

} // namespace

StressReconstructionResult reconstruct_rbf_correction(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const RbfDesign& design, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces,
    const StressReconstructionOptions& options, ConstRef<MatX> projection) {
  const ReconstructionMotion motion { mesh, dofs, positions, velocities, target_forces,
    projection };
  return reconstruct_rbf_correction(std::span(&motion, 1), design, options);
}

StressReconstructionResult reconstruct_rbf_correction(std::span<const ReconstructionMotion> motions,
    const RbfDesign& design, const StressReconstructionOptions& options,
    const StabilityRequirement* stability) {
  options.validate();
  if (motions.empty())
    stress_reconstruction_error("motions", "no motion to reconstruct from");
  if (options.method == ReconstructionMethod::lsqr) {
    for (const ReconstructionMotion& motion : motions)
      if (motion.projection.size() > 0)
        stress_reconstruction_error(
            "method", "the lsqr method has no force projection: use normal_equations");
    return reconstruct_rbf_correction_via_lsqr(motions, design, options);
  }
  for (const ReconstructionMotion& motion : motions)
    check_motion(motion, design);
  const auto start = Clock::now();
  const int u = design.num_unknowns();
  MatX normal = MatX::Zero(u, u);
  VecX rhs = VecX::Zero(u);
  long samples = 0; // frames used, for the singular-system message
  for (const ReconstructionMotion& motion : motions) {
    const std::vector<int> frames
        = detail::selected_frames(int(motion.positions.size()), options.frame_stride);
    accumulate_normal_equations(motion, design, frames, options.full_space_weight, normal, rhs);
    samples += long(frames.size());
  }
  normal.triangularView<Eigen::StrictlyUpper>() = normal.transpose();
  const double assembly_seconds = seconds_since(start);

  const auto solve_start = Clock::now();
  normal += design.smoothness_penalty(normal);
  const RegularisedNormalEquations equations(
      std::move(normal), design.regularization_weights(), samples);
  StableSolve solved = stability ? stable_least_squares(equations, rhs, design, stability->nominal,
                           stability->samples, VecX::Zero(design.num_unknowns()))
                                 : StableSolve { equations.solve(rhs) };
  VecX x = std::move(solved.x);
  material::RbfCorrection correction = design.correction(x);
  const double solve_seconds = seconds_since(solve_start);

  const auto misfit_start = Clock::now();
  const ForceMisfit misfit = correction_force_misfit(motions, correction, options.frame_stride);
  int rows = 0;
  for (const ReconstructionMotion& motion : motions)
    rows += motion.dofs.num_free();
  StressReconstructionResult result { std::move(correction), std::move(x), misfit, solved.cuts,
    rows };
  result.assembly_seconds = assembly_seconds;
  result.solve_seconds = solve_seconds;
  result.misfit_seconds = seconds_since(misfit_start);
  return result;
}

ForceMisfit correction_force_misfit(std::span<const ReconstructionMotion> motions,
    const material::Correction& correction, int frame_stride) {
  ForceMisfit out;
  double count = 0; // frames × free vertices so far
  double residual = 0, target = 0; // their sums of squares
  for (const ReconstructionMotion& motion : motions) {
    const ForceMisfit part = correction_force_misfit(motion.mesh, motion.dofs, correction,
        motion.positions, motion.velocities, motion.target_forces, frame_stride);
    const double part_count = double(part.frames) * (motion.dofs.num_free() / 3.0);
    if (count == 0) {
      out = part;
    } else {
      out.rms_residual = std::sqrt(
          (residual + part_count * part.rms_residual * part.rms_residual) / (count + part_count));
      out.rms_target = std::sqrt(
          (target + part_count * part.rms_target * part.rms_target) / (count + part_count));
      out.frames += part.frames;
    }
    count += part_count;
    residual += part_count * part.rms_residual * part.rms_residual;
    target += part_count * part.rms_target * part.rms_target;
  }
  return out;
}

} // namespace elastolearn::learn
