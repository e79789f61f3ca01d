#pragma once
/// \file Per-spring geometry and node gathers shared by every simulator of this layer. These
/// kernels know no force law: the reference simulator passes its `SpringLaw`, the learned ones
/// their `LearnedSpring`. Parallel with oneTBB above a size threshold; no allocation.
#include <elastolearn/springs/spring_system.hpp>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

namespace elastolearn::springs::detail {

/// Problems smaller than this run serially (TBB's overhead would dominate).
inline constexpr int k_parallel_threshold = 4096;

/// Run fn(begin, end) over [0, n): in parallel chunks of `grain` when n ≥ k_parallel_threshold.
template <class Fn> void parallel_blocks(int n, Fn&& fn, int grain = 1024) {
  if (n < k_parallel_threshold) {
    fn(0, n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n, grain),
      [&](const tbb::blocked_range<int>& r) { fn(r.begin(), r.end()); });
}

/// A spring in its 1-D training frame (paper Fig. 1): unit direction u = (x_i − x_j)/L from
/// node j to node i, length L, elongation e = L − l, elongation rate (v_i − v_j)·u.
struct SpringFrame {
  Vec3 u;
  double length;
  double e;
  double rate;
};

/// Frame of spring s = (i, j) at positions x, velocities v. A zero-length spring gets u = 0.
inline SpringFrame spring_frame(
    const SpringSystem& sys, const Positions& x, const Positions& v, int s) {
  const int i = sys.springs(s, 0), j = sys.springs(s, 1);
  const Vec3 d = x.row(i) - x.row(j);
  const double length = d.norm();
  const Vec3 u = length > 0.0 ? Vec3(d / length) : Vec3::Zero();
  return { u, length, length - sys.rest_lengths[s], (v.row(i) - v.row(j)).dot(u) };
}

/// Per-spring scalar force along u (on node i; node j gets the opposite): out.row(s) = f_s u_s.
template <class ForceFn>
void spring_forces(const SpringSystem& sys, const Positions& x, const Positions& v, ForceFn&& force,
    Positions& out) {
  parallel_blocks(sys.spring_count(), [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      const SpringFrame fr = spring_frame(sys, x, v, s);
      out.row(s) = force(fr.e, fr.rate) * fr.u.transpose();
    }
  });
}

/// Signed sum over incident springs: node_out.row(a) = Σ_{s ∋ a} ±per_spring.row(s), + for the
/// spring's first node. If `average`, divide by the node's spring count (paper §6).
inline void gather(const SpringSystem& sys, const Positions& per_spring, Positions& node_out,
    bool average = false) {
  parallel_blocks(sys.node_count(), [&](int begin, int end) {
    for (int a = begin; a < end; ++a) {
      Vec3 sum = Vec3::Zero();
      for (int p = sys.incident_offsets[a]; p < sys.incident_offsets[a + 1]; ++p) {
        const int s = sys.incident[p];
        if (sys.springs(s, 0) == a)
          sum += per_spring.row(s).transpose();
        else
          sum -= per_spring.row(s).transpose();
      }
      if (average && sys.degree[a] > 0)
        sum /= sys.degree[a];
      node_out.row(a) = sum.transpose();
    }
  });
}

/// Semi-implicit Euler update of free nodes: v += dt (F/m + g + F_ext/m), x += dt v.
inline void semi_implicit_update(const SpringSystem& sys, const Positions& spring_node_forces,
    const Positions& external, const Vec3& gravity, double dt, SpringState& state) {
  parallel_blocks(sys.node_count(), [&](int begin, int end) {
    for (int a = begin; a < end; ++a) {
      if (sys.pinned[a]) {
        state.v.row(a).setZero();
        continue;
      }
      const double inv_m = 1.0 / sys.masses[a];
      state.v.row(a)
          += dt * ((spring_node_forces.row(a) + external.row(a)) * inv_m + gravity.transpose());
      state.x.row(a) += dt * state.v.row(a);
    }
  });
}

} // namespace elastolearn::springs::detail
