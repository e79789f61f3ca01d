#pragma once
/// \file The box of sorted principal stretches s₁ ≥ s₂ ≥ s₃ that a trajectory visits. A learned
/// correction records the one of its training motion (the material file's "training_stretches"):
/// outside it the correction extrapolates, and simulate / evaluate say so.
#include <elastolearn/core/types.hpp>

#include <limits>

namespace elastolearn::material {

struct StretchRange {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity()); ///< least s₁, s₂, s₃ [-]
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity()); ///< greatest s₁, s₂, s₃ [-]

  /// True until a sample is included.
  bool empty() const { return !(min.array() <= max.array()).all(); }
  /// Widen to the sorted stretches `s` (s₁ ≥ s₂ ≥ s₃).
  void include(const Vec3& s) {
    min = min.cwiseMin(s);
    max = max.cwiseMax(s);
  }
  void include(const StretchRange& other) {
    min = min.cwiseMin(other.min);
    max = max.cwiseMax(other.max);
  }
  /// True if every sorted stretch of `s` lies in the box widened by `tolerance` on each side.
  bool contains(const Vec3& s, double tolerance) const {
    return ((s.array() >= min.array() - tolerance) && (s.array() <= max.array() + tolerance)).all();
  }
};

} // namespace elastolearn::material
