#pragma once
/// \file The virtual depth scanner (paper 000 §7, Fig. 8's "point cloud" case; DESIGN.md
/// "Observations and point clouds"): depth cameras ray-cast the deformed surface of a frame and
/// return the points they see, with depth noise and optional outliers — the stand-in for a Kinect
/// capture of a real object.
///
/// Per camera and pixel: the first surface hit along the pixel's ray with depth in
/// [near, far]; a pixel whose first hit is a back face (the camera inside the object, or the
/// back of an open surface) returns nothing, since the face hides what is behind it. A returned
/// point lies on the pixel's ray at depth z + ε, ε ~ N(0, σ²) (depth noise along the ray, as
/// structured-light and time-of-flight sensors have it). With probability `outlier_fraction`
/// the pixel returns an outlier instead: a point on its ray at a depth drawn uniformly in
/// [near, z] — a spurious return in the line of sight (dust, mixed pixels). Points are ordered by
/// camera (as given), then row, then column.
///
/// Random numbers come from a counter-based generator keyed by (seed, frame, camera, pixel), so a
/// scan is the same for a given seed whatever the number of threads and whichever frames are
/// scanned. Pixels are ray-cast in parallel (oneTBB, by image rows).
#include <elastolearn/capture/depth_camera.hpp>
#include <elastolearn/capture/point_cloud.hpp>
#include <elastolearn/capture/ray_caster.hpp>

#include <elastolearn/core/progress.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace elastolearn::capture {

struct ScanOptions {
  double noise = 0; ///< σ [m]: standard deviation of the depth noise, ≥ 0
  double outlier_fraction = 0; ///< probability that a seen pixel returns an outlier, in [0, 1]
  std::uint64_t seed = 1;
  bool normals = false; ///< also return the unit normal of the face each point was seen on

  /// Throws InputError("scan.<field>", ...) for a negative or non-finite noise or a fraction
  /// outside [0, 1].
  void validate() const;
};

/// A noise-free depth image of one camera: depth z [m] per pixel (row v, column u), NaN where the
/// pixel sees nothing (no hit, a back face, or outside [near, far]), and the face seen (−1 where
/// nothing).
struct DepthImage {
  Eigen::MatrixXd depth; ///< height × width
  Eigen::MatrixXi face; ///< height × width
};

class VirtualScanner {
  public:
  /// Precompute the ray-casting structure of a surface (f×3 outward-oriented faces, vertex
  /// indices in [0, num_vertices)). Throws InputError for invalid cameras (validated with source
  /// "camera '<name>'"), options, or faces.
  VirtualScanner(const Faces& faces, int num_vertices, std::vector<DepthCamera> cameras,
      const ScanOptions& options);

  /// Move the surface to `x` (num_vertices × 3 [m]); every later scan and depth image sees it.
  void update(ConstRef<Positions> x);

  /// The points every camera sees of the current surface; `frame` keys the random numbers.
  CloudFrame scan(long frame);

  /// The noise-free depth image of camera `camera` of the current surface.
  DepthImage depth_image(int camera) const;

  const std::vector<DepthCamera>& cameras() const { return m_cameras; }
  /// Pixels over all cameras (rays per scan).
  long long num_pixels() const;

  private:
  /// Ray-cast camera `c` into `image` (sized already).
  void render(int c, DepthImage& image) const;

  SurfaceRayCaster m_caster;
  std::vector<DepthCamera> m_cameras;
  ScanOptions m_options;
  std::vector<DepthImage> m_images; ///< one per camera, reused across frames
};

/// Scan every frame of a motion (frames[t]: num_vertices × 3 [m]) and hand each cloud to
/// `sink(t, cloud)` in frame order; `progress` (optional) is told after each frame. Throws
/// InputError("scan", ...) when an interrupt (Ctrl-C) is requested between frames, and whatever
/// update() or the sink throws.
void scan_frames(VirtualScanner& scanner, const std::vector<Positions>& frames,
    const std::function<void(long frame, const CloudFrame& cloud)>& sink,
    const ProgressCallback& progress = {});

} // namespace elastolearn::capture
