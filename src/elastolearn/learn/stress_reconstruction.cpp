#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/stress_reconstruction.hpp>
#include <elastolearn/learn/stress_reconstruction_lsqr.hpp>

#include <Eigen/Cholesky>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors fail("stress_reconstruction");

/// Element states of elements [begin, end) (serial; no allocation).
void element_states_range(const ReconstructionMesh& mesh, const VecX& x, const VecX& v, int begin,
    int end, std::vector<ElementState>& states) {
  for (int e = begin; e < end; ++e) {
    const fem::TetRestData& rest = mesh.rest[e];
    const Eigen::Vector4i tet = mesh.tets.row(e).transpose();
    ElementState& s = states[e];
    s.frame = material::principal_frame(fem::deformation_gradient(fem::gather_tet(x, tet), rest));
    s.deformation_rate = fem::deformation_gradient(fem::gather_tet(v, tet), rest);
    s.stretch_rates = material::stretch_rates(s.frame, s.deformation_rate);
  }
}

/// Free index of each element's 12 local dofs (−1 for prescribed).
std::vector<std::array<int, 12>> element_free_rows(
    const ReconstructionMesh& mesh, const fem::DofMap& dofs) {
  std::vector<std::array<int, 12>> rows(mesh.num_tets());
  for (int e = 0; e < mesh.num_tets(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c)
        rows[e][3 * a + c] = dofs.free_index(3 * mesh.tets(e, a) + c);
  return rows;
}

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

ReconstructionMesh::ReconstructionMesh(const mesh::TetMesh& mesh, fem::MaterialModel nominal_model)
    : rest(fem::precompute_rest_data(mesh))
    , tets(mesh.tets())
    , num_vertices(mesh.num_vertices())
    , nominal(std::move(nominal_model)) { }

ReconstructionMesh::ReconstructionMesh(std::vector<fem::TetRestData> rest_data, Tets tet_indices,
    int n, fem::MaterialModel nominal_model)
    : rest(std::move(rest_data))
    , tets(std::move(tet_indices))
    , num_vertices(n)
    , nominal(std::move(nominal_model)) {
  if (rest.size() != static_cast<size_t>(tets.rows()))
    fail("mesh", to_text(rest.size()) + " rest data for " + to_text(tets.rows()) + " tets");
  if (tets.size() > 0 && (tets.minCoeff() < 0 || tets.maxCoeff() >= n))
    fail("mesh", "a tet index is outside [0, " + to_text(n) + ")");
}

void compute_element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    std::vector<ElementState>& states) {
  states.resize(mesh.num_tets());
  tbb::parallel_for(
      tbb::blocked_range<int>(0, mesh.num_tets(), 256), [&](const tbb::blocked_range<int>& r) {
        element_states_range(mesh, x, v, r.begin(), r.end(), states);
      });
}

Eigen::Matrix<double, 12, 3> element_force_operator(
    const fem::TetRestData& rest, const material::PrincipalFrame& frame) {
  // f_a = −vol U diag(p̂) Vᵀ g_a = Σ_k p̂_k (−vol (v_k · g_a) u_k).
  const Eigen::Matrix<double, 3, 4> vg = frame.V.transpose() * rest.gradients; // (v_k · g_a)
  Eigen::Matrix<double, 12, 3> G;
  for (int a = 0; a < 4; ++a)
    for (int k = 0; k < 3; ++k)
      G.block<3, 1>(3 * a, k) = (-rest.volume * vg(k, a)) * frame.U.col(k);
  return G;
}

namespace {

/// −vol (dP/dF : Ḟ) g_a for an eigen-form tangent (local dofs x0, y0, z0, x1, …).
Vec12 stiffness_damping_force(const fem::TetRestData& rest, const ElementState& state,
    const material::PrincipalTangent& tangent) {
  const Mat3 stress_rate
      = material::first_piola_differential(state.frame, tangent, state.deformation_rate);
  Vec12 f;
  Eigen::Map<Eigen::Matrix<double, 3, 4>>(f.data()).noalias()
      = -rest.volume * stress_rate * rest.gradients;
  return f;
}

} // namespace

Vec12 element_stiffness_damping_force(const fem::TetRestData& rest, const ElementState& state,
    const material::ElasticModel& elastic, material::DampingTangent kind) {
  return stiffness_damping_force(
      rest, state, material::damping_tangent(elastic, state.frame, kind));
}

Eigen::Matrix<double, 12, 12> element_stiffness_damping_operator(
    const fem::TetRestData& rest, const ElementState& state, material::DampingTangent kind) {
  // The exact eigen-form tangent is linear in (p̂, ∂p̂/∂σ), and so is the force: its columns are
  // the forces of the 12 unit inputs.
  Eigen::Matrix<double, 12, 12> op;
  for (int c = 0; c < 12; ++c) {
    Vec3 stress = Vec3::Zero();
    Mat3 derivative = Mat3::Zero();
    if (c < 3)
      stress[c] = 1;
    else
      derivative((c - 3) % 3, (c - 3) / 3) = 1;
    op.col(c) = stiffness_damping_force(
        rest, state, material::damping_tangent(state.frame, stress, derivative, kind));
  }
  return op;
}

namespace {

/// Nominal Rayleigh α₁ of an element (0 without a damping model).
double nominal_alpha1(const ReconstructionMesh& mesh, const Vec3& stretches) {
  return mesh.nominal.damping ? mesh.nominal.damping->coefficients(stretches[0]).alpha1 : 0.0;
}

/// The stiffness the nominal's damping scales (fem::ElasticForce's choice without a model).
material::DampingTangent nominal_damping_tangent(const ReconstructionMesh& mesh) {
  return mesh.nominal.damping ? mesh.nominal.damping->tangent()
                              : material::DampingTangent::FlipFree;
}

} // namespace

namespace {
constexpr int k_jacobian_batch = 512; ///< elements per batch of CorrectionForceJacobian
}

CorrectionForceJacobian::CorrectionForceJacobian(
    const ReconstructionMesh& mesh, const fem::DofMap& dofs, const RbfDesign& design)
    : m_mesh(mesh)
    , m_design(design)
    , m_free_rows(element_free_rows(mesh, dofs))
    , m_states(mesh.num_tets())
    , m_jt(design.num_unknowns(), dofs.num_free())
    , m_batch(
          12 * std::min(k_jacobian_batch, std::max(1, mesh.num_tets())), design.num_unknowns()) {
  if (design.damping_unknowns() > 0 && mesh.nominal.elastic == nullptr)
    fail("nominal", "fitting the damping correction needs the nominal elastic model");
}

void CorrectionForceJacobian::element_rows(int e, Eigen::Ref<MatX> rows,
    RbfDesign::OutputMatrix& outputs, RbfDesign::OutputGradient& gradients,
    Eigen::RowVectorXd& damping_row) const {
  const material::ElasticModel* elastic = m_mesh.nominal.elastic.get();
  const int u = m_design.num_unknowns(), u_elastic = m_design.elastic_unknowns();
  const ElementState& st = m_states[e];
  const Eigen::Matrix<double, 12, 3> G = element_force_operator(m_mesh.rest[e], st.frame);
  const double alpha1 = elastic != nullptr ? nominal_alpha1(m_mesh, st.frame.stretches) : 0.0;
  if (alpha1 != 0) {
    m_design.output_matrix(st.frame.stretches, outputs, gradients);
    const Eigen::Matrix<double, 12, 12> D = alpha1
        * element_stiffness_damping_operator(m_mesh.rest[e], st, nominal_damping_tangent(m_mesh));
    rows.leftCols(u_elastic).noalias() = (G + D.leftCols<3>()) * outputs;
    rows.leftCols(u_elastic).noalias() += D.rightCols<9>() * gradients;
  } else {
    m_design.output_matrix(st.frame.stretches, outputs);
    rows.leftCols(u_elastic).noalias() = G * outputs;
  }
  if (u > u_elastic) {
    m_design.damping_row(st.frame.stretches, damping_row);
    rows.rightCols(u - u_elastic).noalias() = element_stiffness_damping_force(m_mesh.rest[e], st,
                                                  *elastic, nominal_damping_tangent(m_mesh))
        * damping_row;
  }
}

const MatX& CorrectionForceJacobian::transposed(const VecX& x, const VecX& v) {
  const int m = m_mesh.num_tets();
  const int u = m_design.num_unknowns(), u_elastic = m_design.elastic_unknowns();
  compute_element_states(m_mesh, x, v, m_states);
  m_jt.setZero();
  for (int first = 0; first < m; first += k_jacobian_batch) {
    const int count = std::min(k_jacobian_batch, m - first);
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 32), [&](const tbb::blocked_range<int>& r) {
      // Per-task work space: a few small buffers per 32 elements, next to their O(u) products.
      RbfDesign::OutputMatrix outputs(3, u_elastic);
      RbfDesign::OutputGradient gradients(9, u_elastic);
      Eigen::RowVectorXd damping_row(u - u_elastic);
      for (int i = r.begin(); i < r.end(); ++i)
        element_rows(first + i, m_batch.middleRows(12 * i, 12), outputs, gradients, damping_row);
    });
    for (int i = 0; i < count; ++i)
      for (int l = 0; l < 12; ++l) {
        const int row = m_free_rows[first + i][l];
        if (row >= 0)
          m_jt.col(row) += m_batch.row(12 * i + l).transpose();
      }
  }
  return m_jt;
}

VecX correction_force(const ReconstructionMesh& mesh, const material::Correction& correction,
    const VecX& x, const VecX& v) {
  const int m = mesh.num_tets();
  std::vector<ElementState> states;
  compute_element_states(mesh, x, v, states);
  std::vector<Vec12> element_forces(m);
  const material::ElasticModel* elastic = mesh.nominal.elastic.get();
  const material::DampingTangent kind = nominal_damping_tangent(mesh);
  tbb::parallel_for(tbb::blocked_range<int>(0, m, 256), [&](const tbb::blocked_range<int>& r) {
    for (int e = r.begin(); e < r.end(); ++e) {
      const ElementState& s = states[e];
      if (elastic == nullptr) {
        element_forces[e].noalias() = element_force_operator(mesh.rest[e], s.frame)
            * correction.correction(s.frame.stretches, s.stretch_rates);
        continue;
      }
      const material::CorrectedStress total = material::corrected_principal_stress(
          *elastic, &correction, s.frame.stretches, s.stretch_rates);
      const Vec3 nominal_stress = elastic->principal_stress(s.frame.stretches);
      element_forces[e].noalias()
          = element_force_operator(mesh.rest[e], s.frame) * (total.stress - nominal_stress);
      // ElasticForce's damping with the correction minus without it: α₁ on the corrected minus
      // the nominal stiffness, and the learned Δα₁ on the nominal one (same clamp α₁ + Δα₁ ≥ 0).
      const double alpha1 = nominal_alpha1(mesh, s.frame.stretches);
      const double change
          = material::corrected_stiffness_damping(alpha1, &correction, s.frame.stretches) - alpha1;
      if (alpha1 == 0 && change == 0)
        continue;
      if (alpha1 != 0) {
        material::CorrectedStress scratch;
        const material::CorrectedStress& elastic_stress
            = material::elastic_part(*elastic, &correction, s.frame.stretches, total, scratch);
        element_forces[e] += alpha1
            * (stiffness_damping_force(mesh.rest[e], s,
                   material::damping_tangent(
                       s.frame, elastic_stress.stress, elastic_stress.d_stretches, kind))
                - stiffness_damping_force(
                    mesh.rest[e], s, material::damping_tangent(*elastic, s.frame, kind)));
      }
      if (change != 0)
        element_forces[e]
            += change * element_stiffness_damping_force(mesh.rest[e], s, *elastic, kind);
    }
  });
  VecX f = VecX::Zero(3 * Eigen::Index(mesh.num_vertices));
  for (int e = 0; e < m; ++e)
    for (int a = 0; a < 4; ++a)
      f.segment<3>(3 * mesh.tets(e, a)) += element_forces[e].segment<3>(3 * a);
  return f;
}

void StretchSampleOptions::validate() const {
  if (frame_stride < 1)
    throw InputError("stretch_samples.frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  if (max_samples < 0)
    throw InputError("stretch_samples.max_samples", "must be ≥ 0, got " + to_text(max_samples));
}

MatX collect_stretches(const ReconstructionMesh& mesh, const std::vector<VecX>& positions,
    const StretchSampleOptions& options) {
  options.validate();
  detail::check_frames(mesh, nullptr, positions, nullptr, nullptr);
  const std::vector<int> frames
      = detail::selected_frames(int(positions.size()), options.frame_stride);
  const Eigen::Index m = mesh.num_tets();
  const Eigen::Index total = Eigen::Index(frames.size()) * m;
  const Eigen::Index step = options.max_samples > 0
      ? std::max<Eigen::Index>(1, (total + options.max_samples - 1) / options.max_samples)
      : 1;
  const Eigen::Index rows = (total + step - 1) / step;
  MatX out(rows, 3);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, rows, 1024),
      [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index i = r.begin(); i < r.end(); ++i) {
          const Eigen::Index sample = i * step;
          const int e = int(sample % m);
          const VecX& x = positions[frames[sample / m]];
          const Mat3 F = fem::deformation_gradient(
              fem::gather_tet(x, mesh.tets.row(e).transpose()), mesh.rest[e]);
          out.row(i) = material::principal_frame(F).stretches.transpose();
        }
      });
  return out;
}

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
    fail("frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  if (!std::isfinite(lsqr_tolerance) || lsqr_tolerance <= 0)
    fail("lsqr_tolerance", "must be finite and > 0, got " + to_text(lsqr_tolerance));
  if (lsqr_max_iterations < 0)
    fail("lsqr_max_iterations", "must be ≥ 0, got " + to_text(lsqr_max_iterations));
  if (!std::isfinite(full_space_weight) || full_space_weight < 0)
    fail("full_space_weight", "must be finite and ≥ 0, got " + to_text(full_space_weight));
}

namespace detail {

void check_frames(const ReconstructionMesh& mesh, const fem::DofMap* dofs,
    const std::vector<VecX>& positions, const std::vector<VecX>* velocities,
    const std::vector<VecX>* target_forces) {
  const Eigen::Index n3 = 3 * Eigen::Index(mesh.num_vertices);
  if (positions.empty())
    fail("positions", "no frames");
  if (dofs != nullptr && dofs->num_dofs() != n3)
    fail("dofs", "the DofMap has " + to_text(dofs->num_dofs()) + " dofs, the mesh " + to_text(n3));
  const std::array<std::pair<const char*, const std::vector<VecX>*>, 3> lists {
    { { "positions", &positions }, { "velocities", velocities },
        { "target_forces", target_forces } }
  };
  for (const auto& [name, list] : lists) {
    if (list == nullptr)
      continue;
    if (list->size() != positions.size())
      fail(name, to_text(list->size()) + " frames but " + to_text(positions.size()) + " positions");
    for (size_t t = 0; t < list->size(); ++t) {
      const VecX& f = (*list)[t];
      if (f.size() != n3)
        fail(std::string(name) + "[" + to_text(t) + "]",
            "length " + to_text(f.size()) + ", expected 3n = " + to_text(n3));
      if (!f.allFinite())
        fail(std::string(name) + "[" + to_text(t) + "]", "contains a non-finite value");
    }
  }
}

std::vector<int> selected_frames(int count, int stride) {
  std::vector<int> frames;
  for (int t = 0; t < count; t += stride)
    frames.push_back(t);
  return frames;
}

} // namespace detail

ForceMisfit correction_force_misfit(const ReconstructionMesh& mesh, const fem::DofMap& dofs,
    const material::Correction& correction, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces, int frame_stride) {
  if (frame_stride < 1)
    fail("frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  detail::check_frames(mesh, &dofs, positions, &velocities, &target_forces);
  if (dofs.num_free() == 0)
    fail("dofs", "no free degree of freedom");
  const std::vector<int> frames = detail::selected_frames(int(positions.size()), frame_stride);
  double residual = 0, target = 0;
  VecX g, f;
  for (int t : frames) {
    dofs.restrict_into(target_forces[t], g);
    dofs.restrict_into(correction_force(mesh, correction, positions[t], velocities[t]), f);
    residual += (f - g).squaredNorm();
    target += g.squaredNorm();
  }
  const double count = double(frames.size()) * (dofs.num_free() / 3.0);
  return { std::sqrt(residual / count), std::sqrt(target / count), int(frames.size()) };
}

StressReconstructionResult reconstruct_rbf_correction(const ReconstructionMesh& mesh,
    const fem::DofMap& dofs, const RbfDesign& design, const std::vector<VecX>& positions,
    const std::vector<VecX>& velocities, const std::vector<VecX>& target_forces,
    const StressReconstructionOptions& options, ConstRef<MatX> projection) {
  options.validate();
  const bool projected = projection.size() > 0;
  const double full_weight
      = projected ? options.full_space_weight : 1.0; // of the unprojected misfit
  if (projected && options.method == ReconstructionMethod::lsqr)
    fail("method", "the lsqr method has no force projection: use normal_equations");
  if (options.method == ReconstructionMethod::lsqr)
    return reconstruct_rbf_correction_via_lsqr(
        mesh, dofs, design, positions, velocities, target_forces, options);
  detail::check_frames(mesh, &dofs, positions, &velocities, &target_forces);
  const int rows = dofs.num_free();
  if (rows == 0)
    fail("dofs", "no free degree of freedom");
  if (projected && (projection.rows() != rows || !projection.allFinite()))
    fail("projection",
        "must have one finite row per free dof (" + to_text(rows) + "), got "
            + to_text(projection.rows()));
  if (design.damping_unknowns() > 0 && mesh.nominal.elastic == nullptr)
    fail("nominal", "fitting the damping correction needs the nominal elastic model");
  const auto start = Clock::now();
  const std::vector<int> frames
      = detail::selected_frames(int(positions.size()), options.frame_stride);
  const int u = design.num_unknowns();

  // Frames in k_frame_blocks contiguous blocks; each block's sums are formed serially in frame
  // order on one thread, and the blocks are added in block order.
  const int blocks = std::min<int>(k_frame_blocks, int(frames.size()));
  std::vector<BlockSums> sums(blocks);
  tbb::enumerable_thread_specific<AssemblyScratch> scratch([&] {
    AssemblyScratch s { CorrectionForceJacobian(mesh, dofs, design), VecX(),
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
        const MatX& jt = s.jacobian.transposed(positions[t], velocities[t]);
        dofs.restrict_into(target_forces[t], s.target);
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
  MatX normal = MatX::Zero(u, u);
  VecX rhs = VecX::Zero(u);
  for (const BlockSums& sum : sums) {
    normal += sum.normal;
    rhs += sum.rhs;
  }
  normal.triangularView<Eigen::StrictlyUpper>() = normal.transpose();
  const double assembly_seconds = seconds_since(start);

  const auto solve_start = Clock::now();
  VecX x = solve_regularised_normal_equations(
      std::move(normal), rhs, design.regularization_weights(), long(frames.size()));
  material::RbfCorrection correction = design.correction(x);
  const double solve_seconds = seconds_since(solve_start);

  const auto misfit_start = Clock::now();
  const ForceMisfit misfit = correction_force_misfit(
      mesh, dofs, correction, positions, velocities, target_forces, options.frame_stride);
  StressReconstructionResult result { std::move(correction), std::move(x), misfit, rows };
  result.assembly_seconds = assembly_seconds;
  result.solve_seconds = solve_seconds;
  result.misfit_seconds = seconds_since(misfit_start);
  return result;
}

} // namespace elastolearn::learn
