// The tracer at an eye: the eye's switches, MNEE's light choice and chamber cache, the cornea's reflected branch.
#include "hdeye/render/tracer.h"

#include <algorithm>
#include <atomic>
#include <optional>

namespace hdeye {

namespace {

/// What one eye renders with: the render plan's (EyeRenderOptions, written by ApplyRenderPlan), else the render
/// settings' switches (the limbal arc only where the eye's own EyeParams::limbalArc also asks for it).
struct ResolvedEye {
  EyeSwitches switches;
  const std::vector<bool>* mneeLights = nullptr;  ///< null: MNEE counts every light
  int maxChamberEvents = 64;
};

ResolvedEye ResolveEye(const EyeRenderOptions& options, const EyeGeometry& eye, const RenderSettings& settings) {
  if (options.planned) return {options.switches, &options.mneeLights, options.maxChamberEvents};
  static const EyeRenderOptions kUnplanned;  // the walk bound of an eye no plan was applied to
  EyeSwitches switches = settings.eyeSwitches;
  switches.limbalArc = switches.limbalArc && eye.limbalArc;
  return {switches, nullptr, kUnplanned.maxChamberEvents};
}

/// The eye's event at a hit of the ray from o along unit d: an analytic eye's, or an eye mesh's mapped onto it.
EyeEvent ScatterAtHit(const EyeGeometry& eye, const SurfaceHit& hit, const glm::dvec3& o, const glm::dvec3& d,
                      const EyeLighting& lighting, eyelib::FunctionRef<double()> random) {
  const GeometryContext& ctx = *hit.context;
  return ctx.eye
             ? ScatterAtEye(eye, o, d, EyeGeometry::Part(hit.part), lighting, random, hit.cornea)
             : ScatterAtEyeMesh(eye, EyeMeshHitToCanonical(ctx, eye, hit.part, hit.u, hit.v, d), d, lighting, random);
}

}  // namespace

bool Tracer::SeesCatchlight(const WorldRay& ray, double time) {
  SetTime(time);
  SurfaceHit hit;
  if (!Intersect(ray.origin, ray.dir, ray.tNear, ray.tFar, &hit)) return false;
  const EyeGeometry* found = EyeOf(*hit.context);
  if (!found) return false;
  const std::optional<EyeGeometry> moved = found->motion ? std::optional(found->AtTime(time_)) : std::nullopt;
  const auto transmittance = LightTransmittance();
  EyeLighting lighting{&lights_, transmittance, hit.primIndex, settings_.eyeSwitches};
  lighting.splitAtEntry = lighting.reflectionOnly = true;
  // The entry's two numbers (limbus, Fresnel) fixed: the cornea unless the limbus is all sclera there.
  const auto fixed = [] { return 1 - 1e-9; };
  const EyeEvent ev = ScatterAtHit(moved ? *moved : *found, hit, ray.origin, ray.dir, lighting, fixed);
  if (!(ev.reflection.weight > 0)) return false;
  const glm::dvec3 &o = ev.reflection.origin, &d = ev.reflection.dir;
  // The nearest light the mirror direction meets, then one ray to see whether geometry comes first: most corners
  // meet no light and cast no second ray.
  double nearest = kInf;
  bool met = false;
  for (const RenderLight& light : lights_) {
    if (light.type == LightType::Dome || !Illuminates(light, hit.primIndex)) continue;
    glm::dvec3 le(0);
    double pdf = 0, distance = kInf;
    if (IntersectLight(light, o, d, kInf, &le, &pdf, &distance) && (le.x > 0 || le.y > 0 || le.z > 0))
      met = true, nearest = std::min(nearest, distance);
  }
  if (!met) return false;
  SurfaceHit blocker;
  return !Intersect(o, d, 0, nearest, &blocker, hit.context->eye);
}

const std::vector<double>& Tracer::MneePickOf(const GeometryContext& ctx, const EyeLighting& lighting) {
  LastMneePick& last = lastMneePick_;
  if (last.ctx != &ctx || last.receiver != lighting.receiver || last.mask != lighting.mneeLights) {
    EyeLighting still = lighting;
    still.lights = &sourceLights_;
    last = {&ctx, lighting.receiver, lighting.mneeLights, MneeLightPick(*EyeOf(ctx), still)};
  }
  return last.pick;
}

const eyelib::IrisChamberCache* Tracer::ChamberCacheOf(const GeometryContext& ctx, const EyeGeometry& eye,
                                                       const EyeLighting& lighting) {
  // Successive eye hits are mostly the same eye's: the last cache is kept so that they skip the shared map's
  // lock and key (and, under an open shutter, moving the lights to the opening and back).
  const EyeGeometry& still = shutter_.IsOpen() ? *EyeOf(ctx) : eye;
  LastChamberCache& last = lastChamberCache_;
  if (last.cache && last.ctx == &ctx && last.receiver == lighting.receiver && last.frame == still.canonicalToWorld)
    return last.cache;
  const int rings = ctx.eyeOptions.planned ? ctx.eyeOptions.chamberCacheRings : 0;
  // The build's shadow rays, on whichever thread joins it: a tracer of that thread's own, at this path's time.
  std::atomic<std::int64_t> buildRays{0};
  const auto perThread = [&](eyelib::FunctionRef<void(const EyeLighting&)> body) {
    Tracer here(scene_, sourceLights_, settings_, cutouts_, shutter_, chamberCaches_);
    here.SetTime(time_);
    const auto transmittance = here.LightTransmittance();
    EyeLighting own = lighting;
    own.lights = &here.lights_;
    own.transmittance = transmittance;
    // The tables at hand are per tracer: each thread of the build takes its own from the shared ones.
    if (own.entryTables) own.entryTables = &here.entryTables_;
    body(own);
    buildRays += here.counts_.rays;
  };
  std::shared_ptr<const eyelib::IrisChamberCache> cache;
  if (!shutter_.IsOpen()) {
    cache = chamberCaches_->Get(&ctx, eye, lighting, rings, perThread);
  } else {
    const double pathTime = time_;
    SetTime(shutter_.open);
    const std::optional<EyeGeometry> atOpen = still.motion ? std::optional(still.AtTime(shutter_.open)) : std::nullopt;
    cache = chamberCaches_->Get(&ctx, atOpen ? *atOpen : still, lighting, rings, perThread);
    SetTime(pathTime);
  }
  counts_.rays += buildRays;
  const auto held = std::find(heldChamberCaches_.begin(), heldChamberCaches_.end(), cache);
  if (cache && held == heldChamberCaches_.end()) heldChamberCaches_.push_back(cache);
  last = {&ctx, lighting.receiver, still.canonicalToWorld, cache.get()};
  return cache.get();
}

EyeOutcome Tracer::ShadeEyeHit(const EyeGeometry& eye, int depth, SampleStream& rng, SurfaceHit* hit, PathState* path,
                               PathSample* sample) {
  const auto random = [&rng] { return rng.Next(); };
  const GeometryContext& ctx = *hit->context;
  const ResolvedEye resolved = ResolveEye(ctx.eyeOptions, eye, settings_);
  EyeLighting& lighting = path->eyeLighting;
  lighting.switches = resolved.switches;
  lighting.mneeLights = resolved.mneeLights;
  lighting.maxChamberEvents = resolved.maxChamberEvents;
  lighting.irisLightSplits = settings_.irisLightSplits;
  lighting.chamberSplits = settings_.chamberSplits;
  lighting.receiver = hit->primIndex;
  lighting.chamberEstimator = settings_.chamberEstimator;
  lighting.splitAtEntry = path->splitsAtCornea && path->specular;
  const bool firstEyeVisit = path->part == kNonEye;
  lighting.reflectionOnly = path->cameraReflection == CameraReflection::Only && firstEyeVisit;
  lighting.mneePick = lighting.switches.mnee ? &MneePickOf(ctx, lighting) : nullptr;
  // Tables only for a still eye (and, in IrisIrradianceFromLight, a still light): a moving one's key changes from
  // sample to sample.
  const bool tabulated = settings_.mneeEntryTables && lighting.switches.mnee && !eye.motion && chamberCaches_;
  lighting.entryTables = tabulated ? &entryTables_ : nullptr;
  const bool cached = lighting.switches.mnee && chamberCaches_ && settings_.chamberEstimator != ChamberEstimator::Path;
  lighting.chamberCache = cached ? ChamberCacheOf(ctx, eye, lighting) : nullptr;
  const EyeEvent ev = ScatterAtHit(eye, *hit, path->o, path->d, lighting, random);
  const bool firstEyeEvent = firstEyeVisit && !ev.passThrough;
  if (path->cameraReflection == CameraReflection::Only && firstEyeEvent)
    return TraceOnlyCameraReflection(ev, depth, *hit, path, rng, sample);
  if (firstEyeEvent)
    path->SwitchPart(ev.kind == EyeEvent::Sclera ? kSclera : ev.reflectedAtEntry ? kGlint : kIris, sample);
  sample->L += path->beta * ev.radiance;
  sample->irisMnee += path->beta * ev.radiance;
  if (ev.reflection.weight > 0) {
    path->splitsAtCornea = false;
    path->SwitchPart(path->part, sample);
    if (!(firstEyeEvent && path->cameraReflection == CameraReflection::Left))
      TraceCorneaReflection(ev.reflection, firstEyeEvent ? kGlint : path->part, depth, *hit, *path, rng, sample);
    path->lMark = sample->L;  // what the branch gathered is in its own part
  }
  if (ev.kind == EyeEvent::Continue) {
    path->beta *= ev.weight;
    path->cone = path->cone.AfterBounce(hit->t, true);
    path->SetRay(ev.origin, ev.dir);
    // Every ray an analytic eye continues leaves its cornea outwards (its exits and reflections).
    path->leavingEye = ctx.eye;
    if (!ev.passThrough) {
      path->specular = true, path->skipLights = false, path->skipMnee = ev.skipLightHits;
      if (path->skipMnee) path->skipMneeOf = lighting;
    }
    return EyeOutcome::Continue;
  }
  if (ev.kind == EyeEvent::Absorbed) return EyeOutcome::End;
  ShadeScleraSurface(eye, ev, path->d, path->cone, hit);
  if (depth == 0) sample->first.albedo = hit->albedo;  // the albedo AOV shows the sclera's
  // An eye mesh's sclera is a volume: the path walks through it instead of bouncing off a Lambert surface
  // (only meshes have a closed eyeball to walk in; the analytic eye's sclera stays diffuse).
  if (ev.scleraOnSurface && resolved.switches.scleraScattering && ctx.prototypeScene)
    return EnterSclera(eye, resolved.switches.limbalArc, random, hit, path, sample);
  return EyeOutcome::ShadeSurface;
}

void Tracer::TraceCorneaReflection(const EyeEvent::Branch& reflection, EyePart part, int depth, const SurfaceHit& hit,
                                   const PathState& path, SampleStream& rng, PathSample* sample) {
  PathState branch = path;
  branch.part = part;
  branch.lMark = sample->L;
  branch.beta *= reflection.weight;
  branch.cone = path.cone.AfterBounce(hit.t, true);
  branch.SetRay(reflection.origin, reflection.dir);
  branch.leavingEye = hit.context->eye;  // an analytic eye's reflection leaves its cornea outwards
  branch.SetSpecular();
  TracePath(&branch, depth + 1, rng, sample);
}

EyeOutcome Tracer::TraceOnlyCameraReflection(const EyeEvent& ev, int depth, const SurfaceHit& hit, PathState* path,
                                             SampleStream& rng, PathSample* sample) {
  *sample = PathSample{};  // what the path met before its first eye event is the main path's
  path->lMark = glm::dvec3(0);
  path->part = kGlint;
  if (ev.reflection.weight > 0) TraceCorneaReflection(ev.reflection, kGlint, depth, hit, *path, rng, sample);
  path->lMark = sample->L;  // the branch put its light in its part
  return EyeOutcome::End;
}

void Tracer::ShadeScleraSurface(const EyeGeometry& eye, const EyeEvent& ev, const glm::dvec3& d, const RayCone& cone,
                                SurfaceHit* hit) const {
  if (!ev.scleraOnSurface) hit->n = glm::dot(ev.normal, d) > 0 ? -ev.normal : ev.normal;
  if (!ev.scleraOnSurface || !eye.scleraUsesMaterial)
    hit->albedo = ev.scleraAlbedo;
  else
    hit->albedo = TexturedAlbedo(*hit->material, hit->albedo, SiteOf(*hit, d, cone));
  hit->albedo = glm::clamp(hit->albedo, glm::dvec3(0), glm::dvec3(1));  // an albedo above 1 adds energy
}
}  // namespace hdeye
