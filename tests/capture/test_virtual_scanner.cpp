// The virtual depth scanner against depth maps known in closed form (a plane, a sphere), its
// back-face rule, its noise and outliers, and its determinism.
#include <elastolearn/capture/virtual_scanner.hpp>
#include <elastolearn/core/error.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <map>

using namespace elastolearn;
using namespace elastolearn::capture;

namespace {

/// A square of side 2·half in the plane through `centre` with unit normal `n`, two triangles
/// oriented so that their (x1 − x0) × (x2 − x0) is +n.
struct Surface {
  Positions x;
  Faces faces;
};

Surface square(const Vec3& centre, const Vec3& n, double half) {
  const Vec3 a = n.unitOrthogonal(), b = n.cross(a);
  Surface s;
  s.x.resize(4, 3);
  s.x.row(0) = (centre - half * a - half * b).transpose();
  s.x.row(1) = (centre + half * a - half * b).transpose();
  s.x.row(2) = (centre + half * a + half * b).transpose();
  s.x.row(3) = (centre - half * a + half * b).transpose();
  s.faces.resize(2, 3);
  s.faces << 0, 1, 2, 0, 2, 3;
  return s;
}

/// The icosahedron subdivided `levels` times, vertices on the sphere (centre c, radius r), faces
/// outward.
Surface icosphere(const Vec3& c, double r, int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> v
      = { { -1, t, 0 }, { 1, t, 0 }, { -1, -t, 0 }, { 1, -t, 0 }, { 0, -1, t }, { 0, 1, t },
          { 0, -1, -t }, { 0, 1, -t }, { t, 0, -1 }, { t, 0, 1 }, { -t, 0, -1 }, { -t, 0, 1 } };
  for (Vec3& p : v)
    p.normalize();
  std::vector<std::array<int, 3>> f = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 },
    { 0, 10, 11 }, { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 }, { 3, 9, 4 },
    { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 }, { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 },
    { 8, 6, 7 }, { 9, 8, 1 } };
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> middle;
    const auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = middle.find(key);
      if (it != middle.end())
        return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return middle[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& [a, b, cc] : f) {
      const int ab = mid(a, b), bc = mid(b, cc), ca = mid(cc, a);
      next.push_back({ a, ab, ca });
      next.push_back({ b, bc, ab });
      next.push_back({ cc, ca, bc });
      next.push_back({ ab, bc, ca });
    }
    f = next;
  }
  Surface s;
  s.x.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    s.x.row(static_cast<Eigen::Index>(i)) = (c + r * v[i]).transpose();
  s.faces.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i)
    s.faces.row(static_cast<Eigen::Index>(i)) << f[i][0], f[i][1], f[i][2];
  return s;
}

DepthCamera camera_at(const Vec3& eye, const Vec3& target, int width, int height, double fov) {
  DepthCamera c;
  c.name = "test";
  c.width = width;
  c.height = height;
  c.set_field_of_view(fov);
  c.position = eye;
  c.look_at(target, Vec3(0, 1, 0), "test");
  return c;
}

VirtualScanner scanner_for(
    const Surface& s, std::vector<DepthCamera> cameras, const ScanOptions& options = {}) {
  VirtualScanner scanner(s.faces, static_cast<int>(s.x.rows()), std::move(cameras), options);
  scanner.update(s.x);
  return scanner;
}

} // namespace

TEST(DepthCamera, ProjectsItsPixelRaysBackToThePixelCentres) {
  DepthCamera c = camera_at(Vec3(0.3, -0.2, 1.5), Vec3(0, 0.1, 0), 64, 48, 50);
  c.cx = 30.5; // an off-centre principal point and non-square pixels
  c.fy = 1.1 * c.fx;
  for (int v : { 0, 17, 47 })
    for (int u : { 0, 40, 63 }) {
      const Vec3 d = c.pixel_ray(u, v);
      EXPECT_NEAR(d.dot(c.forward()), 1.0, 1e-14);
      const Vec3 p = c.rotation.transpose() * (2.5 * d); // camera coordinates at depth 2.5
      EXPECT_NEAR(p.z(), 2.5, 1e-12);
      EXPECT_NEAR(c.fx * p.x() / p.z() + c.cx, u + 0.5, 1e-9);
      EXPECT_NEAR(c.fy * p.y() / p.z() + c.cy, v + 0.5, 1e-9);
    }
  // look_at: world up appears up in the image (camera −y), the target on the optical axis.
  EXPECT_GT(-c.rotation.col(1).dot(Vec3(0, 1, 0)), 0.9);
  EXPECT_NEAR(c.forward().dot((Vec3(0, 0.1, 0) - c.position).normalized()), 1.0, 1e-14);
  EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-14);
}

TEST(SurfaceRayCaster, SingleRaysAndStreamsAgreeAndRespectTheRange) {
  const Surface sphere = icosphere(Vec3::Zero(), 1, 2);
  SurfaceRayCaster caster(sphere.faces, static_cast<int>(sphere.x.rows()));
  caster.update(sphere.x);
  const Vec3 eye(0, 0, 3);
  std::vector<Vec3> d;
  for (int i = 0; i < 150; ++i) // a fan of rays, some missing the sphere
    d.push_back(Vec3(0.005 * (i - 75), 0.002 * i, -1));
  std::vector<RayHit> hits(d.size());
  caster.first_hits(eye, d.data(), static_cast<int>(d.size()), 0, 10, hits.data());
  int hit = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const RayHit one = caster.first_hit(eye, d[i], 0, 10);
    EXPECT_EQ(one.face, hits[i].face) << i;
    EXPECT_EQ(one.t, hits[i].t) << i;
    hit += one.face >= 0;
  }
  EXPECT_GT(hit, 50);
  EXPECT_LT(hit, 150);
  // Straight down the axis: the near pole at t = 2, or nothing if the range ends before it.
  EXPECT_NEAR(caster.first_hit(eye, Vec3(0, 0, -1), 0, 10).t, 2, 1e-12);
  EXPECT_EQ(caster.first_hit(eye, Vec3(0, 0, -1), 0, 1.9).face, -1);
  // Starting past the near side (a vertex at each pole) finds the far side: a back face.
  const RayHit far = caster.first_hit(eye, Vec3(0, 0, -1), 2.5, 10);
  EXPECT_NEAR(far.t, 4, 1e-12);
  EXPECT_LT(far.normal.z(), -0.95); // outward, away from the eye
}

TEST(VirtualScanner, ReproducesThePlaneDepthMap) {
  // An oblique plane facing the camera: depth z(u, v) = n·(p0 − e) / (n·d(u, v)) exactly.
  const Vec3 n = Vec3(0.3, 0.2, 1).normalized(), p0(0.05, -0.02, 0);
  const Surface plane = square(p0, n, 10);
  const DepthCamera cam = camera_at(Vec3(0.1, 0.2, 1.2), Vec3(0, 0, 0), 80, 60, 50);
  const VirtualScanner scanner = scanner_for(plane, { cam });
  const DepthImage image = scanner.depth_image(0);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Vec3 d = cam.pixel_ray(u, v);
      const double expected = n.dot(p0 - cam.position) / n.dot(d);
      ASSERT_GE(image.face(v, u), 0) << u << ", " << v;
      // Double-precision re-intersection: exact to rounding of a ~1 m depth.
      EXPECT_NEAR(image.depth(v, u), expected, 1e-13) << u << ", " << v;
    }
}

TEST(VirtualScanner, SeesNothingOfAPlaneThatFacesAway) {
  const Vec3 n = Vec3(0.3, 0.2, 1).normalized();
  const Surface away = square(Vec3::Zero(), -n, 10); // same plane, normal away from the camera
  const DepthCamera cam = camera_at(Vec3(0.1, 0.2, 1.2), Vec3(0, 0, 0), 40, 30, 50);
  VirtualScanner scanner = scanner_for(away, { cam });
  EXPECT_EQ(scanner.scan(0).points.rows(), 0);
  EXPECT_EQ((scanner.depth_image(0).face.array() >= 0).count(), 0);
}

TEST(VirtualScanner, ReproducesTheSphereDepthMapAndSeesOnlyItsNearSide) {
  const Vec3 c(0.1, -0.05, 0.02);
  const double r = 0.3;
  const Surface sphere = icosphere(c, r, 4); // 5120 faces, inscribed: sagitta ≤ 8e-4 r
  const DepthCamera cam = camera_at(Vec3(0.2, 0.4, 1.3), c, 120, 90, 40);
  ScanOptions options;
  options.normals = true;
  VirtualScanner scanner = scanner_for(sphere, { cam }, options);
  const DepthImage image = scanner.depth_image(0);
  int compared = 0, seen = 0;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Vec3 d = cam.pixel_ray(u, v);
      // |e + z d − c|² = r²: a z² + 2 b z + q = 0, nearest root.
      const Vec3 ec = cam.position - c;
      const double a = d.squaredNorm(), b = d.dot(ec), q = ec.squaredNorm() - r * r;
      const double disc = b * b - a * q;
      if (image.face(v, u) >= 0)
        ++seen;
      if (disc <= 0)
        continue;
      const double z = (-b - std::sqrt(disc)) / a;
      const Vec3 p = cam.position + z * d;
      const double cos_incidence = -(p - c).normalized().dot(d.normalized());
      if (cos_incidence < 0.5)
        continue; // near the silhouette the polyhedron and the sphere differ in coverage
      ASSERT_GE(image.face(v, u), 0) << u << ", " << v;
      // The inscribed polyhedron lies inside the sphere: at most sagitta / cos further away.
      EXPECT_GE(image.depth(v, u), z - 1e-12);
      EXPECT_LE(image.depth(v, u), z + 2 * 8e-4 * r / cos_incidence);
      ++compared;
    }
  EXPECT_GT(compared, 1000);
  // Every point seen is on the half the camera faces: its outward normal points at the eye.
  const CloudFrame cloud = scanner.scan(0);
  ASSERT_EQ(cloud.points.rows(), seen);
  for (Eigen::Index i = 0; i < cloud.points.rows(); ++i) {
    const Vec3 p = cloud.points.row(i).transpose();
    EXPECT_GT((p - c).dot(cam.position - p), 0) << i;
    EXPECT_GT(cloud.normals.row(i).dot((cam.position - p).transpose()), 0) << i;
  }
}

TEST(VirtualScanner, CameraInsideAClosedSurfaceSeesNothing) {
  // From inside, the first hit of every ray is a back face, which hides the rest.
  const Surface sphere = icosphere(Vec3::Zero(), 1, 2);
  VirtualScanner scanner
      = scanner_for(sphere, { camera_at(Vec3(0.1, 0, 0), Vec3(1, 0, 0.2), 32, 24, 60) });
  EXPECT_EQ(scanner.scan(0).points.rows(), 0);
}

TEST(VirtualScanner, DepthNoiseIsGaussianAlongTheRay) {
  const Vec3 n(0, 0, 1);
  const Surface plane = square(Vec3::Zero(), n, 10);
  const DepthCamera cam = camera_at(Vec3(0.1, 0.2, 1.0), Vec3(0, 0, 0), 200, 150, 50);
  ScanOptions options;
  options.noise = 2e-3;
  options.seed = 7;
  VirtualScanner scanner = scanner_for(plane, { cam }, options);
  const DepthImage clean = scanner.depth_image(0);
  const CloudFrame cloud = scanner.scan(3);
  ASSERT_EQ(cloud.points.rows(), 200 * 150);
  double sum = 0, sum2 = 0;
  for (int v = 0, i = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u, ++i) {
      const Vec3 p = cloud.points.row(i).transpose();
      const Vec3 d = cam.pixel_ray(u, v);
      // On the pixel's ray …
      EXPECT_LT(((p - cam.position).cross(d)).norm() / d.norm(), 1e-12);
      // … at a depth off by the noise.
      const double e = (p - cam.position).dot(cam.forward()) - clean.depth(v, u);
      sum += e;
      sum2 += e * e;
    }
  const double N = 200 * 150, mean = sum / N, sd = std::sqrt(sum2 / N - mean * mean);
  // Standard errors: mean σ/√N = 1.2e-5, sd σ/√(2N) = 8e-6; 4 of them.
  EXPECT_NEAR(mean, 0, 4 * 2e-3 / std::sqrt(N));
  EXPECT_NEAR(sd, 2e-3, 4 * 2e-3 / std::sqrt(2 * N));
}

TEST(VirtualScanner, OutliersAreTheAskedFractionInTheLineOfSight) {
  const Surface plane = square(Vec3::Zero(), Vec3(0, 0, 1), 10);
  DepthCamera cam = camera_at(Vec3(0, 0, 1.0), Vec3(0, 0, 0), 100, 100, 50);
  cam.near = 0.2;
  ScanOptions options;
  options.outlier_fraction = 0.25;
  VirtualScanner scanner = scanner_for(plane, { cam }, options);
  const CloudFrame cloud = scanner.scan(0);
  ASSERT_EQ(cloud.points.rows(), 100 * 100);
  int outliers = 0;
  for (Eigen::Index i = 0; i < cloud.points.rows(); ++i) {
    const double z = cam.position.z() - cloud.points(i, 2); // depth: the camera looks along −z
    EXPECT_GE(z, cam.near - 1e-12);
    EXPECT_LE(z, 1.0 + 1e-12);
    outliers += z < 1.0 - 1e-9;
  }
  // Binomial(10⁴, 0.25): standard deviation 43; allow 4.
  EXPECT_NEAR(outliers, 2500, 4 * 43);
}

TEST(VirtualScanner, SameSeedSameScanWhateverTheThreadsDifferentSeedDifferentScan) {
  const Surface sphere = icosphere(Vec3::Zero(), 0.2, 3);
  const DepthCamera a = camera_at(Vec3(0, 0, 1), Vec3::Zero(), 64, 48, 40);
  const DepthCamera b = camera_at(Vec3(0.8, 0.3, 0.2), Vec3::Zero(), 32, 32, 40);
  ScanOptions options;
  options.noise = 1e-3;
  options.outlier_fraction = 0.05;
  options.seed = 42;
  const auto run = [&](std::size_t threads, std::uint64_t seed) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    ScanOptions o = options;
    o.seed = seed;
    VirtualScanner scanner = scanner_for(sphere, { a, b }, o);
    return scanner.scan(5).points;
  };
  const Positions one = run(1, 42), two = run(2, 42), other = run(2, 43);
  ASSERT_GT(one.rows(), 100);
  EXPECT_EQ(one, two); // bit for bit
  ASSERT_EQ(other.rows(), one.rows());
  EXPECT_GT((other - one).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(VirtualScanner, PointsAreCameraByCameraRowByRow) {
  const Surface plane = square(Vec3::Zero(), Vec3(0, 0, 1), 10);
  const DepthCamera a = camera_at(Vec3(0, 0, 1), Vec3::Zero(), 8, 6, 40);
  const DepthCamera b = camera_at(Vec3(0.5, 0, 2), Vec3(0.5, 0, 0), 5, 4, 40);
  VirtualScanner scanner = scanner_for(plane, { a, b });
  const CloudFrame cloud = scanner.scan(0);
  ASSERT_EQ(cloud.points.rows(), 8 * 6 + 5 * 4);
  EXPECT_LT((cloud.points.row(0).transpose() - (a.position + a.pixel_ray(0, 0))).norm(), 1e-12);
  EXPECT_LT((cloud.points.row(8 * 6 + 6).transpose() - (b.position + 2 * b.pixel_ray(1, 1))).norm(),
      1e-12);
}

TEST(VirtualScanner, RejectsBadOptionsAndCameras) {
  const Surface plane = square(Vec3::Zero(), Vec3(0, 0, 1), 1);
  const DepthCamera good = camera_at(Vec3(0, 0, 1), Vec3::Zero(), 8, 6, 40);
  ScanOptions noise;
  noise.noise = -1;
  EXPECT_THROW(VirtualScanner(plane.faces, 4, { good }, noise), InputError);
  ScanOptions outliers;
  outliers.outlier_fraction = 1.5;
  EXPECT_THROW(VirtualScanner(plane.faces, 4, { good }, outliers), InputError);
  DepthCamera bad = good;
  bad.far = bad.near;
  EXPECT_THROW(VirtualScanner(plane.faces, 4, { bad }, {}), InputError);
  EXPECT_THROW(VirtualScanner(plane.faces, 4, {}, {}), InputError);
  EXPECT_THROW(VirtualScanner(plane.faces, 3, { good }, {}), InputError); // index 3 out of range
  VirtualScanner scanner(plane.faces, 4, { good }, {});
  Positions nan = plane.x;
  nan(2, 1) = std::nan("");
  EXPECT_THROW(scanner.update(nan), InputError);
}
