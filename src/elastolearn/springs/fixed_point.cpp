#include <elastolearn/springs/fixed_point.hpp>

#include <elastolearn/core/error.hpp>

#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>

namespace elastolearn::springs {

void FixedPointOptions::validate() const {
  if (max_iterations < 1)
    throw InputError("fixed point.max_iterations", "must be >= 1");
  if (!(tolerance > 0.0))
    throw InputError("fixed point.tolerance", "must be > 0");
  if (!(fd_step > 0.0))
    throw InputError("fixed point.fd_step", "must be > 0");
  if (!components[0] && !components[1] && !components[2])
    throw InputError("fixed point.components", "at least one component must be active");
}

namespace {

/// The unknowns: (node, component, kind) with kind 0 = position, 1 = velocity.
struct Unknowns {
  std::vector<int> node, comp, kind;
  std::vector<int> first; // per node: index of its first unknown or −1
  int per_node = 0;
  int size() const { return static_cast<int>(node.size()); }
};

Unknowns make_unknowns(const SpringSystem& sys, const std::array<bool, 3>& components) {
  Unknowns u;
  u.first.assign(static_cast<std::size_t>(sys.node_count()), -1);
  for (int kind = 0; kind < 2; ++kind)
    for (int c = 0; c < 3; ++c)
      u.per_node += components[c] ? 1 : 0;
  for (int a = 0; a < sys.node_count(); ++a) {
    if (sys.pinned[a])
      continue;
    u.first[a] = u.size();
    for (int kind = 0; kind < 2; ++kind)
      for (int c = 0; c < 3; ++c)
        if (components[c]) {
          u.node.push_back(a);
          u.comp.push_back(c);
          u.kind.push_back(kind);
        }
  }
  return u;
}

double& entry(SpringState& s, const Unknowns& u, int k) {
  return u.kind[k] == 0 ? s.x(u.node[k], u.comp[k]) : s.v(u.node[k], u.comp[k]);
}

/// G(s) = Φ(s) − s, scaled: position rows by 1/ℓ, velocity rows by dt/ℓ.
VecX residual(SpringStepper& stepper, const SpringState& s, const Unknowns& u, double ell) {
  SpringState next = s;
  stepper.step(next);
  VecX g(u.size());
  for (int k = 0; k < u.size(); ++k) {
    const double scale = u.kind[k] == 0 ? 1.0 / ell : stepper.dt() / ell;
    g[k] = (u.kind[k] == 0 ? next.x(u.node[k], u.comp[k]) - s.x(u.node[k], u.comp[k])
                           : next.v(u.node[k], u.comp[k]) - s.v(u.node[k], u.comp[k]))
        * scale;
  }
  return g;
}

/// Greedy distance-2 colouring of the spring graph (nodes sharing a neighbour differ in colour).
std::vector<int> distance2_colouring(const SpringSystem& sys, int& colours) {
  const int n = sys.node_count();
  auto neighbour = [&](int a, int p) {
    const int s = sys.incident[p];
    return sys.springs(s, sys.springs(s, 0) == a ? 1 : 0);
  };
  std::vector<int> colour(static_cast<std::size_t>(n), -1);
  std::vector<int> mark;
  colours = 0;
  for (int a = 0; a < n; ++a) {
    mark.assign(static_cast<std::size_t>(colours + 1), 0);
    for (int p = sys.incident_offsets[a]; p < sys.incident_offsets[a + 1]; ++p) {
      const int b = neighbour(a, p);
      if (colour[b] >= 0)
        mark[colour[b]] = 1;
      for (int q = sys.incident_offsets[b]; q < sys.incident_offsets[b + 1]; ++q) {
        const int c = neighbour(b, q);
        if (colour[c] >= 0)
          mark[colour[c]] = 1;
      }
    }
    int col = 0;
    while (mark[col])
      ++col;
    colour[a] = col;
    colours = std::max(colours, col + 1);
  }
  return colour;
}

} // namespace

FixedPointResult solve_fixed_point(
    SpringStepper& stepper, SpringState& state, const FixedPointOptions& options) {
  options.validate();
  const SpringSystem& sys = stepper.system();
  const Unknowns u = make_unknowns(sys, options.components);
  FixedPointResult result;
  if (u.size() == 0) {
    result.converged = true;
    result.message = "no free unknowns";
    return result;
  }
  const double ell = 1.0 + state.x.cwiseAbs().maxCoeff();
  const double dt = stepper.dt();
  int colours = 0;
  const std::vector<int> colour
      = stepper.is_local() ? distance2_colouring(sys, colours) : std::vector<int>();
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;

  VecX g = residual(stepper, state, u, ell);
  double norm = g.cwiseAbs().maxCoeff();
  for (int it = 0; it < options.max_iterations && norm > options.tolerance; ++it) {
    result.iterations = it + 1;
    // Jacobian of G by forward differences, in unknown-groups that do not interact.
    std::vector<Eigen::Triplet<double>> triplets;
    auto add_columns = [&](const std::vector<int>& group) {
      SpringState perturbed = state;
      for (int k : group)
        entry(perturbed, u, k) += options.fd_step * (u.kind[k] == 0 ? ell : ell / dt);
      const VecX gp = residual(stepper, perturbed, u, ell);
      for (int k : group) {
        const double h = options.fd_step * (u.kind[k] == 0 ? ell : ell / dt);
        if (colour.empty()) {
          for (int r = 0; r < u.size(); ++r)
            if (gp[r] != g[r])
              triplets.emplace_back(r, k, (gp[r] - g[r]) / h);
          continue;
        }
        // Rows of node k's closed neighbourhood belong to column k alone (distance-2 colouring).
        const int a = u.node[k];
        auto add_rows_of = [&](int b) {
          if (u.first[b] < 0)
            return;
          for (int r = u.first[b]; r < u.first[b] + u.per_node; ++r)
            triplets.emplace_back(r, k, (gp[r] - g[r]) / h);
        };
        add_rows_of(a);
        for (int p = sys.incident_offsets[a]; p < sys.incident_offsets[a + 1]; ++p) {
          const int s = sys.incident[p];
          add_rows_of(sys.springs(s, sys.springs(s, 0) == a ? 1 : 0));
        }
      }
    };
    if (colour.empty()) {
      for (int k = 0; k < u.size(); ++k)
        add_columns({ k });
    } else {
      for (int col = 0; col < colours; ++col)
        for (int slot = 0; slot < u.per_node; ++slot) {
          std::vector<int> group;
          for (int a = 0; a < sys.node_count(); ++a)
            if (colour[a] == col && u.first[a] >= 0)
              group.push_back(u.first[a] + slot);
          if (!group.empty())
            add_columns(group);
        }
    }
    Eigen::SparseMatrix<double> jac(u.size(), u.size());
    jac.setFromTriplets(triplets.begin(), triplets.end());
    jac.makeCompressed();
    lu.compute(jac);
    if (lu.info() != Eigen::Success) {
      result.message = "singular Jacobian of the step map at iteration " + std::to_string(it + 1);
      break;
    }
    const VecX delta = lu.solve(g);
    // Backtracking: accept the first step length that reduces ‖G‖∞.
    bool accepted = false;
    for (double t = 1.0; t > 1e-4; t *= 0.5) {
      SpringState trial = state;
      for (int k = 0; k < u.size(); ++k)
        entry(trial, u, k) -= t * delta[k]; // J is taken w.r.t. the physical unknowns
      const VecX gt = residual(stepper, trial, u, ell);
      const double nt = gt.allFinite() ? gt.cwiseAbs().maxCoeff() : INFINITY;
      if (nt < norm) {
        state = std::move(trial);
        g = gt;
        norm = nt;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      result.message = "Newton stalled at residual " + std::to_string(norm);
      break;
    }
  }
  result.residual = norm;
  result.converged = norm <= options.tolerance;
  if (result.converged)
    result.message = "converged";
  else if (result.message.empty())
    result.message = "iteration limit reached";
  return result;
}

} // namespace elastolearn::springs
