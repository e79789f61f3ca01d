#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/space_time.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace elastolearn::learn {

namespace {

/// out = A B for sparse matrices A of one fixed pattern and a fixed dense B of a few columns
/// (Φ on the free dofs), row by row: each row of A is read once for all columns of B, where
/// Eigen's column-major sparse × dense product walks the whole of A once per column (9 % of a
/// learning run's time). Entry (i, j) is summed over A's columns in increasing order starting
/// from zero, exactly as Eigen sums it, so the results are bitwise Eigen's; rows split over
/// threads do not change any sum.
class FixedPatternProduct {
  public:
  FixedPatternProduct(const fem::SparseMatrix& pattern, const MatX& b)
      : m_nonzeros(pattern.nonZeros())
      , m_row_start(static_cast<size_t>(pattern.rows()) + 1, 0)
      , m_b(b) {
    const int nnz = static_cast<int>(pattern.nonZeros());
    const int* outer = pattern.outerIndexPtr();
    const int* inner = pattern.innerIndexPtr();
    ELASTOLEARN_CHECK(pattern.isCompressed() && b.rows() == pattern.cols(), "product shapes");
    for (int p = 0; p < nnz; ++p)
      ++m_row_start[inner[p] + 1];
    for (size_t i = 1; i < m_row_start.size(); ++i)
      m_row_start[i] += m_row_start[i - 1];
    m_entry.resize(nnz);
    m_column.resize(nnz);
    std::vector<int> fill(m_row_start.begin(), m_row_start.end() - 1);
    for (int k = 0; k < pattern.cols();
         ++k) // columns in increasing order: each row's entries sorted by column
      for (int p = outer[k]; p < outer[k + 1]; ++p) {
        m_entry[fill[inner[p]]] = p;
        m_column[fill[inner[p]]++] = k;
      }
  }

  void multiply(const fem::SparseMatrix& a, MatX& out) const {
    ELASTOLEARN_CHECK(a.nonZeros() == m_nonzeros && a.isCompressed()
            && a.rows() + 1 == Eigen::Index(m_row_start.size()),
        "the matrix is not of the product's pattern");
    out.resize(a.rows(), m_b.cols());
    const double* values = a.valuePtr();
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.rows(), 64),
        [&](const tbb::blocked_range<Eigen::Index>& r) {
          Eigen::RowVectorXd sum(m_b.cols()); // one per block of rows, not per row
          for (Eigen::Index i = r.begin(); i < r.end(); ++i) {
            sum.setZero();
            for (int p = m_row_start[i]; p < m_row_start[i + 1]; ++p)
              sum.noalias() += values[m_entry[p]] * m_b.row(m_column[p]);
            out.row(i) = sum;
          }
        });
  }

  private:
  Eigen::Index m_nonzeros = 0;
  std::vector<int> m_row_start, m_entry,
      m_column; ///< A's entries row by row (CSR order), as positions in its values
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m_b; ///< rows contiguous
};

} // namespace

void SpaceTimeOptions::validate() const {
  if (!(position_weight > 0 && std::isfinite(position_weight)))
    throw InputError("space_time.position_weight",
        "must be a positive number, got " + std::to_string(position_weight));
  if (max_iterations < 0)
    throw InputError("space_time.max_iterations", "must be ≥ 0");
  if (!(tolerance >= 0))
    throw InputError("space_time.tolerance", "must be ≥ 0");
}

/// Everything that does not change between Gauss–Newton iterations, and the work buffers.
struct SpaceTimeProblem::Impl {
  TrajectoryPhysics& physics;
  const observe::Observation& observed;
  VecX v0;
  int steps = 0; ///< T
  int modes = 0; ///< r
  double h = 0;
  double scale = 0; ///< s = h²/m̄
  double lambda = 0;
  std::vector<int> free; ///< free dofs
  MatX free_basis; ///< Φ restricted to the free dofs
  MatX inertia; ///< Φᵀ M Φ / h² (r × r)
  std::vector<int> observed_dofs; ///< observed free dofs
  std::vector<int> observed_row; ///< their index in the flattened k×3 data frames
  MatX observed_basis; ///< S Φ
  fem::SystemMatrix stiffness, damping;
  std::unique_ptr<FixedPatternProduct> times_basis; ///< A ↦ A Φ for both matrices (one pattern)
  MatX stiffness_basis, damping_basis;
  VecX residual, residual_free;

  Impl(TrajectoryPhysics& p, const observe::Observation& o)
      : physics(p)
      , observed(o) { }

  /// The observed dof i is seen in `frame` (Observation::valid).
  bool seen(int frame, size_t i) const { return observed.is_valid(frame, observed_row[i] / 3); }
  /// S x_i − s_i, 0 at the entries lost in that frame.
  VecX position_error(const VecX& x, int frame) const {
    VecX e(static_cast<Eigen::Index>(observed_dofs.size()));
    const double* d = observed.positions[frame].data();
    for (size_t i = 0; i < observed_dofs.size(); ++i)
      e[static_cast<Eigen::Index>(i)]
          = seen(frame, i) ? x[observed_dofs[i]] - d[observed_row[i]] : 0.0;
    return e;
  }
  /// r_i into residual / residual_free; x_{−1} = x_0 − h v_0.
  void residual_at(const std::vector<VecX>& x, int i, const VecX& before) {
    physics.residual(i == 1 ? before : x[i - 2], x[i - 1], x[i], i * h, residual);
    physics.dofs().restrict_into(residual, residual_free);
  }
};

SpaceTimeProblem::SpaceTimeProblem(TrajectoryPhysics& physics, ConstRef<MatX> basis, int steps,
    const VecX& v0, const observe::Observation& observed, double position_weight)
    : m_impl(std::make_unique<Impl>(physics, observed)) {
  Impl& s = *m_impl;
  const int n3 = physics.dofs().num_dofs();
  s.v0 = v0;
  s.steps = steps;
  s.modes = static_cast<int>(basis.cols());
  s.h = physics.dt();
  s.lambda = position_weight;
  if (steps < 1)
    throw InputError("space_time", "the trajectory needs at least two states");
  if (basis.rows() != n3 || s.modes < 1)
    throw InputError(
        "space_time", "basis must have " + std::to_string(n3) + " rows and at least one column");
  if (v0.size() != n3)
    throw InputError("space_time", "initial velocity of wrong size");
  if (observed.num_frames() != steps + 1)
    throw InputError("observations",
        "have " + std::to_string(observed.num_frames()) + " frames, the trajectory "
            + std::to_string(steps + 1));
  s.free = physics.dofs().free_dofs();
  s.free_basis.resize(static_cast<Eigen::Index>(s.free.size()), s.modes);
  for (size_t i = 0; i < s.free.size(); ++i)
    s.free_basis.row(static_cast<Eigen::Index>(i)) = basis.row(s.free[i]);
  const VecX free_masses = physics.dofs().restrict(physics.dof_masses());
  // Forces → the displacement they cause over 1 % of the trajectory's duration, so that the
  // balance with the position term does not depend on the time step (with h²/m̄ instead, a run
  // at 1 ms steps weighs the physics 16× less than the same motion at 4 ms, and learning stalls:
  // docs/learning_loop.md).
  const double reference_time = 0.01 * steps * s.h;
  s.scale = reference_time * reference_time / free_masses.mean();
  s.inertia = s.free_basis.transpose() * free_masses.asDiagonal() * s.free_basis / (s.h * s.h);
  for (int j = 0; j < observed.num_observed(); ++j) {
    const int v = observed.vertex_ids[j];
    if (v < 0 || 3 * v + 2 >= n3)
      throw InputError("observations", "vertex id " + std::to_string(v) + " out of range");
    if (physics.dofs().is_prescribed_vertex(v))
      continue;
    for (int c = 0; c < 3; ++c) {
      s.observed_dofs.push_back(3 * v + c);
      s.observed_row.push_back(3 * j + c);
    }
  }
  s.observed_basis.resize(static_cast<Eigen::Index>(s.observed_dofs.size()), s.modes);
  for (size_t i = 0; i < s.observed_dofs.size(); ++i)
    s.observed_basis.row(static_cast<Eigen::Index>(i)) = basis.row(s.observed_dofs[i]);
  s.stiffness = physics.make_matrix();
  s.damping = physics.make_matrix();
  const fem::SparseMatrix &k = s.stiffness.matrix(), &d = s.damping.matrix();
  ELASTOLEARN_CHECK(k.nonZeros() == d.nonZeros()
          && std::equal(k.outerIndexPtr(), k.outerIndexPtr() + k.cols() + 1, d.outerIndexPtr())
          && std::equal(k.innerIndexPtr(), k.innerIndexPtr() + k.nonZeros(), d.innerIndexPtr()),
      "the stiffness and damping matrices share one pattern");
  s.times_basis = std::make_unique<FixedPatternProduct>(k, s.free_basis);
}

SpaceTimeProblem::~SpaceTimeProblem() = default;
int SpaceTimeProblem::modes() const {
  return m_impl->modes;
}
int SpaceTimeProblem::steps() const {
  return m_impl->steps;
}

SpaceTimeProblem::Value SpaceTimeProblem::evaluate(const std::vector<VecX>& x) {
  Impl& s = *m_impl;
  ELASTOLEARN_CHECK(static_cast<int>(x.size()) == s.steps + 1, "trajectory length");
  Value value;
  const VecX before = s.physics.state_before_start(x[0], s.v0);
  for (int i = 1; i <= s.steps; ++i) {
    s.residual_at(x, i, before);
    value.residual_squares += s.residual_free.squaredNorm();
    value.physics += 0.5 * (s.scale * (s.free_basis.transpose() * s.residual_free)).squaredNorm();
  }
  for (int i = 0; i <= s.steps; ++i)
    value.position_squares += s.position_error(x[i], i).squaredNorm();
  value.position = 0.5 * s.lambda * s.lambda * value.position_squares;
  return value;
}

void SpaceTimeProblem::assemble(
    const std::vector<VecX>& x, BlockBandedMatrix& normal, VecX& gradient) {
  Impl& s = *m_impl;
  const int T = s.steps, r = s.modes;
  ELASTOLEARN_CHECK(normal.blocks() == T + 1 && normal.block_size() == r, "normal matrix shape");
  normal.set_zero();
  gradient.setZero(static_cast<Eigen::Index>(T + 1) * r);
  const VecX before = s.physics.state_before_start(x[0], s.v0);
  MatX blocks[3];
  for (int i = 1; i <= T; ++i) {
    s.residual_at(x, i, before);
    s.physics.jacobians(s.stiffness, s.damping);
    s.times_basis->multiply(s.stiffness.matrix(), s.stiffness_basis);
    s.times_basis->multiply(s.damping.matrix(), s.damping_basis);
    // ∂(s Φᵀ r_i)/∂z for z_i, z_{i−1}, z_{i−2}: s Φᵀ (M/h² + K + D/h) Φ, s Φᵀ (−2M/h² − D/h) Φ, s
    // Φᵀ M Φ/h².
    blocks[0].noalias() = s.scale * (s.inertia + s.free_basis.transpose() * s.stiffness_basis);
    blocks[1].noalias()
        = s.scale * (-2 * s.inertia - s.free_basis.transpose() * s.damping_basis / s.h);
    blocks[2].noalias() = s.scale * s.inertia;
    int count = 3;
    if (i == 1) { // x_{−1} = x_0 − h v_0 moves with z_0
      blocks[1] += blocks[2];
      count = 2;
    }
    const VecX c = s.scale * (s.free_basis.transpose() * s.residual_free);
    for (int a = 0; a < count; ++a) {
      gradient.segment(static_cast<Eigen::Index>(i - a) * r, r).noalias()
          += blocks[a].transpose() * c;
      for (int b = a; b < count; ++b) // block (i − a, i − b), row block ≥ column block
        normal.block(i - a, i - b).noalias() += blocks[a].transpose() * blocks[b];
    }
  }
  const double lambda2 = s.lambda * s.lambda;
  const MatX position_normal = lambda2 * s.observed_basis.transpose() * s.observed_basis;
  MatX seen_basis; // S Φ with the rows lost in a frame zeroed
  for (int i = 0; i <= T; ++i) {
    bool all_seen = true;
    for (size_t o = 0; o < s.observed_dofs.size() && all_seen; ++o)
      all_seen = s.seen(i, o);
    if (all_seen) {
      normal.block(i, i) += position_normal;
    } else {
      seen_basis = s.observed_basis;
      for (size_t o = 0; o < s.observed_dofs.size(); ++o)
        if (!s.seen(i, o))
          seen_basis.row(static_cast<Eigen::Index>(o)).setZero();
      normal.block(i, i).noalias() += lambda2 * seen_basis.transpose() * seen_basis;
    }
    gradient.segment(static_cast<Eigen::Index>(i) * r, r).noalias()
        += lambda2 * s.observed_basis.transpose() * s.position_error(x[i], i);
  }
}

SpaceTimeResult optimize_space_time(TrajectoryPhysics& physics, ConstRef<MatX> basis,
    const std::vector<VecX>& origin, const VecX& v0, const observe::Observation& observed,
    const SpaceTimeOptions& options, const ProgressCallback& progress) {
  options.validate();
  const auto start_time = Clock::now();
  const int T = static_cast<int>(origin.size()) - 1;
  for (const auto& state : origin)
    if (state.size() != basis.rows())
      throw InputError("space_time", "origin state of wrong size");
  SpaceTimeProblem problem(physics, basis, T, v0, observed, options.position_weight);
  const int r = problem.modes();

  SpaceTimeResult result;
  result.positions = origin;
  auto& x = result.positions;
  SpaceTimeProblem::Value current = problem.evaluate(x);
  result.initial_objective = current.total();

  BlockBandedMatrix normal(T + 1, r);
  BandedBlockCholesky cholesky;
  VecX gradient;
  std::vector<VecX> trial(x.size());
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    problem.assemble(x, normal, gradient);
    // A tiny Levenberg shift keeps directions neither term sees from making JᵀJ singular.
    double max_diagonal = 0;
    for (int i = 0; i <= T; ++i)
      max_diagonal = std::max(max_diagonal, normal.block(i, i).diagonal().maxCoeff());
    for (int i = 0; i <= T; ++i)
      normal.block(i, i).diagonal().array() += 1e-10 * max_diagonal;
    cholesky.compute(normal);
    VecX step = -gradient;
    cholesky.solve_in_place(step);

    // Backtracking line search on E.
    bool accepted = false;
    SpaceTimeProblem::Value candidate;
    for (double alpha = 1; alpha > 1e-3; alpha *= 0.5) {
      for (int i = 0; i <= T; ++i)
        trial[i] = x[i] + alpha * (basis * step.segment(static_cast<Eigen::Index>(i) * r, r));
      candidate = problem.evaluate(trial);
      if (candidate.total() < current.total()) {
        accepted = true;
        break;
      }
    }
    if (!accepted)
      break;
    const double decrease = current.total() - candidate.total();
    x.swap(trial);
    current = candidate;
    result.iterations = iteration + 1;
    if (progress)
      progress(iteration + 1, options.max_iterations,
          "space-time E " + std::to_string(current.total()) + " (physics "
              + std::to_string(current.physics) + ", positions " + std::to_string(current.position)
              + ")");
    if (decrease < options.tolerance * (current.total() + decrease))
      break;
  }
  result.objective = current.total();
  const double free_count = static_cast<double>(physics.dofs().num_free());
  result.physics_rms = std::sqrt(current.residual_squares / (T * free_count));
  const double seen_entries = static_cast<double>(std::max(1L, observed.num_valid()));
  result.position_rms = std::sqrt(current.position_squares / seen_entries);
  result.seconds = seconds_since(start_time);
  return result;
}

std::vector<VecX> trajectory_residuals(
    TrajectoryPhysics& physics, const std::vector<VecX>& positions, const VecX& v0) {
  std::vector<VecX> out(positions.size());
  if (positions.empty())
    return out;
  out[0] = VecX::Zero(positions[0].size());
  const VecX before = physics.state_before_start(positions[0], v0);
  for (size_t i = 1; i < positions.size(); ++i)
    physics.residual(i == 1 ? before : positions[i - 2], positions[i - 1], positions[i],
        static_cast<double>(i) * physics.dt(), out[i]);
  return out;
}

} // namespace elastolearn::learn
