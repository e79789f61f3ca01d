#include <elastolearn/observe/cloud_observation.hpp>

#include <elastolearn/capture/cloud_index.hpp>
#include <elastolearn/capture/correspondence.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>

#include <algorithm>
#include <cmath>

namespace elastolearn::observe {

namespace {

constexpr FieldErrors cloud_observation_error("cloud observation");

} // namespace

void CloudObservationOptions::validate() const {
  if (!(sigma > 0) || !std::isfinite(sigma))
    cloud_observation_error("sigma", "must be positive and finite [m], got " + to_text(sigma));
  if (!(truncation > 0 && truncation < 1))
    cloud_observation_error("truncation", "must be in (0, 1), got " + to_text(truncation));
  if (!(min_relative_weight > 0 && min_relative_weight <= 1))
    cloud_observation_error(
        "min_relative_weight", "must be in (0, 1], got " + to_text(min_relative_weight));
}

Observation observe_clouds(const std::vector<int>& vertex_ids,
    const std::vector<Positions>& positions, const capture::PointCloudSequence& clouds,
    const CloudObservationOptions& options) {
  options.validate();
  const int frames = clouds.num_frames();
  if (static_cast<int>(positions.size()) != frames)
    throw InputError("cloud observation",
        "the trajectory has " + to_text(positions.size()) + " frames, the clouds "
            + to_text(frames));
  if (vertex_ids.empty())
    throw InputError("cloud observation", "no vertex to observe");
  const Eigen::Index n = positions.front().rows();
  for (const int v : vertex_ids)
    if (v < 0 || v >= n)
      throw InputError("cloud observation",
          "vertex id " + to_text(v) + " is outside the mesh's " + to_text(n) + " vertices");
  const int k = static_cast<int>(vertex_ids.size());

  Observation observed;
  observed.vertex_ids = vertex_ids;
  observed.dt = clouds.dt;
  observed.start_time = clouds.start_time;
  observed.valid = ValidityMask::Zero(frames, k);
  observed.positions.resize(static_cast<size_t>(frames));
  capture::CorrespondenceOptions pairing;
  pairing.sigma = options.sigma;
  pairing.truncation = options.truncation;
  Positions at(k, 3);
  VecX weight(k);
  std::vector<double> nonzero;
  for (int t = 0; t < frames; ++t) {
    const Positions& x = positions[static_cast<size_t>(t)];
    if (x.rows() != n)
      throw InputError("cloud observation",
          "frame " + to_text(t) + " has " + to_text(x.rows()) + " vertices, frame 0 " + to_text(n));
    for (int j = 0; j < k; ++j)
      at.row(j) = x.row(vertex_ids[static_cast<size_t>(j)]);
    observed.positions[static_cast<size_t>(t)] = at;
    const capture::CloudIndex cloud(clouds.frame_points(t));
    const auto pairs = capture::find_correspondences(cloud, at, pairing);
    weight.setZero();
    for (const capture::Correspondence& c : pairs)
      weight[c.sample] += c.weight;
    nonzero.clear();
    for (int j = 0; j < k; ++j)
      if (weight[j] > 0)
        nonzero.push_back(weight[j]);
    if (nonzero.empty())
      continue;
    const auto middle = nonzero.begin() + static_cast<std::ptrdiff_t>(nonzero.size() / 2);
    std::nth_element(nonzero.begin(), middle, nonzero.end());
    const double threshold = options.min_relative_weight * *middle;
    for (int j = 0; j < k; ++j)
      if (weight[j] > 0 && weight[j] >= threshold)
        observed.valid(t, j) = 1;
  }
  if (observed.num_valid() == 0)
    throw InputError("cloud observation",
        "no surface vertex has cloud points within reach in any frame (σ = "
            + to_text(options.sigma)
            + " m): do the clouds and the scene share a frame of reference?");
  return observed;
}

} // namespace elastolearn::observe
