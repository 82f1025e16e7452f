#include "scanner/sim/ray_caster.hpp"

#include <embree3/rtcore.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim {
namespace {

// One object as the caster keeps it: world-frame geometry in double for the exact tests.
struct Geometry {
  int object_index = 0;
  double reflectance = 0.0;
  bool sphere = false;
  Eigen::Vector3d centre_W = Eigen::Vector3d::Zero();  // sphere
  Eigen::Vector3d centre_E = Eigen::Vector3d::Zero();  // sphere, in Embree's frame
  double radius_m = 0.0;                               // sphere
  std::vector<Eigen::Vector3d> vertices_W;             // mesh
  std::vector<Eigen::Vector3i> triangles;              // mesh
};

// Per-query data for the callbacks. Embree passes them a pointer to `base`, the first member
// of this standard-layout struct, which makes the cast back to the whole struct valid (the
// "context extension" Embree documents).
struct QueryContext {
  RTCIntersectContext base;
  double origin_W[3];
  double direction_W[3];  // unit
  double t_min_m;
  double t_max_m;
};
static_assert(std::is_standard_layout_v<QueryContext>);

const QueryContext& Query(const RTCIntersectContext* context) {
  return *reinterpret_cast<const QueryContext*>(context);
}

Eigen::Map<const Eigen::Vector3d> Origin(const QueryContext& q) {
  return Eigen::Map<const Eigen::Vector3d>(q.origin_W);
}
Eigen::Map<const Eigen::Vector3d> Direction(const QueryContext& q) {
  return Eigen::Map<const Eigen::Vector3d>(q.direction_W);
}

bool InRange(double t, const QueryContext& q) { return t > q.t_min_m && t <= q.t_max_m; }

// Distance along the query ray to the plane of a triangle Embree reported as hit (Moller-
// Trumbore in double). The barycentric coordinates are not tested again: Embree has decided
// coverage, and a ray through an edge may fall a rounding error outside either neighbour.
// std::nullopt when the ray is parallel to the triangle.
std::optional<double> TriangleDistance(const Geometry& g, unsigned prim, const QueryContext& q) {
  const Eigen::Vector3i& t = g.triangles[prim];
  const Eigen::Vector3d& a = g.vertices_W[t[0]];
  const Eigen::Vector3d e1 = g.vertices_W[t[1]] - a;
  const Eigen::Vector3d e2 = g.vertices_W[t[2]] - a;
  const Eigen::Vector3d p = Direction(q).cross(e2);
  const double det = e1.dot(p);
  if (det == 0.0 || !std::isfinite(det)) return std::nullopt;
  const Eigen::Vector3d s = Origin(q) - a;
  return e2.dot(s.cross(e1)) / det;
}

// Nearest intersection of the query ray with a sphere within the query's range. With a unit
// direction the roots of t^2 + 2 b t + c = 0 are -b -+ h, where h^2 = r^2 - |l|^2 and l is the
// part of (origin - centre) normal to the ray: that form has no cancellation when the ray
// starts far away, and the smaller-magnitude root comes from c / q (Numerical Recipes 5.6).
std::optional<double> SphereDistance(const Geometry& g, const QueryContext& q) {
  const Eigen::Vector3d oc = Origin(q) - g.centre_W;
  const Eigen::Vector3d d = Direction(q);
  const double b = d.dot(oc);
  const Eigen::Vector3d l = oc - b * d;
  const double h2 = (g.radius_m - l.norm()) * (g.radius_m + l.norm());
  if (h2 < 0.0) return std::nullopt;
  const double h = std::sqrt(h2);
  const double c = (oc.norm() - g.radius_m) * (oc.norm() + g.radius_m);
  const double big = -(b + std::copysign(h, b));
  double t0 = big, t1 = big != 0.0 ? c / big : 0.0;
  if (t0 > t1) std::swap(t0, t1);
  if (InRange(t0, q)) return t0;
  if (InRange(t1, q)) return t1;
  return std::nullopt;
}

// Distance from p to the closest point of segment [a, b].
double SegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double s = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + s * ab)).norm();
}

// Distance from p to triangle `prim`: to its plane when p projects inside it, else to the
// nearest edge.
double PointTriangleDistance(const Geometry& g, unsigned prim, const Eigen::Vector3d& p) {
  const Eigen::Vector3i& t = g.triangles[prim];
  const Eigen::Vector3d& a = g.vertices_W[t[0]];
  const Eigen::Vector3d& b = g.vertices_W[t[1]];
  const Eigen::Vector3d& c = g.vertices_W[t[2]];
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0.0) {
    // Inside when p lies on the inner side of all three edges (seen along the normal).
    const bool inside = n.dot((b - a).cross(p - a)) >= 0.0 && n.dot((c - b).cross(p - b)) >= 0.0 &&
                        n.dot((a - c).cross(p - c)) >= 0.0;
    if (inside) return std::abs(n.dot(p - a)) / std::sqrt(n2);
  }
  return std::min({SegmentDistance(p, a, b), SegmentDistance(p, b, c), SegmentDistance(p, c, a)});
}

// What a point query carries through Embree: the point in double and the best distance so far.
struct ClosestQuery {
  const std::vector<std::unique_ptr<Geometry>>* geometries = nullptr;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  double best_m = std::numeric_limits<double>::infinity();
  float pad = 0.0f;  // added to the float search radius so rounding never culls the closest
};

bool ClosestCallback(RTCPointQueryFunctionArguments* args) {
  auto& query = *static_cast<ClosestQuery*>(args->userPtr);
  const Geometry& g = *(*query.geometries)[args->geomID];
  const double d = g.sphere ? std::abs((query.p_W - g.centre_W).norm() - g.radius_m)
                            : PointTriangleDistance(g, args->primID, query.p_W);
  if (!(d < query.best_m)) return false;
  query.best_m = d;
  args->query->radius = static_cast<float>(d) + query.pad;
  return true;  // the search radius shrank
}

// Embree's candidate triangles are accepted only when their exact distance is in range.
void TriangleFilter(const RTCFilterFunctionNArguments* args) {
  const Geometry& g = *static_cast<const Geometry*>(args->geometryUserPtr);
  const QueryContext& q = Query(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const std::optional<double> t = TriangleDistance(g, RTCHitN_primID(args->hit, args->N, i), q);
    if (!t || !InRange(*t, q)) args->valid[i] = 0;
  }
}

void SphereBounds(const RTCBoundsFunctionArguments* args) {
  const Geometry& g = *static_cast<const Geometry*>(args->geometryUserPtr);
  // Padded beyond float rounding of the centre so that Embree never culls a true hit.
  const double pad = 1e-5 * (g.centre_E.norm() + g.radius_m);
  const Eigen::Vector3d lo = g.centre_E.array() - (g.radius_m + pad);
  const Eigen::Vector3d hi = g.centre_E.array() + (g.radius_m + pad);
  RTCBounds* b = args->bounds_o;
  b->lower_x = static_cast<float>(lo.x());
  b->lower_y = static_cast<float>(lo.y());
  b->lower_z = static_cast<float>(lo.z());
  b->upper_x = static_cast<float>(hi.x());
  b->upper_y = static_cast<float>(hi.y());
  b->upper_z = static_cast<float>(hi.z());
}

void SphereIntersect(const RTCIntersectFunctionNArguments* args) {
  assert(args->N == 1);  // only rtcIntersect1 is used: the context holds one ray
  if (args->valid[0] == 0) return;
  const Geometry& g = *static_cast<const Geometry*>(args->geometryUserPtr);
  const QueryContext& q = Query(args->context);
  const std::optional<double> t = SphereDistance(g, q);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  float& tfar = RTCRayN_tfar(ray, args->N, 0);
  if (!t || !(*t < tfar)) return;
  tfar = static_cast<float>(*t);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  const Eigen::Vector3d n = (Origin(q) + *t * Direction(q) - g.centre_W) / g.radius_m;
  RTCHitN_Ng_x(hit, args->N, 0) = static_cast<float>(n.x());
  RTCHitN_Ng_y(hit, args->N, 0) = static_cast<float>(n.y());
  RTCHitN_Ng_z(hit, args->N, 0) = static_cast<float>(n.z());
  RTCHitN_u(hit, args->N, 0) = 0.0f;
  RTCHitN_v(hit, args->N, 0) = 0.0f;
  RTCHitN_primID(hit, args->N, 0) = args->primID;
  RTCHitN_geomID(hit, args->N, 0) = args->geomID;
  RTCHitN_instID(hit, args->N, 0, 0) = args->context->instID[0];
}

void SphereOccluded(const RTCOccludedFunctionNArguments* args) {
  assert(args->N == 1);
  if (args->valid[0] == 0) return;
  const Geometry& g = *static_cast<const Geometry*>(args->geometryUserPtr);
  if (SphereDistance(g, Query(args->context))) {
    RTCRayN_tfar(args->ray, args->N, 0) = -std::numeric_limits<float>::infinity();
  }
}

std::string DeviceErrorText(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
    default:
      return "unknown error";
  }
}

std::unique_ptr<Geometry> SphereGeometry(const SceneObject& object) {
  if (!(object.sphere_radius_m > 0.0) || !std::isfinite(object.sphere_radius_m)) {
    throw Error("ray caster: object '" + object.name + "': sphere radius " +
                std::to_string(object.sphere_radius_m) + ", expected > 0 m");
  }
  auto g = std::make_unique<Geometry>();
  g->sphere = true;
  g->centre_W = object.T_W_O.translation();
  g->radius_m = object.sphere_radius_m;
  return g;
}

std::unique_ptr<Geometry> MeshGeometry(const SceneObject& object) {
  if (object.mesh.triangles.empty()) {
    throw Error("ray caster: object '" + object.name + "' has no triangles");
  }
  const int count = static_cast<int>(object.mesh.vertices.size());
  for (const Eigen::Vector3i& t : object.mesh.triangles) {
    if ((t.array() < 0).any() || (t.array() >= count).any()) {
      throw Error("ray caster: object '" + object.name + "': a triangle indexes a missing vertex");
    }
  }
  auto g = std::make_unique<Geometry>();
  g->vertices_W.reserve(count);
  for (const Eigen::Vector3d& v : object.mesh.vertices) {
    g->vertices_W.push_back(object.T_W_O * v);
    if (!g->vertices_W.back().allFinite()) {
      throw Error("ray caster: object '" + object.name + "' has a non-finite vertex");
    }
  }
  g->triangles = object.mesh.triangles;
  return g;
}

// Object `index` checked and posed in the world frame, as the caster keeps it.
std::unique_ptr<Geometry> PosedGeometry(const SceneObject& object, int index) {
  std::unique_ptr<Geometry> g =
      object.shape == ObjectShape::kSphere ? SphereGeometry(object) : MeshGeometry(object);
  g->object_index = index;
  g->reflectance = object.reflectance;
  return g;
}

// The world-frame box holding every geometry.
Eigen::AlignedBox3d BoundsOf(const std::vector<std::unique_ptr<Geometry>>& geometries) {
  Eigen::AlignedBox3d bounds;
  for (const std::unique_ptr<Geometry>& g : geometries) {
    if (g->sphere) {
      bounds.extend(g->centre_W - Eigen::Vector3d::Constant(g->radius_m));
      bounds.extend(g->centre_W + Eigen::Vector3d::Constant(g->radius_m));
    } else {
      for (const Eigen::Vector3d& v : g->vertices_W) bounds.extend(v);
    }
  }
  return bounds;
}

// An Embree user geometry for one sphere, intersected exactly (SphereDistance).
RTCGeometry NewSphereGeometry(RTCDevice device) {
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, 1);
  rtcSetGeometryBoundsFunction(geometry, SphereBounds, nullptr);
  rtcSetGeometryIntersectFunction(geometry, SphereIntersect);
  rtcSetGeometryOccludedFunction(geometry, SphereOccluded);
  return geometry;
}

}  // namespace

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  // Embree works in float relative to this point (the centre of the objects' bounds).
  Eigen::Vector3d origin_E_W = Eigen::Vector3d::Zero();
  std::vector<std::unique_ptr<Geometry>> geometries;  // index = Embree geometry id

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }

  void CheckDevice(const std::string& doing) const {
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE) {
      throw Error("ray caster: Embree failed " + doing + ": " + DeviceErrorText(code));
    }
  }

  // Embree's float margins around the exact range: wide enough that its rounding never culls
  // a candidate the exact test would accept; the filter and the sphere test decide.
  std::pair<float, float> FloatRange(const Eigen::Vector3d& origin_E, double t_min,
                                     double t_max) const {
    const double margin = 1e-5 * (origin_E.norm() + t_min) + 1e-7;
    const float tnear = t_min > margin ? static_cast<float>(t_min - margin) : 0.0f;
    const float tfar = std::isfinite(t_max) ? static_cast<float>(t_max + margin + 1e-5 * t_max)
                                            : std::numeric_limits<float>::infinity();
    return {tnear, tfar};
  }

  // The device and an empty scene.
  void CreateScene();
  // Geometry g added to the scene as Embree geometry `id`; `name` is its object's, for messages.
  void Attach(Geometry& g, unsigned id, const std::string& name);
  // An Embree triangle mesh of g, its vertices in float relative to origin_E_W; the exact range
  // test (TriangleFilter) decides its hits.
  RTCGeometry NewMeshGeometry(const Geometry& g) const;
};

void RayCaster::Impl::CreateScene() {
  device = rtcNewDevice(nullptr);
  if (device == nullptr) {
    throw Error("ray caster: cannot create an Embree device: " +
                DeviceErrorText(rtcGetDeviceError(nullptr)));
  }
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) == 0) {
    throw Error(
        "ray caster: this Embree was built without filter functions, which the exact "
        "double-precision range test needs");
  }
  scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
}

void RayCaster::Impl::Attach(Geometry& g, unsigned id, const std::string& name) {
  RTCGeometry geometry = nullptr;
  if (g.sphere) {
    g.centre_E = g.centre_W - origin_E_W;
    geometry = NewSphereGeometry(device);
  } else {
    geometry = NewMeshGeometry(g);
  }
  rtcSetGeometryUserData(geometry, &g);
  rtcCommitGeometry(geometry);
  rtcAttachGeometryByID(scene, geometry, id);
  rtcReleaseGeometry(geometry);
  CheckDevice("adding object '" + name + "'");
}

RTCGeometry RayCaster::Impl::NewMeshGeometry(const Geometry& g) const {
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               g.vertices_W.size()));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), g.triangles.size()));
  if (vertices == nullptr || indices == nullptr) CheckDevice("allocating a mesh");
  for (size_t v = 0; v < g.vertices_W.size(); ++v) {
    const Eigen::Vector3d p = g.vertices_W[v] - origin_E_W;
    for (int k = 0; k < 3; ++k) vertices[3 * v + k] = static_cast<float>(p[k]);
  }
  for (size_t t = 0; t < g.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) indices[3 * t + k] = static_cast<unsigned>(g.triangles[t][k]);
  }
  rtcSetGeometryIntersectFilterFunction(geometry, TriangleFilter);
  rtcSetGeometryOccludedFilterFunction(geometry, TriangleFilter);
  return geometry;
}

RayCaster::RayCaster(const std::vector<SceneObject>& objects) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  // Posed geometry first: its bounds give Embree's origin.
  for (size_t i = 0; i < objects.size(); ++i) {
    m.geometries.push_back(PosedGeometry(objects[i], static_cast<int>(i)));
  }
  const Eigen::AlignedBox3d bounds = BoundsOf(m.geometries);
  if (!bounds.isEmpty()) m.origin_E_W = bounds.center();
  m.CreateScene();
  for (size_t i = 0; i < m.geometries.size(); ++i) {
    m.Attach(*m.geometries[i], static_cast<unsigned>(i), objects[i].name);
  }
  rtcCommitScene(m.scene);
  m.CheckDevice("building the scene");
}

RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

std::optional<double> RayCaster::DistanceToSurface(const Eigen::Vector3d& p_W, double max_m) const {
  const Impl& m = *impl_;
  if (!p_W.allFinite() || !(max_m > 0.0)) {
    throw Error("ray caster: DistanceToSurface: expected a finite point and max_m > 0");
  }
  ClosestQuery closest;
  closest.geometries = &m.geometries;
  closest.p_W = p_W;
  const Eigen::Vector3d p_E = p_W - m.origin_E_W;
  closest.pad = static_cast<float>(1e-6 * (1.0 + p_E.norm() + max_m));
  RTCPointQuery query;
  query.x = static_cast<float>(p_E.x());
  query.y = static_cast<float>(p_E.y());
  query.z = static_cast<float>(p_E.z());
  query.time = 0.0f;
  query.radius = static_cast<float>(max_m) + closest.pad;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(m.scene, &query, &context, ClosestCallback, &closest);
  if (!(closest.best_m <= max_m)) return std::nullopt;
  return closest.best_m;
}

int RayCaster::object_count() const { return static_cast<int>(impl_->geometries.size()); }

std::optional<SurfaceHit> RayCaster::Cast(const Ray& ray_W, double t_min_m, double t_max_m) const {
  const Impl& m = *impl_;
  const double norm = ray_W.direction.norm();
  if (!ray_W.origin.allFinite() || !std::isfinite(norm) || norm == 0.0) {
    throw Error("ray caster: Cast: expected a finite origin and a finite, non-zero direction");
  }
  if (!(t_min_m >= 0.0) || std::isnan(t_max_m)) {
    throw Error("ray caster: Cast: expected 0 <= t_min_m, got " + std::to_string(t_min_m));
  }
  if (!(t_max_m > t_min_m)) return std::nullopt;
  const Eigen::Vector3d direction = ray_W.direction / norm;
  QueryContext q;
  rtcInitIntersectContext(&q.base);
  Eigen::Map<Eigen::Vector3d>(q.origin_W) = ray_W.origin;
  Eigen::Map<Eigen::Vector3d>(q.direction_W) = direction;
  q.t_min_m = t_min_m;
  q.t_max_m = t_max_m;

  const Eigen::Vector3d origin_E = ray_W.origin - m.origin_E_W;
  const auto [tnear, tfar] = m.FloatRange(origin_E, t_min_m, t_max_m);
  RTCRayHit rayhit;
  rayhit.ray.org_x = static_cast<float>(origin_E.x());
  rayhit.ray.org_y = static_cast<float>(origin_E.y());
  rayhit.ray.org_z = static_cast<float>(origin_E.z());
  rayhit.ray.dir_x = static_cast<float>(direction.x());
  rayhit.ray.dir_y = static_cast<float>(direction.y());
  rayhit.ray.dir_z = static_cast<float>(direction.z());
  rayhit.ray.tnear = tnear;
  rayhit.ray.tfar = tfar;
  rayhit.ray.time = 0.0f;
  rayhit.ray.mask = 0xFFFFFFFFu;
  rayhit.ray.id = 0;
  rayhit.ray.flags = 0;
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m.scene, &q.base, &rayhit);
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;

  // The accepted candidate, intersected once more in double for the returned hit.
  const Geometry& g = *m.geometries[rayhit.hit.geomID];
  SurfaceHit hit;
  hit.object_index = g.object_index;
  hit.reflectance = g.reflectance;
  if (g.sphere) {
    const std::optional<double> t = SphereDistance(g, q);
    assert(t);
    if (!t) return std::nullopt;
    hit.distance_m = *t;
    hit.point_W = ray_W.origin + *t * direction;
    hit.normal_W = (hit.point_W - g.centre_W) / g.radius_m;
  } else {
    const std::optional<double> t = TriangleDistance(g, rayhit.hit.primID, q);
    assert(t);
    if (!t) return std::nullopt;
    hit.distance_m = *t;
    hit.point_W = ray_W.origin + *t * direction;
    const Eigen::Vector3i& tri = g.triangles[rayhit.hit.primID];
    const Eigen::Vector3d& a = g.vertices_W[tri[0]];
    hit.normal_W = (g.vertices_W[tri[1]] - a).cross(g.vertices_W[tri[2]] - a).normalized();
  }
  return hit;
}

bool RayCaster::Blocked(const Eigen::Vector3d& from_W, const Eigen::Vector3d& to_W,
                        double eps_m) const {
  const Impl& m = *impl_;
  const Eigen::Vector3d span = to_W - from_W;
  const double length = span.norm();
  if (!from_W.allFinite() || !std::isfinite(length) || !(eps_m >= 0.0)) {
    throw Error("ray caster: Blocked: expected finite points and eps_m >= 0");
  }
  if (!(length > 2.0 * eps_m)) return false;
  const Eigen::Vector3d direction = span / length;
  QueryContext q;
  rtcInitIntersectContext(&q.base);
  Eigen::Map<Eigen::Vector3d>(q.origin_W) = from_W;
  Eigen::Map<Eigen::Vector3d>(q.direction_W) = direction;
  q.t_min_m = eps_m;
  q.t_max_m = length - eps_m;

  const Eigen::Vector3d origin_E = from_W - m.origin_E_W;
  const auto [tnear, tfar] = m.FloatRange(origin_E, q.t_min_m, q.t_max_m);
  RTCRay ray;
  ray.org_x = static_cast<float>(origin_E.x());
  ray.org_y = static_cast<float>(origin_E.y());
  ray.org_z = static_cast<float>(origin_E.z());
  ray.dir_x = static_cast<float>(direction.x());
  ray.dir_y = static_cast<float>(direction.y());
  ray.dir_z = static_cast<float>(direction.z());
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(m.scene, &q.base, &ray);
  // Embree marks an occluded ray by setting tfar to -infinity.
  return ray.tfar < 0.0f;
}

}  // namespace uwscan::scanner::sim
