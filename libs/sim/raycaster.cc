#include "sim/raycaster.h"

#include <embree3/rtcore.h>

#include <cmath>

#include "core/check.h"

namespace jvl::sim {

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  const Mesh* mesh = nullptr;
};

RayCaster::RayCaster(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  JVL_CHECK(!mesh.triangles.empty(), "scene mesh is empty");
  impl_->mesh = &mesh;
  // Embree picks its kernels by the CPU (SSE2 ... AVX-512) and they do not round alike: the
  // same scene gave hit distances one or two float ULPs apart with AVX2 (FMA) or AVX-512 kernels,
  // which moved scan points by ~1e-6 m and image pixels by a grey level. The SSE2 kernels run on
  // every x86-64 CPU (the SSE4.2 and AVX kernels give the same bytes), so the simulator writes the
  // same data on every machine; they cost about 25 % of sim_sequence's time.
  impl_->device = rtcNewDevice("threads=1,isa=sse2");
  JVL_CHECK(impl_->device != nullptr,
            "cannot create the Embree device (error " << rtcGetDeviceError(nullptr) << ")");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    v[3 * i] = mesh.vertices[i].x();
    v[3 * i + 1] = mesh.vertices[i].y();
    v[3 * i + 2] = mesh.vertices[i].z();
  }
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                             mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
  const RTCError err = rtcGetDeviceError(impl_->device);
  JVL_CHECK(err == RTC_ERROR_NONE, "Embree failed to build the scene BVH (error " << err << ")");
}

RayCaster::~RayCaster() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

namespace {

void FillHit(const Mesh& mesh, unsigned prim, float tfar, float nx, float ny, float nz,
             const Eigen::Vector3d& d, Hit* hit) {
  hit->t = tfar;
  hit->face = static_cast<int32_t>(mesh.triangle_face[prim]);
  hit->dynamic = -1;
  Eigen::Vector3d n(nx, ny, nz);
  n.normalize();
  if (n.dot(d) > 0) n = -n;
  hit->normal = n;
}

}  // namespace

Hit RayCaster::Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                         double t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(o.x());
  rh.ray.org_y = static_cast<float>(o.y());
  rh.ray.org_z = static_cast<float>(o.z());
  rh.ray.dir_x = static_cast<float>(d.x());
  rh.ray.dir_y = static_cast<float>(d.y());
  rh.ray.dir_z = static_cast<float>(d.z());
  rh.ray.tnear = static_cast<float>(t_min);
  rh.ray.tfar = static_cast<float>(t_max);
  rh.ray.mask = 0xFFFFFFFF;
  rh.ray.flags = 0;
  rh.ray.time = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  Hit hit;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    FillHit(*impl_->mesh, rh.hit.primID, rh.ray.tfar, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z, d,
            &hit);
  }
  return hit;
}

void RayCaster::Intersect8(const Eigen::Vector3d& o, const Eigen::Vector3d* d, int count,
                           double t_min, double t_max, Hit* hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(32) int valid[8];
  alignas(32) RTCRayHit8 rh;
  for (int i = 0; i < 8; ++i) {
    const bool on = i < count;
    const Eigen::Vector3d di = on ? d[i] : Eigen::Vector3d::UnitX();
    valid[i] = on ? -1 : 0;
    rh.ray.org_x[i] = static_cast<float>(o.x());
    rh.ray.org_y[i] = static_cast<float>(o.y());
    rh.ray.org_z[i] = static_cast<float>(o.z());
    rh.ray.dir_x[i] = static_cast<float>(di.x());
    rh.ray.dir_y[i] = static_cast<float>(di.y());
    rh.ray.dir_z[i] = static_cast<float>(di.z());
    rh.ray.tnear[i] = static_cast<float>(t_min);
    rh.ray.tfar[i] = static_cast<float>(t_max);
    rh.ray.mask[i] = 0xFFFFFFFF;
    rh.ray.flags[i] = 0;
    rh.ray.time[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect8(valid, impl_->scene, &context, &rh);
  for (int i = 0; i < count; ++i) {
    hits[i] = Hit();
    if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
      FillHit(*impl_->mesh, rh.hit.primID[i], rh.ray.tfar[i], rh.hit.Ng_x[i], rh.hit.Ng_y[i],
              rh.hit.Ng_z[i], d[i], &hits[i]);
    }
  }
}

void IntersectBoxes(const std::vector<Box>& boxes, const Eigen::Vector3d& o,
                    const Eigen::Vector3d& d, Hit* hit) {
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    if (b.size.x() <= 0) continue;
    // Bounding-sphere rejection before the exact test.
    const Eigen::Vector3d oc = b.center - o;
    const double along = oc.dot(d), r2 = 0.25 * b.size.squaredNorm();
    if (oc.squaredNorm() - along * along > r2 || (along < 0 && oc.squaredNorm() > r2)) continue;
    // Ray in the box frame (rotation about z by yaw), then the slab test.
    const double c = std::cos(b.yaw), s = std::sin(b.yaw);
    const Eigen::Vector3d r = o - b.center;
    const Eigen::Vector3d lo(c * r.x() + s * r.y(), -s * r.x() + c * r.y(), r.z());
    const Eigen::Vector3d ld(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    double t0 = 1e-3, t1 = hit->t;
    int axis = -1;
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      const double h = b.size[k] / 2;
      if (std::abs(ld[k]) < 1e-12) {
        miss = std::abs(lo[k]) > h;
        continue;
      }
      double ta = (-h - lo[k]) / ld[k], tb = (h - lo[k]) / ld[k];
      if (ta > tb) std::swap(ta, tb);
      if (ta > t0) {
        t0 = ta;
        axis = k;
      }
      t1 = std::min(t1, tb);
      miss = t0 > t1;
    }
    if (miss || axis < 0) continue;
    Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
    n_local[axis] = ld[axis] > 0 ? -1.0 : 1.0;
    hit->t = t0;
    hit->face = -1;
    hit->dynamic = static_cast<int32_t>(i);
    hit->normal = Eigen::Vector3d(c * n_local.x() - s * n_local.y(),
                                  s * n_local.x() + c * n_local.y(), n_local.z());
  }
}

}  // namespace jvl::sim
