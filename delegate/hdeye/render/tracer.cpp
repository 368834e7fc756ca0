// The tracer's path loop: a camera path's vertices, the BSDF-sampled continuation and Russian roulette.
#include "hdeye/render/tracer.h"

#include <algorithm>

namespace hdeye {

PathSample Tracer::Li(const WorldRay& ray, const RayCone& cone, SampleStream& rng, double time,
                      CameraReflection reflection) {
  SetTime(time);
  PathSample sample;
  // Referred to (not copied) by the path's EyeLighting, so it lives as long as the path.
  const auto transmittance = LightTransmittance();
  PathState path(ray, cone);
  path.eyeLighting = EyeLighting{&lights_, transmittance, -1, settings_.eyeSwitches};
  path.cameraReflection = reflection;
  TracePath(&path, 0, rng, &sample);
  // A reflection-only path ends at its first eye event, where it takes the glint part (TraceOnlyCameraReflection);
  // one that never got there brings nothing.
  if (reflection == CameraReflection::Only && path.part != kGlint) return PathSample{};
  return sample;
}

void Tracer::TracePath(PathState* pathState, int firstDepth, SampleStream& rng, PathSample* samplePtr) {
  PathState& path = *pathState;
  PathSample& sample = *samplePtr;
  for (int depth = firstDepth; depth <= settings_.maxDepth; ++depth) {
    SurfaceHit hit;
    const bool hitGeometry = Intersect(path.o, path.d, path.tNear, path.tFar, &hit, path.leavingEye);
    if (depth == 0) {
      sample.hitAny = hitGeometry;
      if (hitGeometry) sample.first.Set(hit);
    }
    const bool hideDomes = depth == 0 && !settings_.domeLightCameraVisibility;  // usdrecord's default look
    sample.L += LightsMet(path, hitGeometry ? hit.t : kInf, hideDomes);
    if (!hitGeometry) break;
    // Initialised in place (not assigned): a copy of the whole shading per vertex costs more than it seems.
    const bool eyeHit = EyeOf(*hit.context) != nullptr;
    SurfaceShading shading = eyeHit ? SurfaceShading{} : ShadeMaterialHit(&hit, path.d, path.cone);
    if (!eyeHit) {
      if (!shading.present && path.cutoutCrossings++ < kMaxCutoutCrossings) {
        // A cut-out: lights behind it were not yet tested; the next segment tests them, with this ray's weights.
        path.PassCutout(hit.t, hit.p);
        --depth;
        continue;
      }
      if (depth == 0) sample.first.n = hit.n;  // the normal AOV shows the normal map
    }
    path.fromPrim = hit.primIndex;  // the next ray leaves this vertex (light linking)
    sample.L += path.beta * hit.emission;
    if (const EyeGeometry* eye = EyeOf(*hit.context)) {
      rng.AlignToPair();  // the eye draws whole pairs (EyeLighting)
      // A moving eye is shaded with its frames at the path's time (where the ray met it).
      const std::optional<EyeGeometry> moved = eye->motion ? std::optional(eye->AtTime(time_)) : std::nullopt;
      const EyeOutcome outcome = ShadeEyeHit(moved ? *moved : *eye, depth, rng, &hit, &path, &sample);
      if (outcome == EyeOutcome::Continue) continue;
      if (outcome == EyeOutcome::End) break;
    }
    // Sclera (and any eye surface handed back to us) is Lambertian; everything else is the bound
    // UsdPreviewSurface.
    const bool eyeSurface = EyeOf(*hit.context) != nullptr;
    if (eyeSurface) shading.bsdf = PreviewSurface::Lambert(hit.albedo);  // an eye hit's shading is unused
    const PreviewSurface& bsdf = shading.bsdf;
    if (depth == 0 && !eyeSurface) sample.first.albedo = bsdf.albedo;  // the albedo AOV shows the texture
    const glm::dvec3 origin = SpawnOrigin(hit.p, hit.n, SpawnScaleOf(*hit.context));
    const PreviewSurfaceAt bsdfAt(bsdf, hit.n, -path.d);  // wo's Fresnel and lobes, shared by both
    const bool reflectionOnly = path.cameraReflection == CameraReflection::Only;
    if (!reflectionOnly) sample.L += SampleLd(hit, bsdfAt, origin, path.beta, rng);
    if (!SampleContinuation(hit, bsdf, bsdfAt, origin, depth, rng, &path)) break;
    if (reflectionOnly && !path.splitsAtCornea) break;  // past a diffuse bounce: no split to come
  }
  path.SwitchPart(path.part, &sample);
}

void Tracer::SetTime(double time) {
  time_ = time;
  rayTime_ = shutter_.RayTime(time);
  if (&lights_ == &lightsNow_)
    for (std::size_t k = 0; k < sourceLights_.size(); ++k) MoveLightTo(sourceLights_[k], time, &lightsNow_[k]);
}

bool Tracer::SampleContinuation(const SurfaceHit& hit, const PreviewSurface& bsdf, const PreviewSurfaceAt& bsdfAt,
                                const glm::dvec3& origin, int depth, SampleStream& rng, PathState* path) const {
  const double uLobe = rng.Next();
  double uDir1, uDir2;
  rng.Next2D(&uDir1, &uDir2);
  BsdfSample bs;
  if (!bsdfAt.Sample(path->insideGlass, uLobe, uDir1, uDir2, &bs)) return false;
  if (bs.transmitted && bsdf.thinWalled) {
    // Straight through a thin wall: the same ray, continued past the wall. Origin and weighting state stay
    // the previous vertex's, so a light met beyond is weighted (and its pdf taken) as from there, as next
    // event estimation saw it through the wall's transmittance.
    path->beta *= bs.weight;
    path->tNear = hit.t + SpawnOffset(hit.p, SpawnScaleOf(*hit.context));
    return RussianRoulette(depth, rng, path);
  }
  // Under a normal map, a direction on the wrong side of the surface itself ends the path (the energy a
  // shading normal cannot conserve); it would otherwise start inside the surface and hit it again.
  if (hit.normalMapped && (glm::dot(bs.wi, hit.ng) > 0) == bs.transmitted) return false;
  if (bs.transmitted) path->insideGlass = !path->insideGlass;
  path->bsdfPdf = bs.pdf;
  path->specular = bs.delta, path->skipLights = !bs.delta && !settings_.mis, path->skipMnee = false;
  path->splitsAtCornea = path->splitsAtCornea && bs.delta;  // only the camera's delta chain splits
  path->beta *= bs.weight;
  path->cone = path->cone.AfterBounce(hit.t, bs.delta);
  path->SetRay(glm::dot(bs.wi, hit.n) > 0 ? origin : SpawnOrigin(hit.p, -hit.n, SpawnScaleOf(*hit.context)), bs.wi);
  return RussianRoulette(depth, rng, path);
}

bool Tracer::RussianRoulette(int depth, SampleStream& rng, PathState* path) {
  if (depth < 3) return true;
  const double q = std::min(0.95, std::max({path->beta.x, path->beta.y, path->beta.z}));
  if (rng.Next() >= q) return false;
  path->beta /= q;
  return true;
}
}  // namespace hdeye
