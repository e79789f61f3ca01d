#include <elastolearn/capture/virtual_scanner.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/core/interrupt.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace elastolearn::capture {

namespace {

constexpr FieldErrors scan_error("scan");

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// A counter-based stream of random numbers for one (seed, frame, camera, pixel): each draw
/// hashes the key with a counter, so no state is shared between pixels or threads.
class PixelRandom {
  public:
  PixelRandom(std::uint64_t seed, long frame, int camera, long long pixel)
      : m_key(splitmix64(splitmix64(splitmix64(seed) ^ static_cast<std::uint64_t>(frame))
                  ^ static_cast<std::uint64_t>(camera))
          ^ static_cast<std::uint64_t>(pixel)) { }
  /// Uniform in [0, 1).
  double uniform() {
    return static_cast<double>(splitmix64(m_key + ++m_counter) >> 11) * 0x1.0p-53;
  }
  /// Standard normal (Box–Muller).
  double normal() {
    const double u1 = 1.0 - uniform(); // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

  private:
  std::uint64_t m_key;
  std::uint64_t m_counter = 0;
};

} // namespace

void ScanOptions::validate() const {
  if (!std::isfinite(noise) || noise < 0)
    scan_error("noise", "must be finite and ≥ 0, got " + to_text(noise));
  if (!(outlier_fraction >= 0 && outlier_fraction <= 1))
    scan_error("outliers", "must be a fraction in [0, 1], got " + to_text(outlier_fraction));
}

VirtualScanner::VirtualScanner(const Faces& faces, int num_vertices,
    std::vector<DepthCamera> cameras, const ScanOptions& options)
    : m_caster(faces, num_vertices)
    , m_cameras(std::move(cameras))
    , m_options(options) {
  m_options.validate();
  if (m_cameras.empty())
    throw InputError("scan", "no cameras");
  for (const DepthCamera& camera : m_cameras) {
    camera.validate("camera '" + camera.name + "'");
    m_images.push_back({ Eigen::MatrixXd(camera.height, camera.width),
        Eigen::MatrixXi(camera.height, camera.width) });
  }
}

void VirtualScanner::update(ConstRef<Positions> x) {
  m_caster.update(x);
}

long long VirtualScanner::num_pixels() const {
  long long n = 0;
  for (const DepthCamera& camera : m_cameras)
    n += camera.num_pixels();
  return n;
}

void VirtualScanner::render(int c, DepthImage& image) const {
  const DepthCamera& camera = m_cameras[static_cast<std::size_t>(c)];
  const double nan = std::numeric_limits<double>::quiet_NaN();
  tbb::parallel_for(
      tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
        // A row at a time, in chunks: neighbouring pixels' rays are traced together.
        constexpr int chunk = 64;
        Vec3 d[chunk];
        RayHit hits[chunk];
        for (int v = rows.begin(); v < rows.end(); ++v) {
          for (int u0 = 0; u0 < camera.width; u0 += chunk) {
            const int n = std::min(chunk, camera.width - u0);
            for (int i = 0; i < n; ++i)
              d[i] = camera.pixel_ray(u0 + i, v);
            // d has unit component along the optical axis, so the ray parameter is the depth.
            m_caster.first_hits(camera.position, d, n, camera.near, camera.far, hits);
            for (int i = 0; i < n; ++i) {
              const bool seen = hits[i].face >= 0 && hits[i].normal.dot(d[i]) < 0;
              image.depth(v, u0 + i) = seen ? hits[i].t : nan;
              image.face(v, u0 + i) = seen ? hits[i].face : -1;
            }
          }
        }
      });
}

DepthImage VirtualScanner::depth_image(int camera) const {
  ELASTOLEARN_CHECK(camera >= 0 && camera < static_cast<int>(m_cameras.size()),
      "depth_image: camera index out of range");
  const DepthCamera& c = m_cameras[static_cast<std::size_t>(camera)];
  DepthImage image { Eigen::MatrixXd(c.height, c.width), Eigen::MatrixXi(c.height, c.width) };
  render(camera, image);
  return image;
}

CloudFrame VirtualScanner::scan(long frame) {
  // Rows of the output, camera by camera and image row by image row, fixed before the parallel
  // fill so that every pixel's point has its place whatever the threads do.
  std::vector<std::vector<Eigen::Index>> row_start(m_cameras.size());
  Eigen::Index seen = 0;
  for (std::size_t c = 0; c < m_cameras.size(); ++c) {
    render(static_cast<int>(c), m_images[c]);
    const Eigen::MatrixXi& face = m_images[c].face;
    row_start[c].resize(static_cast<std::size_t>(face.rows()));
    for (Eigen::Index v = 0; v < face.rows(); ++v) {
      row_start[c][static_cast<std::size_t>(v)] = seen;
      seen += (face.row(v).array() >= 0).count();
    }
  }
  CloudFrame out;
  out.points.resize(seen, 3);
  if (m_options.normals)
    out.normals.resize(seen, 3);
  for (std::size_t c = 0; c < m_cameras.size(); ++c) {
    const DepthCamera& camera = m_cameras[c];
    const DepthImage& image = m_images[c];
    tbb::parallel_for(
        tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
          for (int v = rows.begin(); v < rows.end(); ++v) {
            Eigen::Index row = row_start[c][static_cast<std::size_t>(v)];
            for (int u = 0; u < camera.width; ++u) {
              const int face = image.face(v, u);
              if (face < 0)
                continue;
              double z = image.depth(v, u);
              if (m_options.noise > 0 || m_options.outlier_fraction > 0) {
                PixelRandom random(m_options.seed, frame, static_cast<int>(c),
                    static_cast<long long>(v) * camera.width + u);
                if (m_options.outlier_fraction > 0 && random.uniform() < m_options.outlier_fraction)
                  z = camera.near + random.uniform() * (z - camera.near);
                else if (m_options.noise > 0)
                  z += m_options.noise * random.normal();
              }
              out.points.row(row) = (camera.position + z * camera.pixel_ray(u, v)).transpose();
              if (m_options.normals)
                out.normals.row(row) = m_caster.face_normal(face).transpose();
              ++row;
            }
          }
        });
  }
  return out;
}

void scan_frames(VirtualScanner& scanner, const std::vector<Positions>& frames,
    const std::function<void(long frame, const CloudFrame& cloud)>& sink,
    const ProgressCallback& progress) {
  const long T = static_cast<long>(frames.size());
  for (long t = 0; t < T; ++t) {
    if (interrupt_requested())
      throw InputError("scan", "interrupted before frame " + std::to_string(t));
    scanner.update(frames[static_cast<std::size_t>(t)]);
    sink(t, scanner.scan(t));
    if (progress)
      progress(t + 1, T, "frame " + std::to_string(t + 1) + "/" + std::to_string(T));
  }
}

} // namespace elastolearn::capture
