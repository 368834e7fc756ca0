// The sclera random walk, run in the canonical eye frame. See scleraScattering.h.
#include "hdeye/scleraScattering.h"

#include <cmath>

namespace hdeye {

ScleraExit ScatterInSclera(const EyeGeometry& eye, const glm::dvec3& entry, const glm::dvec3& inwardDir,
                           const glm::dvec3& scleraColor, const glm::dvec3& meanFreePathMm,
                           const WorldBoundary& boundary, const std::function<double()>& random,
                           const ScleraScatteringSettings& settings) {
  ScleraExit out;
  const double scale = eye.worldPerMm;  // world units per mm
  if (!boundary || !random || !std::isfinite(scale) || !(scale > 0)) return out;

  // The walk sees the eyeball in mm, canonical frame: each query maps there and back. Distances scale by
  // worldPerMm; the map is a similarity, so normals transform as directions.
  const eyelib::SssBoundary canonical = [&](const glm::dvec3& o, const glm::dvec3& d, double tMax, double* t,
                                            glm::dvec3* n) {
    double tw = 0;
    glm::dvec3 nw(0.0);
    if (!boundary(eye.ToWorld(o), eye.DirToWorld(d), tMax * scale, &tw, &nw)) return false;
    *t = tw / scale;
    *n = eye.DirToCanonical(nw);
    return true;
  };

  eyelib::RandomWalkSettings s;
  s.ior = settings.ior;
  s.g = settings.g;
  s.maxSteps = settings.maxSteps;
  s.teleport = settings.limbalArc;
  s.cylinder = eyelib::TeleportationCylinder(2 * eye.chamber.LimbusOuterRadius());
  const eyelib::SssMedium medium = eyelib::SssMediumFromArtist(scleraColor, meanFreePathMm);
  const eyelib::WalkResult w = eyelib::RandomWalkSss(medium, s, eye.ToCanonical(entry),
                                                     eye.DirToCanonical(inwardDir), canonical, random);
  out.status = w.status;
  out.steps = w.steps;
  out.teleported = w.Teleported();
  out.weight = w.weight;
  if (w.status == eyelib::WalkStatus::Exited) {
    out.origin = eye.ToWorld(w.exitPoint);
    out.dir = eye.DirToWorld(w.exitDir);
  }
  return out;
}

}  // namespace hdeye
