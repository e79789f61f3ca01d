#include <elastolearn/capture/ray_caster.hpp>
#include <elastolearn/core/error.hpp>

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace elastolearn::capture {

namespace {

std::string device_error(RTCDevice device) {
  switch (rtcGetDeviceError(device)) {
  case RTC_ERROR_NONE:
    return "no error";
  case RTC_ERROR_OUT_OF_MEMORY:
    return "out of memory";
  case RTC_ERROR_INVALID_ARGUMENT:
    return "invalid argument";
  case RTC_ERROR_INVALID_OPERATION:
    return "invalid operation";
  case RTC_ERROR_UNSUPPORTED_CPU:
    return "unsupported CPU";
  case RTC_ERROR_CANCELLED:
    return "cancelled";
  default:
    return "unknown error";
  }
}

} // namespace

struct SurfaceRayCaster::Impl {
  Faces faces;
  int num_vertices = 0;
  Positions x; ///< current positions, double (for the exact re-intersection)
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  RTCGeometry geometry = nullptr;
  float* vertices = nullptr; ///< Embree's vertex buffer (owned by the geometry)
  bool built = false;

  ~Impl() {
    if (scene)
      rtcReleaseScene(scene);
    if (device)
      rtcReleaseDevice(device);
  }

  void check(const char* what) const {
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE)
      throw std::runtime_error(std::string("Embree: ") + what + ": " + device_error(device));
  }
};

SurfaceRayCaster::SurfaceRayCaster(const Faces& faces, int num_vertices)
    : m_impl(std::make_unique<Impl>()) {
  Impl& s = *m_impl;
  if (faces.rows() == 0)
    throw InputError("surface", "no triangles to scan");
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      if (faces(f, c) < 0 || faces(f, c) >= num_vertices)
        throw InputError("surface",
            "face " + std::to_string(f) + " has vertex index " + std::to_string(faces(f, c))
                + " outside [0, " + std::to_string(num_vertices) + ")");
  s.faces = faces;
  s.num_vertices = num_vertices;
  s.device = rtcNewDevice(nullptr);
  if (!s.device)
    throw std::runtime_error("Embree: cannot create a device: " + device_error(nullptr));
  s.scene = rtcNewScene(s.device);
  rtcSetSceneFlags(s.scene, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
  s.geometry = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  s.vertices = static_cast<float*>(rtcSetNewGeometryBuffer(s.geometry, RTC_BUFFER_TYPE_VERTEX, 0,
      RTC_FORMAT_FLOAT3, 3 * sizeof(float), static_cast<std::size_t>(num_vertices)));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(s.geometry, RTC_BUFFER_TYPE_INDEX,
      0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), static_cast<std::size_t>(faces.rows())));
  s.check("cannot allocate the surface buffers");
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      indices[3 * f + c] = static_cast<unsigned>(faces(f, c));
  rtcSetGeometryBuildQuality(s.geometry, RTC_BUILD_QUALITY_REFIT);
  rtcAttachGeometry(s.scene, s.geometry);
  rtcReleaseGeometry(s.geometry); // the scene keeps it alive
  s.check("cannot set up the scene");
}

SurfaceRayCaster::~SurfaceRayCaster() = default;
SurfaceRayCaster::SurfaceRayCaster(SurfaceRayCaster&&) noexcept = default;
SurfaceRayCaster& SurfaceRayCaster::operator=(SurfaceRayCaster&&) noexcept = default;

int SurfaceRayCaster::num_faces() const {
  return static_cast<int>(m_impl->faces.rows());
}

Vec3 SurfaceRayCaster::face_normal(int f) const {
  const Impl& s = *m_impl;
  const Vec3 x0 = s.x.row(s.faces(f, 0)).transpose();
  return (s.x.row(s.faces(f, 1)).transpose() - x0)
      .cross(s.x.row(s.faces(f, 2)).transpose() - x0)
      .normalized();
}

void SurfaceRayCaster::update(ConstRef<Positions> x) {
  Impl& s = *m_impl;
  if (x.rows() != s.num_vertices)
    throw InputError("surface",
        "positions have " + std::to_string(x.rows()) + " rows, the surface has "
            + std::to_string(s.num_vertices) + " vertices");
  if (!x.allFinite())
    throw InputError("surface", "non-finite vertex position");
  s.x = x;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (int c = 0; c < 3; ++c)
      s.vertices[3 * i + c] = static_cast<float>(x(i, c));
  rtcUpdateGeometryBuffer(s.geometry, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(s.geometry);
  rtcCommitScene(s.scene);
  s.check("cannot build the ray-casting tree");
  s.built = true;
}

namespace {

void set_ray(RTCRayHit& rh, const Vec3& origin, const Vec3& direction, double t_min, double t_max) {
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(direction.x());
  rh.ray.dir_y = static_cast<float>(direction.y());
  rh.ray.dir_z = static_cast<float>(direction.z());
  rh.ray.tnear = static_cast<float>(t_min);
  rh.ray.tfar = t_max < double(std::numeric_limits<float>::max())
      ? static_cast<float>(t_max)
      : std::numeric_limits<float>::infinity();
  rh.ray.time = 0;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/// The hit of a traced ray, its distance recomputed in double against the face's plane.
RayHit exact_hit(const RTCRayHit& rh, const Faces& faces, const Positions& x, const Vec3& origin,
    const Vec3& direction, double t_min, double t_max) {
  RayHit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
    return hit;
  const int f = static_cast<int>(rh.hit.primID);
  const Vec3 x0 = x.row(faces(f, 0)).transpose();
  const Vec3 n = (x.row(faces(f, 1)).transpose() - x0).cross(x.row(faces(f, 2)).transpose() - x0);
  const double dn = direction.dot(n);
  // The double-precision distance to the face's plane; Embree's float distance for a ray that
  // grazes the plane (where the plane distance is ill-conditioned).
  const double t = std::abs(dn) > 1e-12 * n.norm() * direction.norm()
      ? (x0 - origin).dot(n) / dn
      : static_cast<double>(rh.ray.tfar);
  if (!(t >= t_min && t <= t_max))
    return hit;
  hit.face = f;
  hit.t = t;
  hit.normal = n.normalized();
  return hit;
}

/// Rays per stream call: 64 RTCRayHit (5 KiB) live on the stack.
constexpr int k_stream = 64;

} // namespace

RayHit SurfaceRayCaster::first_hit(
    const Vec3& origin, const Vec3& direction, double t_min, double t_max) const {
  const Impl& s = *m_impl;
  ELASTOLEARN_CHECK(s.built, "SurfaceRayCaster::first_hit before update()");
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  set_ray(rh, origin, direction, t_min, t_max);
  rtcIntersect1(s.scene, &context, &rh);
  return exact_hit(rh, s.faces, s.x, origin, direction, t_min, t_max);
}

void SurfaceRayCaster::first_hits(const Vec3& origin, const Vec3* directions, int count,
    double t_min, double t_max, RayHit* out) const {
  const Impl& s = *m_impl;
  ELASTOLEARN_CHECK(s.built, "SurfaceRayCaster::first_hits before update()");
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRayHit rays[k_stream];
  for (int begin = 0; begin < count; begin += k_stream) {
    const int n = std::min(k_stream, count - begin);
    for (int i = 0; i < n; ++i)
      set_ray(rays[i], origin, directions[begin + i], t_min, t_max);
    rtcIntersect1M(s.scene, &context, rays, static_cast<unsigned>(n), sizeof(RTCRayHit));
    for (int i = 0; i < n; ++i)
      out[begin + i]
          = exact_hit(rays[i], s.faces, s.x, origin, directions[begin + i], t_min, t_max);
  }
}

} // namespace elastolearn::capture
