#include <elastolearn/capture/cloud_index.hpp>

#include <nanoflann.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace elastolearn::capture {

namespace {

/// nanoflann's view of an N×3 row-major array.
struct PointsAdaptor {
  const Positions* points;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points->rows()); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return (*points)(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(dim));
  }
  template <class Box> bool kdtree_get_bbox(Box&) const { return false; }
};

using Tree
    = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor>,
        PointsAdaptor, 3, Eigen::Index>;

} // namespace

struct CloudIndex::Impl {
  Positions points;
  PointsAdaptor adaptor { &points };
  std::unique_ptr<Tree> tree; ///< null for an empty cloud
};

CloudIndex::CloudIndex(ConstRef<Positions> points)
    : m_impl(std::make_unique<Impl>()) {
  m_impl->points = points;
  m_impl->adaptor.points = &m_impl->points;
  if (points.rows() > 0) {
    m_impl->tree
        = std::make_unique<Tree>(3, m_impl->adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    m_impl->tree->buildIndex();
  }
}

CloudIndex::~CloudIndex() = default;
CloudIndex::CloudIndex(CloudIndex&&) noexcept = default;
CloudIndex& CloudIndex::operator=(CloudIndex&&) noexcept = default;

const Positions& CloudIndex::points() const {
  return m_impl->points;
}

void CloudIndex::within(
    const Vec3& query, double radius, std::vector<std::pair<Eigen::Index, double>>& out) const {
  out.clear();
  if (!m_impl->tree)
    return;
  nanoflann::SearchParams params;
  params.sorted = false;
  m_impl->tree->radiusSearch(query.data(), radius * radius, out, params);
  std::sort(out.begin(), out.end());
}

std::pair<Eigen::Index, double> CloudIndex::nearest(const Vec3& query) const {
  if (!m_impl->tree)
    return { -1, std::numeric_limits<double>::infinity() };
  Eigen::Index index = -1;
  double distance = 0;
  m_impl->tree->knnSearch(query.data(), 1, &index, &distance);
  return { index, distance };
}

double CloudIndex::median_spacing() const {
  const Eigen::Index n = size();
  if (n < 2)
    return 0;
  std::vector<double> nearest(static_cast<std::size_t>(n));
  tbb::parallel_for(Eigen::Index(0), n, [&](Eigen::Index i) {
    Eigen::Index index[2];
    double distance[2];
    const Vec3 p = m_impl->points.row(i).transpose();
    m_impl->tree->knnSearch(p.data(), 2, index, distance);
    // The nearest is the point itself (distance 0) unless a duplicate shares its place.
    nearest[static_cast<std::size_t>(i)] = std::sqrt(distance[1]);
  });
  const auto middle = nearest.begin() + n / 2;
  std::nth_element(nearest.begin(), middle, nearest.end());
  return *middle;
}

} // namespace elastolearn::capture
