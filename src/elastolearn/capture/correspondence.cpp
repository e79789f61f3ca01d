#include <elastolearn/capture/correspondence.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>

namespace elastolearn::capture {

namespace {

constexpr FieldErrors correspondence_error("correspondence");

/// Samples per parallel block: each block's pairs are collected apart and joined in block order,
/// so the result does not depend on how blocks are spread over threads.
constexpr int k_block = 256;

} // namespace

void CorrespondenceOptions::validate() const {
  if (!(sigma > 0) || !std::isfinite(sigma))
    correspondence_error("sigma",
        "must be positive and finite (the scanner's accuracy in metres), got " + to_text(sigma));
  if (!(truncation > 0 && truncation < 1))
    correspondence_error("truncation", "must be in (0, 1), got " + to_text(truncation));
}

double CorrespondenceOptions::radius() const {
  return sigma * std::sqrt(-2.0 * std::log(truncation));
}

std::vector<Correspondence> find_correspondences(const CloudIndex& cloud,
    ConstRef<Positions> sample_positions, const CorrespondenceOptions& options) {
  options.validate();
  const int K = static_cast<int>(sample_positions.rows());
  if (cloud.size() == 0 || K == 0)
    return {};
  const double radius = options.radius();
  const double inv_two_sigma2 = 0.5 / (options.sigma * options.sigma);
  const double peak = std::pow(2 * std::numbers::pi * options.sigma * options.sigma, -1.5);
  const int blocks = (K + k_block - 1) / k_block;
  std::vector<std::vector<Correspondence>> found(static_cast<std::size_t>(blocks));
  tbb::enumerable_thread_specific<std::vector<std::pair<Eigen::Index, double>>> buffers;
  tbb::parallel_for(0, blocks, [&](int b) {
    auto& matches = buffers.local();
    auto& out = found[static_cast<std::size_t>(b)];
    for (int k = b * k_block; k < std::min(K, (b + 1) * k_block); ++k) {
      cloud.within(sample_positions.row(k).transpose(), radius, matches);
      for (const auto& [n, d2] : matches) {
        const double g = std::exp(-d2 * inv_two_sigma2);
        if (g >= options.truncation)
          out.push_back({ k, n, peak * g });
      }
    }
  });
  std::size_t total = 0;
  for (const auto& block : found)
    total += block.size();
  std::vector<Correspondence> pairs;
  pairs.reserve(total);
  for (const auto& block : found)
    pairs.insert(pairs.end(), block.begin(), block.end());
  if (options.normalize_per_point) {
    VecX sum = VecX::Zero(cloud.size());
    for (const Correspondence& c : pairs)
      sum[c.point] += c.weight;
    for (Correspondence& c : pairs)
      c.weight /= sum[c.point];
  }
  return pairs;
}

double correspondence_energy(const SurfaceSamples& samples, ConstRef<Positions> x,
    ConstRef<Positions> cloud, const std::vector<Correspondence>& pairs, double sigma,
    Positions* gradient) {
  const double inv_sigma2 = 1.0 / (sigma * sigma);
  Positions s;
  samples.positions(x, s);
  // ∂E/∂s_k = −Σ_n p_kn (c_n − s_k) / σ², accumulated per sample, then spread to the vertices.
  Positions per_sample;
  if (gradient)
    per_sample.setZero(s.rows(), 3);
  double energy = 0;
  for (const Correspondence& c : pairs) {
    const Eigen::RowVector3d r = cloud.row(c.point) - s.row(c.sample);
    energy += 0.5 * c.weight * inv_sigma2 * r.squaredNorm();
    if (gradient)
      per_sample.row(c.sample) -= c.weight * inv_sigma2 * r;
  }
  if (gradient) {
    gradient->setZero(x.rows(), 3);
    samples.scatter(per_sample, *gradient);
  }
  return energy;
}

Eigen::SparseMatrix<double> correspondence_hessian(const SurfaceSamples& samples, int num_vertices,
    const std::vector<Correspondence>& pairs, double sigma) {
  VecX total = VecX::Zero(samples.num_samples());
  for (const Correspondence& c : pairs)
    total[c.sample] += c.weight / (sigma * sigma);
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < samples.num_samples(); ++k) {
    if (total[k] == 0)
      continue;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double w = total[k] * samples.weights(k, i) * samples.weights(k, j);
        if (w != 0)
          entries.emplace_back(samples.vertices(k, i), samples.vertices(k, j), w);
      }
  }
  Eigen::SparseMatrix<double> H(num_vertices, num_vertices);
  H.setFromTriplets(entries.begin(), entries.end());
  return H;
}

} // namespace elastolearn::capture
