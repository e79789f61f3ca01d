#pragma once
/// \file A k-d tree (nanoflann) over one frame's cloud points, built once per frame and queried
/// every time the mesh moves (paper 000 §5.3: correspondences are recomputed as the optimisation
/// moves the mesh; the cloud stays where it is).
#include <elastolearn/core/types.hpp>

#include <memory>
#include <utility>
#include <vector>

namespace elastolearn::capture {

class CloudIndex {
  public:
  /// Copies the N×3 points (N ≥ 0, finite — a point-cloud sequence validates them) and builds the
  /// tree. An empty cloud gives an index that finds nothing.
  explicit CloudIndex(ConstRef<Positions> points);
  ~CloudIndex();
  CloudIndex(CloudIndex&&) noexcept;
  CloudIndex& operator=(CloudIndex&&) noexcept;
  CloudIndex(const CloudIndex&) = delete;
  CloudIndex& operator=(const CloudIndex&) = delete;

  const Positions& points() const;
  Eigen::Index size() const { return points().rows(); }

  /// Every point within `radius` of `query`, as (point index, squared distance), in `out`
  /// (cleared first; its capacity is reused), sorted by point index. Thread safe.
  void within(
      const Vec3& query, double radius, std::vector<std::pair<Eigen::Index, double>>& out) const;

  /// The point nearest to `query`, as (point index, squared distance); (−1, +∞) for an empty
  /// cloud. Thread safe.
  std::pair<Eigen::Index, double> nearest(const Vec3& query) const;

  /// Median distance from a point to its nearest other point [m] (0 with fewer than 2 points):
  /// the cloud's spacing, e.g. for subdivision_for_spacing. Parallel.
  double median_spacing() const;

  private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

} // namespace elastolearn::capture
