#include <elastolearn/core/base64.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/report_animation.hpp>

#include <algorithm>
#include <bit>
#include <limits>
#include <span>

namespace elastolearn::io {

std::optional<SurfaceAnimation> surface_animation(const mesh::TetMesh& mesh, double dt,
    const std::vector<AnimatedRun>& runs, const std::vector<Positions>* markers,
    const std::string& markers_label, const AnimationBudget& budget) {
  const std::vector<int>& surface = mesh.surface_vertices();
  const int n = mesh.num_vertices();
  std::size_t available = std::numeric_limits<std::size_t>::max();
  for (const AnimatedRun& run : runs) {
    if (!run.frames || run.frames->empty())
      throw InputError("report animation", "the " + run.label + " run has no frames");
    for (const VecX& x : *run.frames) {
      if (x.size() != 3 * Eigen::Index(n)) {
        throw InputError("report animation",
            "a frame of the " + run.label + " run has " + std::to_string(x.size())
                + " coordinates, the mesh " + std::to_string(3 * n));
      }
    }
    available = std::min(available, run.frames->size());
  }
  long per_frame = 3L * long(surface.size()) * long(runs.size());
  if (markers && !markers->empty()) {
    available = std::min(available, markers->size());
    per_frame += 3L * long(markers->front().rows());
  }
  if (available == std::numeric_limits<std::size_t>::max() || per_frame == 0)
    throw InputError("report animation", "nothing to animate");
  if (2 * per_frame > budget.max_values)
    return std::nullopt;
  const auto total = static_cast<long>(available);
  const long frames_allowed = std::min<long>(budget.max_frames, budget.max_values / per_frame);
  // The smallest stride that shows at most frames_allowed of the available frames.
  const long stride = std::max<long>(1, (total + frames_allowed - 1) / frames_allowed);
  SurfaceAnimation out;
  out.stride = static_cast<int>(stride);
  out.frames = static_cast<int>((total + stride - 1) / stride);
  out.frame_seconds = dt * double(stride);

  std::vector<int> index_of(static_cast<std::size_t>(n), -1);
  for (std::size_t i = 0; i < surface.size(); ++i)
    index_of[static_cast<std::size_t>(surface[i])] = static_cast<int>(i);
  const Faces& faces = mesh.surface_faces();
  out.faces.reserve(static_cast<std::size_t>(faces.size()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    for (int c = 0; c < 3; ++c)
      out.faces.push_back(index_of[static_cast<std::size_t>(faces(f, c))]);
  }

  for (const AnimatedRun& run : runs) {
    AnimationTrack track { run.label, false, static_cast<int>(surface.size()), {} };
    track.positions.reserve(static_cast<std::size_t>(out.frames) * surface.size() * 3);
    for (long t = 0; t < total; t += stride) {
      const VecX& x = (*run.frames)[static_cast<std::size_t>(t)];
      for (int v : surface) {
        for (int c = 0; c < 3; ++c)
          track.positions.push_back(static_cast<float>(x[3 * v + c]));
      }
    }
    out.tracks.push_back(std::move(track));
  }
  if (markers && !markers->empty()) {
    const auto count = static_cast<int>(markers->front().rows());
    AnimationTrack track { markers_label, true, count, {} };
    for (long t = 0; t < total; t += stride) {
      const Positions& p = (*markers)[static_cast<std::size_t>(t)];
      for (int j = 0; j < count; ++j) {
        for (int c = 0; c < 3; ++c)
          track.positions.push_back(static_cast<float>(p(j, c)));
      }
    }
    out.tracks.push_back(std::move(track));
  }
  return out;
}

nlohmann::json animation_to_json(const SurfaceAnimation& animation) {
  static_assert(std::endian::native == std::endian::little,
      "the viewer reads the positions as little-endian Float32Array");
  nlohmann::json tracks = nlohmann::json::array();
  for (const AnimationTrack& t : animation.tracks) {
    tracks.push_back({ { "label", t.label }, { "points", t.points }, { "count", t.count },
        { "positions", base64_encode(std::as_bytes(std::span(t.positions))) } });
  }
  return { { "faces", animation.faces }, { "frames", animation.frames },
    { "stride", animation.stride }, { "frame_seconds", animation.frame_seconds },
    { "tracks", tracks } };
}

} // namespace elastolearn::io
