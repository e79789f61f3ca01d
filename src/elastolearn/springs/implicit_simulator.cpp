#include <elastolearn/springs/implicit_simulator.hpp>

#include <elastolearn/core/error.hpp>
#include <elastolearn/springs/spring_kernels.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::springs {

namespace {
/// Σ_a ⟨x_a, y_a⟩ over all rows, summed in fixed chunks so the result does not depend on the
/// thread count (same inputs, same result).
double dot(const Positions& x, const Positions& y) {
  const int n = static_cast<int>(x.rows());
  constexpr int chunks = 32;
  double partial[chunks] = {};
  const int per = (n + chunks - 1) / chunks;
  auto body = [&](int c) {
    double s = 0.0;
    for (int a = c * per; a < std::min(n, (c + 1) * per); ++a)
      s += x.row(a).dot(y.row(a));
    partial[c] = s;
  };
  if (n < detail::k_parallel_threshold) {
    for (int c = 0; c < chunks; ++c)
      body(c);
  } else {
    tbb::parallel_for(0, chunks, body);
  }
  double sum = 0.0;
  for (double p : partial)
    sum += p;
  return sum;
}
} // namespace

ImplicitLearnedSimulator::ImplicitLearnedSimulator(SpringSystem system, LearnedSpring spring,
    double dt, const LearnedSimulatorOptions& options, const Loads& loads)
    : m_system(std::move(system))
    , m_spring(std::move(spring))
    , m_dt(dt)
    , m_options(options) {
  m_options.validate();
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("simulation.dt", "must be > 0, got " + std::to_string(dt));
  const int n = m_system.node_count(), s = m_system.spring_count();
  m_free_index.assign(static_cast<std::size_t>(n), -1);
  int free = 0;
  for (int a = 0; a < n; ++a)
    if (!m_system.pinned[a])
      m_free_index[a] = free++;
  m_direct = m_options.solver == LinearSolverKind::direct
      || (m_options.solver == LinearSolverKind::automatic && 3 * free <= m_options.direct_max_dofs);
  m_u.resize(s, 3);
  m_force.resize(s);
  m_alpha.resize(s);
  m_beta.resize(s);
  m_a.resize(s);
  m_b.resize(s);
  m_diag_inverse.resize(static_cast<std::size_t>(n));
  for (Positions* p : { &m_rhs, &m_dv, &m_r, &m_z, &m_p, &m_q })
    *p = Positions::Zero(n, 3);
  if (m_direct)
    setup_direct();
  set_loads(loads);
}

void ImplicitLearnedSimulator::set_loads(const Loads& loads) {
  m_external = detail::checked_forces(m_system, loads);
  m_gravity = loads.gravity;
}

void ImplicitLearnedSimulator::setup_direct() {
  const SpringSystem& sys = m_system;
  const int free = static_cast<int>(
      std::count_if(m_free_index.begin(), m_free_index.end(), [](int f) { return f >= 0; }));
  std::vector<Eigen::Triplet<double>> triplets;
  auto add_block = [&](int fi, int fj) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        triplets.emplace_back(3 * fi + r, 3 * fj + c, 0.0);
  };
  for (int f : m_free_index)
    if (f >= 0)
      add_block(f, f);
  for (int s = 0; s < sys.spring_count(); ++s) {
    const int fi = m_free_index[sys.springs(s, 0)], fj = m_free_index[sys.springs(s, 1)];
    if (fi >= 0 && fj >= 0) {
      add_block(fi, fj);
      add_block(fj, fi);
    }
  }
  m_matrix.resize(3 * free, 3 * free);
  m_matrix.setFromTriplets(triplets.begin(), triplets.end());
  m_matrix.makeCompressed();
  auto slot = [&](int row, int col) {
    const int* begin = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col];
    const int* end = m_matrix.innerIndexPtr() + m_matrix.outerIndexPtr()[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    ELASTOLEARN_CHECK(it != end && *it == row, "sparsity pattern misses an entry");
    return static_cast<int>(it - m_matrix.innerIndexPtr());
  };
  auto block_slots = [&](int fi, int fj, int* out) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        out[3 * r + c] = slot(3 * fi + r, 3 * fj + c);
  };
  m_diag_slot.assign(static_cast<std::size_t>(9 * sys.node_count()), -1);
  for (int a = 0; a < sys.node_count(); ++a)
    if (m_free_index[a] >= 0)
      block_slots(m_free_index[a], m_free_index[a], &m_diag_slot[9 * a]);
  m_offdiag_slot.assign(static_cast<std::size_t>(18 * sys.spring_count()), -1);
  for (int s = 0; s < sys.spring_count(); ++s) {
    const int fi = m_free_index[sys.springs(s, 0)], fj = m_free_index[sys.springs(s, 1)];
    if (fi >= 0 && fj >= 0) {
      block_slots(fi, fj, &m_offdiag_slot[18 * s]);
      block_slots(fj, fi, &m_offdiag_slot[18 * s + 9]);
    }
  }
  m_ldlt.analyzePattern(m_matrix); // symbolic analysis once per scene
  m_flat_rhs.resize(3 * free);
  m_flat_solution.resize(3 * free);
}

void ImplicitLearnedSimulator::compute_spring_terms(const SpringState& state) {
  const double h = m_dt;
  detail::parallel_blocks(m_system.spring_count(), [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      const detail::SpringFrame fr = detail::spring_frame(m_system, state.x, state.v, s);
      double f = 0.0, f_e = 0.0, f_v = 0.0;
      m_spring.force_slopes(fr.e, fr.rate, f, f_e, f_v);
      const double a = std::max(-f_e, 0.0);
      const double b = fr.length > 0.0 ? std::max(-f / fr.length, 0.0) : 0.0;
      const double d = std::max(-f_v, 0.0);
      m_u.row(s) = fr.u.transpose();
      m_force[s] = f;
      m_a[s] = a;
      m_b[s] = b;
      m_alpha[s] = h * d + h * h * a;
      m_beta[s] = h * h * b;
    }
  });
}

void ImplicitLearnedSimulator::build_rhs(const SpringState& state) {
  const SpringSystem& sys = m_system;
  const double h = m_dt;
  detail::parallel_blocks(sys.node_count(), [&](int begin, int end) {
    for (int a = begin; a < end; ++a) {
      if (sys.pinned[a]) {
        m_rhs.row(a).setZero();
        continue;
      }
      Vec3 force = Vec3::Zero(), kv = Vec3::Zero();
      Mat3 diag = sys.masses[a] * Mat3::Identity();
      for (int p = sys.incident_offsets[a]; p < sys.incident_offsets[a + 1]; ++p) {
        const int s = sys.incident[p];
        const bool first = sys.springs(s, 0) == a;
        const int other = sys.springs(s, first ? 1 : 0);
        const Vec3 u = m_u.row(s).transpose();
        force += (first ? m_force[s] : -m_force[s]) * u;
        const Vec3 dv = (state.v.row(a) - state.v.row(other)).transpose();
        const double along = u.dot(dv);
        kv += m_a[s] * along * u + m_b[s] * (dv - along * u);
        diag += m_beta[s] * Mat3::Identity() + (m_alpha[s] - m_beta[s]) * u * u.transpose();
      }
      const Vec3 external = m_external.row(a).transpose() + sys.masses[a] * m_gravity;
      m_rhs.row(a) = (h * (force + external) - h * h * kv).transpose();
      m_diag_inverse[a] = diag.inverse();
      if (m_direct) {
        const int* slots = &m_diag_slot[9 * a];
        for (int k = 0; k < 9; ++k)
          m_matrix.valuePtr()[slots[k]] = diag(k / 3, k % 3);
      }
    }
  });
}

void ImplicitLearnedSimulator::apply(const Positions& x, Positions& y) const {
  const SpringSystem& sys = m_system;
  detail::parallel_blocks(sys.node_count(), [&](int begin, int end) {
    for (int a = begin; a < end; ++a) {
      if (sys.pinned[a]) {
        y.row(a).setZero();
        continue;
      }
      const Vec3 xa = x.row(a).transpose();
      Vec3 sum = sys.masses[a] * xa;
      for (int p = sys.incident_offsets[a]; p < sys.incident_offsets[a + 1]; ++p) {
        const int s = sys.incident[p];
        const int other = sys.springs(s, sys.springs(s, 0) == a ? 1 : 0);
        const Vec3 u = m_u.row(s).transpose();
        const Vec3 d = xa - x.row(other).transpose(); // pinned rows of x are zero
        sum += m_beta[s] * d + (m_alpha[s] - m_beta[s]) * u.dot(d) * u;
      }
      y.row(a) = sum.transpose();
    }
  });
}

void ImplicitLearnedSimulator::solve_direct() {
  const SpringSystem& sys = m_system;
  detail::parallel_blocks(sys.spring_count(), [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      const int* slots = &m_offdiag_slot[18 * s];
      if (slots[0] < 0)
        continue;
      const Vec3 u = m_u.row(s).transpose();
      const Mat3 block
          = -(m_beta[s] * Mat3::Identity() + (m_alpha[s] - m_beta[s]) * u * u.transpose());
      for (int k = 0; k < 9; ++k) {
        m_matrix.valuePtr()[slots[k]] = block(k / 3, k % 3);
        m_matrix.valuePtr()[slots[9 + k]] = block(k % 3, k / 3);
      }
    }
  });
  m_ldlt.factorize(m_matrix);
  ELASTOLEARN_CHECK(m_ldlt.info() == Eigen::Success,
      "implicit step: factorisation of the SPD system matrix failed");
  for (int a = 0; a < sys.node_count(); ++a)
    if (m_free_index[a] >= 0)
      m_flat_rhs.segment<3>(3 * m_free_index[a]) = m_rhs.row(a).transpose();
  m_flat_solution = m_ldlt.solve(m_flat_rhs);
  for (int a = 0; a < sys.node_count(); ++a) {
    if (m_free_index[a] >= 0)
      m_dv.row(a) = m_flat_solution.segment<3>(3 * m_free_index[a]).transpose();
    else
      m_dv.row(a).setZero();
  }
  m_stats = { true, 0, 0.0, true };
}

void ImplicitLearnedSimulator::solve_cg() {
  // Preconditioned CG on A Δv = b, warm-started from the previous step's Δv (kept in m_dv).
  const SpringSystem& sys = m_system;
  const int n = sys.node_count();
  auto precondition = [&](const Positions& r, Positions& z) {
    detail::parallel_blocks(n, [&](int begin, int end) {
      for (int a = begin; a < end; ++a) {
        if (sys.pinned[a])
          z.row(a).setZero();
        else
          z.row(a) = (m_diag_inverse[a] * r.row(a).transpose()).transpose();
      }
    });
  };
  const double b_norm = std::sqrt(dot(m_rhs, m_rhs));
  apply(m_dv, m_q);
  m_r = m_rhs - m_q;
  precondition(m_r, m_z);
  m_p = m_z;
  double rz = dot(m_r, m_z);
  double r_norm = std::sqrt(dot(m_r, m_r));
  const double target = m_options.cg_tolerance * b_norm;
  int it = 0;
  while (r_norm > target && it < m_options.cg_max_iterations) {
    apply(m_p, m_q);
    const double alpha = rz / dot(m_p, m_q);
    m_dv += alpha * m_p;
    m_r -= alpha * m_q;
    r_norm = std::sqrt(dot(m_r, m_r));
    ++it;
    if (r_norm <= target)
      break;
    precondition(m_r, m_z);
    const double rz_new = dot(m_r, m_z);
    m_p = m_z + (rz_new / rz) * m_p;
    rz = rz_new;
  }
  m_stats = { false, it, b_norm > 0.0 ? r_norm / b_norm : 0.0, r_norm <= target };
}

void ImplicitLearnedSimulator::step(SpringState& state) {
  const SpringSystem& sys = m_system;
  compute_spring_terms(state);
  build_rhs(state);
  if (dot(m_rhs, m_rhs) == 0.0) {
    m_dv.setZero(); // exactly at a static equilibrium: nothing moves
    m_stats = { m_direct, 0, 0.0, true };
  } else if (m_direct) {
    solve_direct();
  } else {
    solve_cg();
  }
  detail::parallel_blocks(sys.node_count(), [&](int begin, int end) {
    for (int a = begin; a < end; ++a) {
      if (sys.pinned[a]) {
        state.v.row(a).setZero();
        continue;
      }
      state.v.row(a) += m_dv.row(a);
      state.x.row(a) += m_dt * state.v.row(a);
    }
  });
}

} // namespace elastolearn::springs
