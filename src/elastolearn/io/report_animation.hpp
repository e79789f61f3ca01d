#pragma once
/// \file The surface motion a learning report animates in the browser (report.html, WebGL): the
/// rest mesh's boundary triangles and, per shown frame, the positions of its surface vertices for
/// each model ("truth", "learned", ...), plus optional marker points (observed vertices). Frames
/// are decimated to a budget so that the HTML stays small (docs/report.md, "Animation").
#include <elastolearn/core/types.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace elastolearn::io {

/// One animated object: a surface (the mesh's boundary, in the animation's surface vertex order)
/// or a set of points.
struct AnimationTrack {
  std::string label;
  bool points = false; ///< markers instead of the surface
  int count = 0; ///< vertices (surface) or points per frame
  /// frames × count × 3 coordinates [m], single precision (what WebGL draws).
  std::vector<float> positions;
};

struct SurfaceAnimation {
  std::vector<int> faces; ///< boundary triangles, flat, indices into the surface vertex order
  int frames = 0; ///< frames shown (after decimation)
  int stride = 1; ///< every stride-th simulated frame is shown
  double frame_seconds = 0; ///< simulated time between shown frames [s]
  std::vector<AnimationTrack> tracks;
};

/// Limits of an animation: at most `max_frames` frames and `max_values` coordinates in all tracks.
struct AnimationBudget {
  int max_frames = 150;
  long max_values = 600000; ///< 2.4 MB of floats, 3.2 MB of base64 in the HTML
};

/// A flat-trajectory model to animate: frames (flat 3n, frame 0 = initial state) of `mesh`.
struct AnimatedRun {
  std::string label;
  const std::vector<VecX>* frames = nullptr;
};

/// The animation of `runs` (surfaces, each frames of `mesh`) and, if `markers` is not null, the
/// marker positions (k×3 per frame, the same dt; e.g. an observation's positions) as points
/// labelled `markers_label`. Frames are taken every `stride`-th, the smallest stride that meets
/// `budget`; all tracks show the frames every run (and the markers) has. Nothing (std::nullopt)
/// when even two frames exceed the budget. Throws InputError("report animation", ...) if a run
/// has no frames or a frame is not 3n long.
std::optional<SurfaceAnimation> surface_animation(const mesh::TetMesh& mesh, double dt,
    const std::vector<AnimatedRun>& runs, const std::vector<Positions>* markers = nullptr,
    const std::string& markers_label = "observed", const AnimationBudget& budget = {});

/// JSON for the viewer: {"faces": [...], "frames", "stride", "frame_seconds", "tracks":
/// [{"label", "points", "count", "positions": base64 of little-endian float32}]}.
nlohmann::json animation_to_json(const SurfaceAnimation& animation);

} // namespace elastolearn::io
