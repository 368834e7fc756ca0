// The tracer's lights: next event estimation and the lights a BSDF-sampled ray meets, weighted by MIS.
#include "hdeye/render/tracer.h"

#include <algorithm>

namespace hdeye {

namespace {

/// a^2 / (a^2 + b^2), as a ratio so that pdfs past 1e154 (a tiny light far away) do not overflow.
double PowerHeuristic(double a, double b) {
  if (!(a > 0)) return 0;
  const double q = b / a;
  return std::isfinite(q) ? 1 / (1 + q * q) : 0;
}

}  // namespace

glm::dvec3 Tracer::LightsMet(const PathState& path, double maxDistance, bool hideDomes) const {
  if (path.skipLights) return glm::dvec3(0);
  // Lights are not geometry: shadow rays pass through them, so a ray meets every light along it before the geometry
  // it hits (a dome behind a rect included), each weighted as next event estimation would have sampled it.
  glm::dvec3 sum(0);
  for (std::size_t k = 0; k < lights_.size(); ++k) {
    const RenderLight& l = lights_[k];
    if (path.skipMnee && MneeCountsLight(path.skipMneeOf, k)) continue;
    if (hideDomes && l.type == LightType::Dome) continue;
    if (!Illuminates(l, path.fromPrim)) continue;
    glm::dvec3 le(0);
    double lpdf = 0, distance = kInf;
    if (!IntersectLight(l, path.o, path.d, maxDistance, &le, &lpdf, &distance) || distance < path.tNear) continue;
    if (path.specular)
      sum += le;
    else if (settings_.mis)
      sum += le * PowerHeuristic(path.bsdfPdf, lpdf * LightSelectPdf());
  }
  return path.beta * sum;
}

glm::dvec3 Tracer::SampleLd(const SurfaceHit& hit, const PreviewSurfaceAt& bsdf, const glm::dvec3& origin,
                            const glm::dvec3& beta, SampleStream& rng) const {
  const double uPick = rng.Next();
  double u1, u2;
  rng.Next2D(&u1, &u2);
  if (lights_.empty() || !bsdf.HasSmoothLobe()) return glm::dvec3(0);
  if (!SamplesEveryLight())
    return beta * SampleLdFrom(lights_[std::min(lights_.size() - 1, std::size_t(uPick * lights_.size()))], hit, bsdf,
                               origin, u1, u2);
  glm::dvec3 sum(0);
  for (const RenderLight& light : lights_) sum += SampleLdFrom(light, hit, bsdf, origin, u1, u2);
  return beta * sum;
}

glm::dvec3 Tracer::SampleLdFrom(const RenderLight& light, const SurfaceHit& hit, const PreviewSurfaceAt& bsdf,
                                const glm::dvec3& origin, double u1, double u2) const {
  if (!Illuminates(light, hit.primIndex)) return glm::dvec3(0);
  const LightSample ls = SampleLight(light, origin, u1, u2);
  const double cosS = glm::dot(ls.dir, hit.n);
  if (!(ls.pdf > 0 && cosS > 0)) return glm::dvec3(0);
  // A normal map may tilt the shading normal towards a light below the surface itself: no light there.
  if (hit.normalMapped && glm::dot(ls.dir, hit.ng) <= 0) return glm::dvec3(0);
  double bsdfPdf;
  const glm::dvec3 f = bsdf.EvalAndPdf(ls.dir, &bsdfPdf);
  if (!(f.x > 0 || f.y > 0 || f.z > 0)) return glm::dvec3(0);
  const double transmittance = Transmittance(light, origin, ls.dir, ls.distance * (1 - 1e-6));
  if (!(transmittance > 0)) return glm::dvec3(0);
  const double pl = ls.pdf * LightSelectPdf();
  // A delta light (a point, a parallel beam) is found by light sampling alone: weight 1.
  const double w = settings_.mis && !ls.delta ? PowerHeuristic(pl, bsdfPdf) : 1.0;
  return f * ls.radiance * (cosS * w * transmittance / pl);
}
}  // namespace hdeye
