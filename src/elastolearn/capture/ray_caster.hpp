#pragma once
/// \file First hits of rays on a triangle surface whose vertices move from frame to frame,
/// through Embree 3's BVH (Debian's libembree-dev). The topology is given once; each update()
/// uploads new vertex positions and refits the BVH (its tree is built once, its boxes are
/// recomputed: O(faces), and the tree stays good for the moderate deformations of vibrating
/// solids). Embree traverses in single precision; the hit distance is then recomputed in double
/// against the hit triangle's plane, so depths are exact to double rounding wherever Embree picks
/// the right triangle.
#include <elastolearn/core/types.hpp>

#include <memory>

namespace elastolearn::capture {

/// The first triangle along a ray, or none (face = −1).
struct RayHit {
  int face = -1; ///< row of the faces array
  double t = 0; ///< ray parameter of the hit: the point is origin + t·direction
  Vec3 normal = Vec3::Zero(); ///< unit normal of the face, (x1 − x0) × (x2 − x0) normalised
};

class SurfaceRayCaster {
  public:
  /// `faces` f×3 vertex indices in [0, num_vertices), f ≥ 1. Throws InputError("surface", ...)
  /// for an index out of range or no faces; std::runtime_error if Embree cannot start.
  SurfaceRayCaster(const Faces& faces, int num_vertices);
  ~SurfaceRayCaster();
  SurfaceRayCaster(SurfaceRayCaster&&) noexcept;
  SurfaceRayCaster& operator=(SurfaceRayCaster&&) noexcept;
  SurfaceRayCaster(const SurfaceRayCaster&) = delete;
  SurfaceRayCaster& operator=(const SurfaceRayCaster&) = delete;

  /// Move the vertices to `x` (num_vertices × 3, finite [m]) and refit. Not thread safe.
  /// Throws InputError("surface", ...) for a wrong row count or non-finite positions.
  void update(ConstRef<Positions> x);

  /// The first hit with t in [t_min, t_max] of the ray origin + t·direction (direction need not
  /// be unit length). Thread safe between updates; call update() at least once first.
  RayHit first_hit(const Vec3& origin, const Vec3& direction, double t_min, double t_max) const;

  /// first_hit for `count` rays from one origin (directions[i] → out[i]), traced together as a
  /// coherent stream: Embree groups them into packets, which is faster for the neighbouring
  /// pixels of a camera. Thread safe between updates.
  void first_hits(const Vec3& origin, const Vec3* directions, int count, double t_min, double t_max,
      RayHit* out) const;

  int num_faces() const;
  /// Unit normal of face f at the current positions, (x1 − x0) × (x2 − x0) normalised (zero for a
  /// degenerate face).
  Vec3 face_normal(int f) const;

  private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

} // namespace elastolearn::capture
