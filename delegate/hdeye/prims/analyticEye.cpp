#include "hdeye/prims/analyticEye.h"

#include "hdeye/prims/eyeParamsSync.h"
#include "hdeye/prims/motionSync.h"
#include "hdeye/prims/renderParam.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace hdeye {

namespace {

/// The first crossing of a ray with the eye, in the ray's own parameter: the cornea cap, or the
/// closing disk at the iris plane seen from behind.
/// worldToCanonical: the eye's frame at the ray's time.
/// cornea: where the hit is, when it is on the cornea.
bool IntersectEye(const EyeGeometry& eye, const glm::dmat4& worldToCanonical, const glm::dvec3& o, const glm::dvec3& d,
                  double tNear, double tFar, double* t, EyeGeometry::Part* part, glm::dvec3* worldNormal,
                  CorneaPoint* cornea = nullptr) {
  // Map without normalising the direction, so the ray parameter t is the world ray's.
  const glm::dvec3 oc(worldToCanonical * glm::dvec4(o, 1)), dc(worldToCanonical * glm::dvec4(d, 0));
  if (eye.chamber.Surface().HeadsAway(oc, dc)) return false;  // leaving the eye: its shadow rays, its exits
  bool hit = false;
  glm::dvec3 nc;
  if (const auto h = eye.chamber.Surface().Intersect({oc, dc}, tFar); h && h->t > tNear && h->fromOutside) {
    *t = h->t, *part = EyeGeometry::kCornea, nc = h->normal, hit = true;
    if (cornea) *cornea = {h->point, h->normal};
  }
  // The back: the plane of the iris, from below, inside the iris disk (pupil included: the lens).
  if (dc.z > 0 && oc.z < eye.chamber.IrisZ()) {
    const double tb = (eye.chamber.IrisZ() - oc.z) / dc.z;
    const glm::dvec3 q = oc + tb * dc;
    const double r2 = q.x * q.x + q.y * q.y, R = eye.chamber.IrisRadius();
    if (tb > tNear && tb < (hit ? *t : tFar) && r2 <= R * R)
      *t = tb, *part = EyeGeometry::kBack, nc = {0, 0, -1}, hit = true;
  }
  if (hit) *worldNormal = glm::normalize(glm::transpose(glm::dmat3(worldToCanonical)) * nc);
  return hit;
}

/// The eye's world-to-canonical frame at Embree ray time `rayTime` (its own when it does not move).
glm::dmat4 WorldToCanonicalAt(const EyeGeometry& eye, float rayTime) {
  if (!eye.motion) return eye.worldToCanonical;
  const EyeMotion& m = *eye.motion;
  return glm::inverse(m.prim->At(m.shutter.FrameTime(rayTime)) * m.canonicalInPrim);
}

/// Times a moving eye's bounds are measured at over the shutter: a turn of up to 180 degrees moves the box's corners
/// by at most 1 - cos(90 / 64 degrees) = 3e-4 of their radius between two of them, which the pad below covers.
constexpr int kBoundsTimes = 65;

void Bounds(const RTCBoundsFunctionArguments* args) {
  const auto* ctx = static_cast<const GeometryContext*>(args->geometryUserPtr);
  const EyeGeometry& eye = *ctx->eye;
  // The cap fits in a box of +-7.6 mm by 7.6 mm below the apex to slightly above it. A moving eye is one static
  // box over its whole sweep (its intersection evaluates the eye at each ray's time), padded by 0.1 mm.
  const double pad = eye.motion ? 0.1 : 0.0;
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dmat4& frame : eye.CanonicalToWorldOverShutter(kBoundsTimes))
    for (int k = 0; k < 8; ++k) {
      const glm::dvec3 corner(k & 1 ? 7.6 + pad : -7.6 - pad, k & 2 ? 7.6 + pad : -7.6 - pad,
                              k & 4 ? 0.1 + pad : -4.1 - pad);
      const glm::dvec3 w(frame * glm::dvec4(corner, 1));
      lo = glm::min(lo, w), hi = glm::max(hi, w);
    }
  RTCBounds* b = args->bounds_o;
  b->lower_x = float(lo.x), b->lower_y = float(lo.y), b->lower_z = float(lo.z);
  b->upper_x = float(hi.x), b->upper_y = float(hi.y), b->upper_z = float(hi.z);
}

void Intersect(const RTCIntersectFunctionNArguments* args) {
  const auto* ctx = static_cast<const GeometryContext*>(args->geometryUserPtr);
  EyeRayExchange& exchange = ThisThreadsEyeRays();
  if (exchange.leaving == ctx->eye) return;
  RTCRayHitN* rayhit = args->rayhit;
  RTCRayN* ray = RTCRayHitN_RayN(rayhit, args->N);
  RTCHitN* hitN = RTCRayHitN_HitN(rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    const glm::dvec3 o(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i));
    const glm::dvec3 d(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i));
    double t;
    EyeGeometry::Part part;
    glm::dvec3 n;
    CorneaPoint cornea;
    const EyeGeometry& eye = *ctx->eye;
    if (!IntersectEye(eye, WorldToCanonicalAt(eye, RTCRayN_time(ray, args->N, i)), o, d, RTCRayN_tnear(ray, args->N, i),
                      RTCRayN_tfar(ray, args->N, i), &t, &part, &n, &cornea))
      continue;
    RTCRayN_tfar(ray, args->N, i) = float(t);
    if (part == EyeGeometry::kCornea) exchange.cornea = {&eye, float(t), cornea};
    RTCHitN_Ng_x(hitN, args->N, i) = float(n.x);
    RTCHitN_Ng_y(hitN, args->N, i) = float(n.y);
    RTCHitN_Ng_z(hitN, args->N, i) = float(n.z);
    RTCHitN_u(hitN, args->N, i) = 0;
    RTCHitN_v(hitN, args->N, i) = 0;
    RTCHitN_primID(hitN, args->N, i) = part;
    RTCHitN_geomID(hitN, args->N, i) = args->geomID;
    RTCHitN_instID(hitN, args->N, i, 0) = args->context->instID[0];
  }
}

void Occluded(const RTCOccludedFunctionNArguments* args) {
  const auto* ctx = static_cast<const GeometryContext*>(args->geometryUserPtr);
  if (ThisThreadsEyeRays().leaving == ctx->eye) return;
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    const glm::dvec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                       RTCRayN_org_z(args->ray, args->N, i));
    const glm::dvec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                       RTCRayN_dir_z(args->ray, args->N, i));
    double t;
    EyeGeometry::Part part;
    glm::dvec3 n;
    const EyeGeometry& eye = *ctx->eye;
    if (IntersectEye(eye, WorldToCanonicalAt(eye, RTCRayN_time(args->ray, args->N, i)), o, d,
                     RTCRayN_tnear(args->ray, args->N, i), RTCRayN_tfar(args->ray, args->N, i), &t, &part, &n))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}

}  // namespace

void AnalyticEye::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  const DirtyBits bits = *dirtyBits;
  if (bits & (dirty::DirtyParams | dirty::InitRepr)) {
    SyncEyeParams(sceneDelegate, renderParam, "eye", Id(), &params_, &irisTexture_);
  }
  if (bits & (dirty::DirtyTransform | dirty::InitRepr)) {
    const PrimMotion synced = SyncTransformMotion(sceneDelegate, renderParam, Id(), "eye " + Id());
    transform_ = synced.transform;
    motion_ = synced.motion;
  }
  eye_ = EyeGeometry(params_, transform_);
  if (motion_)
    eye_.motion = std::make_shared<const EyeMotion>(
        EyeMotion{motion_, params_.modelTransform, renderParam ? renderParam->GetShutter() : Shutter{}});
  eye_.irisTexture = irisTexture_;
  if (!(eye_.worldPerMm > 0) || !std::isfinite(eye_.worldPerMm))
    throw std::runtime_error("eye " + Id() + ": its transform is degenerate");
  context_.eye = &eye_;
  RTCScene scene = renderParam->AcquireSceneForEdit();
  if (!geometry_) {
    geometry_ = rtcNewGeometry(renderParam->Device(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry_, 1);
    rtcSetGeometryUserData(geometry_, &context_);
    rtcSetGeometryBoundsFunction(geometry_, Bounds, nullptr);
    rtcSetGeometryIntersectFunction(geometry_, Intersect);
    rtcSetGeometryOccludedFunction(geometry_, Occluded);
    geometryId_ = rtcAttachGeometry(scene, geometry_);
  }
  if (bits & (dirty::DirtyVisibility | dirty::InitRepr)) {
    if (sceneDelegate->GetVisible(Id()))
      rtcEnableGeometry(geometry_);
    else
      rtcDisableGeometry(geometry_);
  }
  rtcCommitGeometry(geometry_);  // bounds follow the transform
  *dirtyBits = dirty::Clean;
}

void AnalyticEye::Finalize(RenderParam* renderParam) {
  if (!geometry_) return;
  rtcDetachGeometry(renderParam->AcquireSceneForEdit(), geometryId_);
  rtcReleaseGeometry(geometry_);
  geometry_ = nullptr;
}

}  // namespace hdeye
