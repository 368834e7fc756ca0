// The tracer's shadow rays: what fraction of a light passes the surfaces, thin walls and cut-outs on the way.
#include "hdeye/render/tracer.h"

#include <limits>
#include "hdeye/render/thinWalls.h"

namespace hdeye {

double Tracer::Transmittance(const RenderLight& light, const glm::dvec3& o, const glm::dvec3& d, double tFar,
                             const EyeGeometry* leaving) const {
  if (!light.unshadowed.empty()) return CrossSurfaces(light, o, d, tFar, leaving);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = float(o.x), ray.org_y = float(o.y), ray.org_z = float(o.z);
  ray.dir_x = float(d.x), ray.dir_y = float(d.y), ray.dir_z = float(d.z);
  ray.tnear = 0;
  ray.tfar = tFar < 3e38 ? float(tFar) : std::numeric_limits<float>::infinity();
  ray.mask = ~0u, ray.flags = 0, ray.time = rayTime_;
  ThinWallsMet::Reset();
  eyeRays_->leaving = leaving;
  rtcOccluded1(scene_, &context, &ray);
  eyeRays_->leaving = nullptr;
  ++counts_.rays;
  const bool blocked = ray.tfar < 0;
  if (blocked && !cutouts_) return 0;
  if (!blocked && !ThinWallsMet::Any()) return 1;
  return CrossSurfaces(light, o, d, tFar, leaving);
}

double Tracer::CrossSurfaces(const RenderLight& light, const glm::dvec3& o, const glm::dvec3& d, double tFar,
                             const EyeGeometry* leaving) const {
  double transmittance = 1, left = tFar;
  glm::dvec3 origin = o;
  for (int crossed = 0; crossed < kMaxCutoutCrossings; ++crossed) {
    SurfaceHit hit;
    if (!Intersect(origin, d, 0, left, &hit, leaving)) return transmittance;  // further along: still leaving
    if (CastsShadow(light, hit.primIndex) && !CutAway(hit, d)) {
      if (!IsThinWall(*hit.context)) return 0;  // an eye or an opaque surface
      transmittance *= ThinWallTransmittance(*hit.context, glm::dot(hit.ng, d));
      if (!(transmittance > 0)) return 0;
    }
    const glm::dvec3 next = SpawnOrigin(hit.p, -hit.ng);  // ng faces the ray: -ng is the far side
    left -= glm::length(next - origin);
    if (!(left > 0)) return transmittance;
    origin = next;
  }
  return 0;
}

bool Tracer::CutAway(const SurfaceHit& hit, const glm::dvec3& d) const {
  return cutouts_ && !EyeOf(*hit.context) && hit.material->params.opacityThreshold > 0 &&
         !ShadeMaterial(*hit.material, hit.albedo, -d, hit.n, SiteOf(hit, d, RayCone{})).present;
}
}  // namespace hdeye
