// The tracer in an eye mesh's sclera: the wet surface's Fresnel choice, then eyelib's random walk to the exit.
#include "hdeye/render/tracer.h"

#include <eyelib/optics.h>
#include <algorithm>

namespace hdeye {

EyeOutcome Tracer::EnterSclera(const EyeGeometry& eye, bool limbalArc, eyelib::FunctionRef<double()> random,
                               SurfaceHit* hit, PathState* path, PathSample* sample) const {
  const ScleraStep step = ScleraWalk(eye, *hit, path->d, hit->albedo, limbalArc, random);
  if (step.kind == ScleraStep::Ended) return EyeOutcome::End;
  if (step.kind == ScleraStep::Reflected) {  // a delta lobe: lights it meets count in full
    path->cone = path->cone.AfterBounce(hit->t, true);
    path->SetRay(step.origin, step.dir);
    path->SetSpecular();
    return EyeOutcome::Continue;
  }
  // The exit is a diffuse transmission lobe: the walk decides where light leaves and how much (its Fresnel
  // test at the boundary included); the direction it leaves in is then taken as Lambertian about the exit's
  // outward normal, as Cycles and Hyperion do. The walk's own refracted exit direction is dropped, not
  // followed: its pdf is unknown (it depends on the whole walk), so it could be neither MIS-weighted against
  // light sampling nor combined with next event estimation at the exit without counting the light twice.
  // With a Lambertian lobe, next event estimation and the sampled continuation are weighted by the power
  // heuristic like any diffuse bounce. What this approximates: light refracted out of a dielectric is
  // Lambertian times (1 - F(theta)), a little darker at grazing exit.
  if (path->part != kLimbalArc && step.teleported) path->SwitchPart(kLimbalArc, sample);
  path->beta *= step.weight;
  hit->p = step.point;
  hit->n = hit->ng = step.normal;
  hit->albedo = glm::dvec3(1);  // the colour is in the walk's weight
  path->d = -step.normal;       // wo = the outward normal: the lobe is the outward hemisphere
  return EyeOutcome::ShadeSurface;
}

Tracer::ScleraStep Tracer::ScleraWalk(const EyeGeometry& eye, const SurfaceHit& hit, const glm::dvec3& d,
                                      const glm::dvec3& albedo, bool limbalArc,
                                      eyelib::FunctionRef<double()> random) const {
  ScleraStep step;
  const double ior = eye.chamber.CorneaIor();
  // Fresnel against the shading normal (smooth highlights); which side is inside, against the
  // geometric one (the walk's boundary is the triangles themselves).
  const glm::dvec3 wo = -d;
  const double cosO = std::max(0.0, glm::dot(wo, hit.n));
  if (random() < eyelib::FresnelDielectric(cosO, ior)) {
    step.kind = ScleraStep::Reflected;
    step.dir = eyelib::Reflect(wo, hit.n);
    // A shading normal can tilt the mirror direction under the triangle: lift it just above.
    const double cosG = glm::dot(step.dir, hit.ng);
    if (cosG < 1e-4) step.dir = glm::normalize(step.dir + (1e-4 - cosG) * hit.ng);
    step.origin = SpawnOrigin(hit.p, hit.ng, eye.SpawnScale());
    return step;
  }
  glm::dvec3 inward;
  if (!eyelib::Refract(wo, hit.n, ior, &inward)) return step;  // cannot happen from outside (ior >= 1)
  // The refracted direction must enter the triangle the ray met (hit.ng faces the ray: inside is -ng).
  const double cosIn = glm::dot(inward, hit.ng);
  if (cosIn > -1e-4) inward = glm::normalize(inward - (cosIn + 1e-4) * hit.ng);

  // The walk meets the mesh as it is now (deformed or not): its own triangles, placed by the prim
  // transform; the cylinder lives in the eye's canonical frame (ScatterInSclera), so it follows the eye.
  std::int64_t queries = 0;
  MeshCrossing exitCrossing;
  const WorldBoundary boundary =
      EyeMeshBoundary(hit.context->prototypeScene, eye.objectToWorld, &queries, &exitCrossing, rayTime_);
  ScleraScatteringSettings ws;
  ws.ior = ior;
  ws.limbalArc = limbalArc;
  const ScleraExit exit = ScatterInSclera(eye, hit.p, inward, albedo, eye.scleraMeanFreePath, boundary, random, ws);
  CountWalk(exit, queries);
  if (!exit.Exited()) return step;

  step.kind = ScleraStep::Exited;
  step.point = exit.origin;
  step.weight = exit.weight;
  step.teleported = exit.teleported;
  step.normal = ExitShadingNormal(*hit.context, exitCrossing, exit.normal);
  return step;
}

void Tracer::CountWalk(const ScleraExit& exit, std::int64_t queries) const {
  counts_.rays += queries;
  ++counts_.walks;
  if (exit.teleported) ++counts_.teleportedWalks;
  if (exit.status == eyelib::WalkStatus::Capped) ++counts_.cappedWalks;
  if (exit.status == eyelib::WalkStatus::Invalid) ++counts_.invalidWalks;
}

glm::dvec3 Tracer::ExitShadingNormal(const GeometryContext& ctx, const MeshCrossing& crossing,
                                     const glm::dvec3& outward) {
  if (!ctx.vertexNormals || !ctx.triangleVertices || crossing.triangle == RTC_INVALID_GEOMETRY_ID ||
      3 * std::size_t(crossing.triangle) + 2 >= ctx.triangleVertices->size())
    return outward;
  const int* tri = &(*ctx.triangleVertices)[3 * std::size_t(crossing.triangle)];
  const WorldNormal shading(ctx.normalToWorld, InterpolateAtTriangle(*ctx.vertexNormals, tri, crossing.u, crossing.v));
  return shading.Valid() && glm::dot(shading.v, outward) > 0 ? shading.v / shading.length : outward;
}
}  // namespace hdeye
