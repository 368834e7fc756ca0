// The sclera random walk, run in the canonical eye frame, and the eye mesh's boundary for it.
// See scleraScattering.h.
#include "hdeye/render/scleraScattering.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

namespace hdeye {

ScleraExit ScatterInSclera(const EyeGeometry& eye, const glm::dvec3& entry, const glm::dvec3& inwardDir,
                           const glm::dvec3& scleraColor, const glm::dvec3& meanFreePathMm,
                           const WorldBoundary& boundary, eyelib::FunctionRef<double()> random,
                           const ScleraScatteringSettings& settings) {
  ScleraExit out;
  const double scale = eye.worldPerMm;  // world units per mm
  if (!boundary || !random || !std::isfinite(scale) || !(scale > 0)) return out;
  if (!eyelib::ValidateSssArtistParams(scleraColor, meanFreePathMm).empty()) return out;

  // The walk sees the eyeball in mm, canonical frame: each query maps there and back. Distances scale by
  // worldPerMm; the map is a similarity, so normals transform as directions. The exit is always the
  // last crossing the callback reports (the walk ends right after it), so the last normal is the exit's.
  glm::dvec3 lastNormal(0.0);
  const eyelib::SssBoundary canonical = [&](const glm::dvec3& o, const glm::dvec3& d, double tMax, double* t,
                                            glm::dvec3* n) {
    double tw = 0;
    glm::dvec3 nw(0.0);
    if (!boundary(eye.ToWorld(o), eye.DirToWorld(d), tMax * scale, &tw, &nw)) return false;
    *t = tw / scale;
    *n = glm::dot(nw, nw) > 0 ? eye.DirToCanonical(nw) : nw;  // a zero normal stays zero: the walk reports it
    lastNormal = nw;
    return true;
  };

  eyelib::RandomWalkSettings s;
  s.ior = settings.ior;
  s.g = settings.g;
  s.maxSteps = settings.maxSteps;
  s.teleport = settings.limbalArc;
  s.cylinder = eyelib::TeleportationCylinder(2 * eye.chamber.LimbusOuterRadius());
  const eyelib::SssMedium medium = eyelib::SssMediumFromArtist(scleraColor, meanFreePathMm);
  const eyelib::WalkResult w =
      eyelib::RandomWalkSss(medium, s, eye.ToCanonical(entry), eye.DirToCanonical(inwardDir), canonical, random);
  out.status = w.status;
  out.steps = w.steps;
  out.teleports = w.teleports;
  out.teleported = w.Teleported();
  out.weight = w.weight;
  if (w.status == eyelib::WalkStatus::Exited) {
    out.origin = eye.ToWorld(w.exitPoint);
    out.dir = eye.DirToWorld(w.exitDir);
    const double length = glm::length(lastNormal);
    out.normal = length > 0 && std::isfinite(length) ? lastNormal / length : out.dir;
    if (glm::dot(out.normal, out.dir) < 0) out.normal = -out.normal;
  }
  return out;
}

namespace {

constexpr int kMaxBackwardQueries = 8;

double MaxAbs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

/// The ray parameter at which o + t d leaves the box [lo, hi] (0 if o is already outside it).
double BoxExit(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& lo, const glm::dvec3& hi) {
  double t = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0)
      t = std::min(t, (hi[a] - o[a]) / d[a]);
    else if (d[a] < 0)
      t = std::min(t, (lo[a] - o[a]) / d[a]);
  }
  return std::max(0.0, t);
}

class MeshBoundaryQuery {
 public:
  MeshBoundaryQuery(RTCScene scene, const glm::dmat4& objectToWorld, std::int64_t* rays, MeshCrossing* last,
                    float rayTime)
      : scene_(scene),
        rayTime_(rayTime),
        worldToObject_(glm::inverse(objectToWorld)),
        normalToWorld_(glm::transpose(glm::inverse(glm::dmat3(objectToWorld)))),
        rays_(rays),
        last_(last) {
    RTCBounds b;
    rtcGetSceneBounds(scene, &b);
    // A margin of 1% of the box: the backward ray starts strictly outside the mesh.
    const glm::dvec3 lo(b.lower_x, b.lower_y, b.lower_z), hi(b.upper_x, b.upper_y, b.upper_z);
    const glm::dvec3 margin = 0.01 * (hi - lo) + glm::dvec3(1e-30);
    lo_ = lo - margin, hi_ = hi + margin;
  }

  bool operator()(const glm::dvec3& worldOrigin, const glm::dvec3& worldDir, double tMax, double* t,
                  glm::dvec3* normal) const {
    // Object space, the direction not normalised: the ray parameter stays the world one.
    const glm::dvec3 o(worldToObject_ * glm::dvec4(worldOrigin, 1));
    const glm::dvec3 d(worldToObject_ * glm::dvec4(worldDir, 0));
    const double dLength = glm::length(d);
    if (!(dLength > 0) || !std::isfinite(dLength) || !(tMax > 0)) return false;
    const double T = std::min(tMax, BoxExit(o, d, lo_, hi_));
    if (!(T > 0)) return false;
    const glm::dvec3 far = o + T * d;
    // Float rounding of the query (the origin and far point as floats, Embree's float hit distance)
    // moves a crossing by a few ulps of the largest coordinate involved: 16 of them, in the ray parameter.
    const double tNear = 16 * double(FLT_EPSILON) * std::max(MaxAbs(o), MaxAbs(far)) / dLength;
    if (!(T > tNear)) return false;

    RTCRayHit rh;
    double sNear = 0, best = -1;
    glm::dvec3 ng(0.0);
    MeshCrossing crossing;
    for (int k = 0; k < kMaxBackwardQueries; ++k) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rh.ray.org_x = float(far.x), rh.ray.org_y = float(far.y), rh.ray.org_z = float(far.z);
      rh.ray.dir_x = float(-d.x), rh.ray.dir_y = float(-d.y), rh.ray.dir_z = float(-d.z);
      rh.ray.tnear = float(sNear);
      rh.ray.tfar = float(T - tNear);  // s = T - t: t >= tNear
      rh.ray.mask = ~0u, rh.ray.flags = 0, rh.ray.time = rayTime_;
      rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      if (rays_) ++*rays_;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {  // none nearer the origin: the last one found is the closest
        if (best < 0) return false;
        *t = best;
        *normal = ng;
        if (last_) *last_ = crossing;
        return true;
      }
      const double s = rh.ray.tfar;
      best = T - s;
      const glm::dvec3 n = normalToWorld_ * glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
      const double nLength = glm::length(n);
      ng = nLength > 0 && std::isfinite(nLength) ? n / nLength : glm::dvec3(0.0);
      crossing = MeshCrossing{rh.hit.primID, rh.hit.u, rh.hit.v};
      sNear = s + tNear;                // past this crossing by its rounding bound
      if (!(sNear < T - tNear)) break;  // nothing nearer can be told apart from the origin's own surface
    }
    if (best >= 0 && !(sNear < T - tNear)) {
      *t = best;
      *normal = ng;
      if (last_) *last_ = crossing;
      return true;
    }
    // More crossings than the bound allows on one segment: report it (the walk ends as Invalid).
    *t = std::numeric_limits<double>::quiet_NaN();
    *normal = glm::dvec3(0.0);
    return true;
  }

 private:
  RTCScene scene_;
  float rayTime_;
  glm::dmat4 worldToObject_;
  glm::dmat3 normalToWorld_;
  glm::dvec3 lo_{0.0}, hi_{0.0};
  std::int64_t* rays_;
  MeshCrossing* last_;
};

}  // namespace

WorldBoundary EyeMeshBoundary(RTCScene prototype, const glm::dmat4& objectToWorld, std::int64_t* rays,
                              MeshCrossing* last, float rayTime) {
  if (!prototype) return {};
  return MeshBoundaryQuery(prototype, objectToWorld, rays, last, rayTime);
}

}  // namespace hdeye
