#include "hdeye/render/eyeShading.h"

#include "hdeye/render/entryTables.h"
#include "hdeye/render/sampleDirections.h"
#include "hdeye/render/surfacePoint.h"

#include <eyelib/eye_constants.h>
#include <eyelib/mnee.h>
#include <eyelib/optics.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hdeye {

namespace {

using eyelib::paper::kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The angular error of Snell's law (radians) at which a render's MNEE solve stops: a cornea point within about
/// 1e-8 mm of the path's, far below anything an image resolves. Newton converges quadratically, so eyelib's default
/// 1e-11 often costs one more iteration for nothing the image can show.
constexpr double kRenderMneeTolerance = 1e-8;

/// World offset for spawning a ray off the eye's surface along world normal n.
glm::dvec3 Offset(const EyeGeometry& eye, const glm::dvec3& p, const glm::dvec3& n) {
  return p + n * (1e-6 * eye.worldPerMm * 8 + 1e-7 * glm::length(p));
}

using ChamberHit = eyelib::ChamberSurfaceHit<double>;

/// Chamber directions per side of the lattice the control variate integrates its prediction over at the first iris
/// vertex (kControlSide^2 directions, one random shift for all): 2 x 2, measured against 1, 3 x 3 and 4 x 4 in
/// docs/iris_benchmark.md (one direction is noisier than the walk itself; more than four cost more than they gain).
constexpr int kControlSide = 2;

/// An unbiased estimate of the chamber irradiance the cache predicts at iris point x (canonical mm): the cache's
/// irradiance where a shifted lattice of chamber paths from x lands, times the iris albedo there and the paths'
/// Fresnel weights (the cosine-weighted hemisphere integral of eyelib's IrisChamberTransport, at x itself).
template <class Random> glm::dvec3 PredictedChamberLight(const EyeGeometry& eye, const eyelib::IrisChamberCache& cache,
                                                         const glm::dvec3& x, const EyeLighting& lighting,
                                                         const Random& random) {
  const double u1 = random(), u2 = random();
  glm::dvec3 E(0);
  for (int a = 0; a < kControlSide; ++a)
    for (int b = 0; b < kControlSide; ++b) {
      double share;
      const glm::dvec3 d = eyelib::ChamberDirection(a, b, kControlSide, u1, u2, &share);
      const eyelib::ChamberReturn back = eyelib::TraceChamberReturn(eye.chamber, x, d, lighting.maxChamberEvents);
      if (back.weight > 0) E += (share * back.weight) * eye.IrisAlbedo(back.point) * cache.Irradiance(back.point);
    }
  return E;
}

/// The iris's diffuse reflection at x (canonical mm), the walk's `vertex`-th iris vertex (1 the first): albedo / pi
/// times the mean of `splits` MNEE estimates of its direct light and the chamber estimator's term. Path: MNEE alone at
/// every vertex. Cache: at the first vertex also the cached chamber light, nothing after. ControlVariate: at the first
/// vertex also an unbiased estimate of the cache's chamber light, at the second minus the cache's prediction of what
/// this and every later vertex bring (its mean over the first vertex's bounce is what the first added, so the mean
/// is the path's whatever the cache's error).
glm::dvec3 IrisDirectLight(const EyeGeometry& eye, const glm::dvec3& x, const glm::dvec3& albedo, int vertex,
                           const EyeLighting& lighting, eyelib::FunctionRef<double()> random, int splits) {
  const eyelib::IrisChamberCache* cache = lighting.chamberCache;
  const ChamberEstimator estimator = cache ? lighting.chamberEstimator : ChamberEstimator::Path;
  if (estimator == ChamberEstimator::Cache && vertex > 1) return glm::dvec3(0);
  glm::dvec3 E(0);
  for (int i = 0; i < splits; ++i) E += IrisIrradianceMnee(eye, x, lighting, random);
  E /= double(splits);
  if (estimator == ChamberEstimator::Cache) E += cache->Chamber(x);
  if (estimator == ChamberEstimator::ControlVariate && vertex == 1)
    E += PredictedChamberLight(eye, *cache, x, lighting, random);
  if (estimator == ChamberEstimator::ControlVariate && vertex == 2) E -= cache->Irradiance(x);
  return (albedo / kPi) * E;
}

/// A cosine-distributed direction off the iris plane into the chamber (+z, canonical); one 2D sample (two draws).
glm::dvec3 IrisBounce(eyelib::FunctionRef<double()> random) {
  const double u1 = random(), u2 = random();
  return CosineHemisphereLocal(u1, u2);
}

/// Whether MNEE counts every light that illuminates the eye. Only then do the iris bounces play Russian roulette: a
/// light MNEE leaves out (too large, too grazing, or switched off) reaches the iris only through the walk's exit,
/// whose every path it needs.
bool MneeCountsEveryLight(const EyeLighting& lighting) {
  for (std::size_t k = 0; k < lighting.lights->size(); ++k)
    if (Illuminates((*lighting.lights)[k], lighting.receiver) && !MneeCountsLight(lighting, k)) return false;
  return true;
}

/// Russian roulette at an iris bounce, on the walk's throughput `beta` (which carries the 1 / n^2 of the entry; what
/// leaves the eye carries beta n^2): the walk goes on with probability q = min(1, max(beta n^2)), as pbrt does past a
/// path's first bounce, and its throughput is divided by q. What it carries on is the chamber light and the light of
/// surfaces seen through the exit (MNEE has the lights): a dark iris's walks mostly end where they would carry
/// little, and what the surviving ones gather is unbiased. Draws a pair (the second unused) only when q < 1.
bool SurvivesRoulette(double ior, eyelib::FunctionRef<double()> random, glm::dvec3* beta) {
  const double q = std::max({beta->x, beta->y, beta->z}) * (ior * ior);
  if (!(q < 1)) return true;
  const double u = random();
  random();
  if (!(u < q)) return false;
  *beta /= q;
  return true;
}

/// Whether a walk meeting the cornea from inside (unit d, outward normal n) reflects (Fresnel, 1 under total
/// internal reflection) rather than leaves. Draws two numbers (the second unused) so the walk's next draws start on
/// a pair.
bool ReflectsInside(const glm::dvec3& d, const glm::dvec3& n, double ior, eyelib::FunctionRef<double()> random) {
  const double u = random();
  random();
  return u < eyelib::FresnelDielectric(glm::dot(-d, n), ior);
}

/// The iris light a chamber walk leaving iris point x (a diffuse bounce, unit throughput) gathers before it leaves
/// the eye or is absorbed, within `maxEvents` events; what leaves the eye is not followed (the walk the path goes on
/// with carries that).
glm::dvec3 GatherFromIris(const EyeGeometry& eye, const glm::dvec3& x, const EyeLighting& lighting,
                          eyelib::FunctionRef<double()> random, int maxEvents) {
  glm::dvec3 gathered(0), beta(1), p = x, d = IrisBounce(random);
  const double ior = eye.chamber.CorneaIor();
  int vertex = 1;  // x is the walk's first iris vertex
  for (int k = 0; k < maxEvents; ++k) {
    const ChamberHit hit = eye.chamber.NextSurfaceFromInside(p, d);
    if (hit.kind == ChamberHit::Iris) {
      const glm::dvec3 albedo = eye.IrisAlbedo(hit.point);
      if (lighting.switches.mnee)
        gathered += beta * IrisDirectLight(eye, hit.point, albedo, ++vertex, lighting, random, 1);
      d = IrisBounce(random);
      beta *= albedo;
      p = hit.point;
    } else if (hit.kind == ChamberHit::Cornea && ReflectsInside(d, hit.normal, ior, random)) {
      d = d - 2 * glm::dot(d, hit.normal) * hit.normal;
      p = hit.point;
    } else {
      break;
    }
  }
  return gathered;
}

/// The camera path's walk inside the chamber from cornea point p (mm) along the refracted direction d: the light it
/// gathers at iris vertices (times gatherScale) and where it leaves the eye, or how it ends.
EyeEvent WalkChamber(const EyeGeometry& eye, glm::dvec3 p, glm::dvec3 d, const EyeLighting& lighting,
                     eyelib::FunctionRef<double()> random, double gatherScale);

/// What light `light` (not a dome: EstimatedEverySample) is predicted to bring the eye's iris, for MneeLightPick: its
/// irradiance at the apex (world units, unshadowed, through no cornea), times 0.1 plus the cosine of its direction
/// off the gaze.
double PredictedIrisLight(const EyeGeometry& eye, const RenderLight& light) {
  const double L = std::max(0.0, 0.2126 * light.radiance.x + 0.7152 * light.radiance.y + 0.0722 * light.radiance.z);
  const glm::dvec3 apex = eye.ToWorld(glm::dvec3(0)), gaze = eye.DirToWorld(glm::dvec3(0, 0, 1));
  if (light.type == LightType::Distant) {
    const double solidAngle = light.delta ? 1 : kPi * (1 - light.cosHalfAngle * light.cosHalfAngle);
    return L * solidAngle * (0.1 + std::max(0.0, glm::dot(light.direction, gaze)));
  }
  const glm::dvec3 to = light.position - apex;
  const double d2 = std::max(glm::dot(to, to), 1e-300);
  const glm::dvec3 dir = to / std::sqrt(d2);
  const double facing = std::max(0.0, -glm::dot(light.direction, dir));  // a one-sided emitter's cosine to the eye
  double intensity;  // radiant intensity towards the eye (world units), from the light's size
  switch (light.type) {
    case LightType::Sphere: intensity = light.delta ? L : L * kPi * light.radius * light.radius; break;
    case LightType::Disk: intensity = L * kPi * light.radius * light.radius * facing; break;
    case LightType::Rect: intensity = L * 4 * glm::length(light.axisU) * glm::length(light.axisV) * facing; break;
    case LightType::Cylinder: intensity = L * 2 * light.halfLength * (light.delta ? 1 : 2 * light.radius); break;
    default: intensity = L; break;
  }
  return intensity / d2 * (0.1 + std::max(0.0, glm::dot(dir, gaze)));
}

/// Whether MNEE estimates light `index` in every sample rather than picking it among the others: a dome it counts.
/// A dome surrounds the eye, so it lights every iris point through the whole cornea; picked among small keys by
/// a prediction of its mean, its estimate (which varies as much as its texture does) is what the pixel's noise is
/// made of (docs/render_plan.md, sweep dome-contrast).
bool EstimatedEverySample(const EyeLighting& lighting, std::size_t index) {
  return MneeCountsLight(lighting, index) && (*lighting.lights)[index].type == LightType::Dome;
}

/// Whether MNEE picks light `index` among the others for one estimate a sample.
bool Picked(const EyeLighting& lighting, std::size_t index) {
  return MneeCountsLight(lighting, index) && !EstimatedEverySample(lighting, index);
}

/// Chooses the picked light (Picked) of an MNEE estimate from one uniform number: by lighting.mneePick, else
/// uniformly among them; false if there is none.
bool PickMneeLight(const EyeLighting& lighting, double u, std::size_t* index, double* pdf) {
  const std::size_t n = lighting.lights->size();
  const std::vector<double>* pick = lighting.mneePick;
  if (pick && pick->size() == n) {
    double cumulative = 0;
    std::size_t last = n;
    for (std::size_t k = 0; k < n; ++k) {
      if (!((*pick)[k] > 0) || !Picked(lighting, k)) continue;
      last = k;
      cumulative += (*pick)[k];
      if (u < cumulative) break;
    }
    if (last == n) return false;
    *index = last, *pdf = (*pick)[last];
    return true;
  }
  std::size_t counted = 0;
  for (std::size_t k = 0; k < n; ++k) counted += Picked(lighting, k);
  if (counted == 0) return false;
  std::size_t chosen = std::min(counted - 1, std::size_t(u * double(counted)));
  for (std::size_t k = 0; k < n; ++k)
    if (Picked(lighting, k) && chosen-- == 0) *index = k;
  *pdf = 1 / double(counted);
  return true;
}

/// Irradiance (world units) at iris point x from light `index` through the cornea by MNEE, the light sampled from
/// the uniform pair (u1, u2).
glm::dvec3 IrisIrradianceFromLight(const EyeGeometry& eye, const glm::dvec3& x, const EyeLighting& lighting,
                                   std::size_t index, double u1, double u2) {
  const RenderLight& light = (*lighting.lights)[index];
  // Sample the light (a point on it, or a direction, with its pdf) as seen from about where its centre's light
  // crosses the cornea on the way to x: seen from the apex instead, the sampled point's cosine towards the path's
  // own cornea point over the apex's cosine diverges at the light's rim for iris points off the axis
  // (eyelib::ApproximateEntryPoint). The estimate is unbiased for any origin.
  const bool hasCentre = !light.delta && light.type != LightType::Distant && light.type != LightType::Dome;
  glm::dvec3 entry(0);
  if (hasCentre) {
    const eyelib::LightEnd centre{false, eye.ToCanonical(light.position), {}};
    entry = lighting.entryTables && !light.motion ? lighting.entryTables->At(eye.chamber, centre, x)
                                                  : eyelib::ApproximateEntryPoint(eye.chamber, x, centre);
  }
  const glm::dvec3 origin = eye.ToWorld(entry);
  const LightSample ls = SampleLight(light, origin, u1, u2);
  if (!(ls.pdf > 0)) return glm::dvec3(0);
  eyelib::LightEnd end;
  glm::dvec3 y(0), emitterNormal(0);
  double weight;  // radiance over the sample's pdf, in the measure the transfer expects
  const bool distant = !std::isfinite(ls.distance);
  if (distant) {
    end.distant = true;
    end.direction = eye.DirToCanonical(ls.dir);
    weight = 1 / ls.pdf;  // E_perp = L dw
  } else if (light.delta) {
    // A point of radiant intensity I: E = I x transfer, the transfer per mm^2 and I per world unit^2 (a line:
    // its sampled point, standing for its whole length).
    y = light.type == LightType::Cylinder ? origin + ls.dir * ls.distance : light.position;
    end.position = eye.ToCanonical(y);
    weight = 1 / (eye.worldPerMm * eye.worldPerMm);
  } else if (ls.pointLimit) {
    // A sphere too small to sample over its surface: its centre, of intensity radiance x pi r^2.
    y = light.position;
    end.position = eye.ToCanonical(y);
    weight = kPi * (light.radius / eye.worldPerMm) * (light.radius / eye.worldPerMm);
  } else {
    y = origin + ls.dir * ls.distance;
    emitterNormal = EmitterNormal(light, y);
    const double cosY = std::abs(glm::dot(emitterNormal, ls.dir));
    if (!(cosY > 0)) return glm::dvec3(0);
    const double pdfArea = ls.pdf * cosY / (ls.distance * ls.distance);
    end.position = eye.ToCanonical(y);
    // transfer is per mm^2 of iris; a world unit is 1 / worldPerMm mm.
    weight = 1 / (pdfArea * eye.worldPerMm * eye.worldPerMm);
  }
  eyelib::MneeOptions options;
  options.scleraOccludes = false;  // visibility is the renderer's: shadow rays below
  options.tolerance = kRenderMneeTolerance;
  eyelib::SeedStrategy seeds;
  seeds.allSolutions = lighting.switches.mneeAllSolutions;
  if (hasCentre) {
    seeds.start = eyelib::Vec2<double>(entry.x, entry.y);  // Newton's start: near every point's path
    // A small sphere or disk (under about 3 degrees) gains nothing from retrying a failed start elsewhere.
    const bool round = light.type == LightType::Sphere || light.type == LightType::Disk;
    seeds.retryStart = !(round && light.radius < 0.05 * glm::length(light.position - origin));
  } else if (distant) {
    // One sampled direction (of a dome, or of a distant light's cone): the entry along that very direction, a
    // light of no extent, so a failed start is not retried either.
    const glm::dvec3 along = eyelib::ApproximateEntryPoint(eye.chamber, x, end);
    seeds.start = eyelib::Vec2<double>(along.x, along.y);
    seeds.retryStart = false;
  }
  const eyelib::MneeResult paths = eyelib::FindRefractionPaths(eye.chamber, x, end, seeds, options);
  glm::dvec3 E(0);
  for (const eyelib::MneeSolution& s : paths.solutions) {
    const glm::dvec3 p = eye.ToWorld(s.p), n = eye.DirToWorld(s.normal);
    double cosEmit = 1, tFar = kInf;
    glm::dvec3 toLight = ls.dir;
    if (!distant) {
      const glm::dvec3 d = y - p;
      tFar = glm::length(d);
      toLight = d / tFar;
      cosEmit = light.delta || ls.pointLimit ? 1.0 : std::max(0.0, -glm::dot(emitterNormal, toLight));
      if (cosEmit == 0) continue;
      tFar *= 1 - 1e-6;
    }
    const double transmittance = lighting.transmittance(index, Offset(eye, p, n), toLight, tFar, &eye);
    if (!(transmittance > 0)) continue;
    // Emission from the sampled light point towards this path's own cornea point (a rect's texture there,
    // ShapingAPI; the sample's radiance for distant lights and domes, which have no shaping).
    const glm::dvec3 le = distant ? ls.radiance : EmittedRadiance(light, y, -toLight);
    E += le * (s.transfer * cosEmit * weight * transmittance);
  }
  return E;
}

}  // namespace

glm::dvec3 IrisIrradianceMnee(const EyeGeometry& eye, const glm::dvec3& x, const EyeLighting& lighting,
                              eyelib::FunctionRef<double()> random) {
  // The random numbers drawn do not depend on the lights: four, the light point first (one 2D pair of the
  // renderer's sampler), the fourth unused so the caller's next draws start on a pair. Domes take the same point
  // as the picked light: each estimate is unbiased on its own.
  const double u1 = random(), u2 = random(), pick = random();
  random();
  glm::dvec3 E(0);
  for (std::size_t k = 0; k < lighting.lights->size(); ++k)
    if (EstimatedEverySample(lighting, k)) E += IrisIrradianceFromLight(eye, x, lighting, k, u1, u2);
  // Only the lights MNEE counts; picking among them alone (not among all lights with zero for the rest)
  // spends every sample on light MNEE is responsible for.
  std::size_t index = 0;
  double pickPdf = 0;
  if (PickMneeLight(lighting, pick, &index, &pickPdf))
    E += IrisIrradianceFromLight(eye, x, lighting, index, u1, u2) / pickPdf;
  return E;
}

std::vector<double> MneeLightPick(const EyeGeometry& eye, const EyeLighting& lighting) {
  const std::vector<RenderLight>& lights = *lighting.lights;
  std::vector<double> pick(lights.size(), 0.0);
  double predicted = 0;
  std::size_t counted = 0;
  for (std::size_t k = 0; k < lights.size(); ++k)
    if (Picked(lighting, k)) pick[k] = PredictedIrisLight(eye, lights[k]), predicted += pick[k], ++counted;
  const bool informed = counted > 1 && predicted > 0 && std::isfinite(predicted);
  for (std::size_t k = 0; k < lights.size(); ++k) {
    if (!Picked(lighting, k)) continue;
    pick[k] = informed ? 0.8 * pick[k] / predicted + 0.2 / double(counted) : 1 / double(counted);
  }
  return pick;
}

EyeEvent ScatterAtEye(const EyeGeometry& eye, const glm::dvec3& worldOrigin, const glm::dvec3& worldDir,
                      EyeGeometry::Part part, const EyeLighting& lighting, eyelib::FunctionRef<double()> random,
                      const std::optional<CorneaPoint>& cornea) {
  if (part == EyeGeometry::kBack) return EyeEvent{};  // the back of the eye: dark
  const glm::dvec3 d = eye.DirToCanonical(worldDir);
  if (cornea) return ScatterFromCornea(eye, CorneaEntry{cornea->point, cornea->normal, d}, lighting, random);
  const auto entry = eye.chamber.Surface().Intersect({eye.ToCanonical(worldOrigin), d});
  if (!entry || !entry->fromOutside) return EyeEvent{};  // Embree's float hit was a graze the exact test rejects
  return ScatterFromCornea(eye, CorneaEntry{entry->point, entry->normal, d}, lighting, random);
}

EyeEvent ScatterAtEyeMesh(const EyeGeometry& eye, const EyeMeshHit& hit, const glm::dvec3& worldDir,
                          const EyeLighting& lighting, eyelib::FunctionRef<double()> random) {
  EyeEvent ev;
  if (!hit.fromOutside) {
    // The inside of an eye mesh belongs to the analytic model; the Embree filter already skips these
    // hits, this only guards a disagreement in the last bit. Step past the surface, unchanged.
    ev.kind = EyeEvent::Continue;
    ev.passThrough = true;
    ev.dir = worldDir;
    ev.origin = SpawnOrigin(hit.worldPoint, worldDir, eye.SpawnScale());
    return ev;
  }
  // Past the outer limbus edge (a projection that does not cover the hit included), and anywhere below
  // the iris plane (the back of the eyeball, whatever its radius), the mesh is sclera.
  if (!hit.onCornea) {
    ev.kind = EyeEvent::Sclera;
    ev.scleraAlbedo = eye.scleraColor;
    ev.scleraOnSurface = true;
    return ev;
  }
  // The path continues against the analytic model from the analytic point at the hit's projected (x, y),
  // with the direction the mapping carried there (eyeMeshMapping.h).
  ev = ScatterFromCornea(eye, CorneaEntry{hit.analyticPoint, hit.analyticNormal, hit.canonicalDir}, lighting, random);
  if (ev.kind == EyeEvent::Sclera) {
    ev.scleraOnSurface = true;  // the limbus blend chose sclera: shade the mesh surface there
    return ev;
  }
  // Re-projected: every leaving ray (reflection at entry, exit after the chamber walk) leaves from the
  // deformed hit point, its canonical direction turned back by the hit's local rotation. ScatterFromCornea
  // placed it through the eye's rigid frame; undo that exactly (a similarity) to recover the canonical one.
  // Baseline: a reflection at entry leaves from the mesh point the ray met, in the eye's affine frame;
  // exits leave from the analytic exit point there (the mesh is transparent from inside).
  const auto leaveFromMesh = [&](glm::dvec3* origin, glm::dvec3* dir) {
    EyeMeshHit leaving = hit;
    if (!hit.reprojected) leaving.worldToLocal = glm::dmat3(1.0);  // the direction is already the world one
    *dir = EyeMeshLeavingDirection(leaving, hit.reprojected ? eye.DirToCanonical(*dir) : *dir);
    *origin = SpawnOrigin(hit.worldPoint, hit.worldNormal, eye.SpawnScale());
  };
  if (ev.kind == EyeEvent::Continue && (hit.reprojected || ev.reflectedAtEntry)) leaveFromMesh(&ev.origin, &ev.dir);
  if (ev.reflection.weight > 0) leaveFromMesh(&ev.reflection.origin, &ev.reflection.dir);
  return ev;
}

EyeEvent ScatterFromCornea(const EyeGeometry& eye, const CorneaEntry& entry, const EyeLighting& lighting,
                           eyelib::FunctionRef<double()> random) {
  EyeEvent ev;
  const double ior = eye.chamber.CorneaIor();
  const glm::dvec3 &p = entry.point, &n = entry.normal, &d = entry.dir;
  const glm::dvec3 worldPoint = eye.ToWorld(p);

  // Limbus: the sclera's share of this point is its probability of being shaded as sclera. Both choices at the
  // entry are drawn first: one pair.
  const double uLimbus = random(), uFresnel = random();
  if (uLimbus < eye.chamber.LimbusWeight(eyelib::Radius(p.x, p.y))) {
    ev.kind = EyeEvent::Sclera;
    ev.scleraAlbedo = eye.scleraColor;
    ev.normal = eye.DirToWorld(n);
    return ev;
  }
  // The Fresnel choice at the entry decides only where the path goes on: the reflection off the cornea, or the
  // walk's exit. The light the walk gathers inside (the iris's MNEE light) is taken in every path, weighted by the
  // transmittance 1 - F: drawing that choice too would cost the iris a Bernoulli factor of variance, F / (1 - F)
  // relative (about 3 % at normal incidence, far more at grazing), for saving a walk in F of the paths.
  const double F = eyelib::FresnelDielectric(glm::dot(-d, n), ior);
  const auto reflectAtEntry = [&](EyeEvent* event) {
    event->kind = EyeEvent::Continue;
    event->reflectedAtEntry = true;
    event->weight = glm::dvec3(1);
    event->skipLightHits = false;
    event->dir = eye.DirToWorld(eyelib::Reflect(-d, n));
    event->origin = Offset(eye, worldPoint, eye.DirToWorld(n));
  };
  glm::dvec3 wt;
  if (!(F < 1) || !eyelib::Refract(-d, n, ior, &wt)) {  // grazing: all reflected
    reflectAtEntry(&ev);
    return ev;
  }
  if (!(lighting.splitAtEntry && lighting.reflectionOnly)) ev = WalkChamber(eye, p, wt, lighting, random, 1 - F);
  if (lighting.splitAtEntry && F > 0) {
    EyeEvent reflected;
    reflectAtEntry(&reflected);
    ev.reflection = {reflected.origin, reflected.dir, F};
    ev.weight *= 1 - F;
  } else if (uFresnel < F) {
    reflectAtEntry(&ev);
  }
  return ev;
}

namespace {

EyeEvent WalkChamber(const EyeGeometry& eye, glm::dvec3 p, glm::dvec3 d, const EyeLighting& lighting,
                     eyelib::FunctionRef<double()> random, double gatherScale) {
  EyeEvent ev;
  const double ior = eye.chamber.CorneaIor();
  glm::dvec3 n, wt;

  // The walk inside the chamber. Radiance changes by the squared index ratio across the cornea
  // (pbrt's non-symmetric BTDF): a camera path entering sees inside radiance divided by n^2, and
  // multiplies it back on the way out; light that MNEE brings to the iris keeps only the first.
  // At the first iris vertex the walk splits (EyeLighting::irisLightSplits, chamberSplits): several MNEE estimates
  // of the light there, and several walks on from it; this one goes on (and out) with the others' company, so what
  // it gathers inside from then on weighs 1 / chamberSplits, and its exit keeps the full weight.
  glm::dvec3 beta(1 / (ior * ior));
  bool straightFromIris = false, split = false;
  const bool roulette = lighting.switches.mnee && MneeCountsEveryLight(lighting);
  int irisVertices = 0;
  double gatherWeight = gatherScale;
  const int chamberSplits = std::max(1, lighting.chamberSplits);
  for (int k = 0; k < lighting.maxChamberEvents; ++k, ++ev.internalEvents) {
    const ChamberHit hit = eye.chamber.NextSurfaceFromInside(p, d);
    if (hit.kind != ChamberHit::Iris && hit.kind != ChamberHit::Cornea) return ev;  // the lens, or the rim's gap
    if (hit.kind == ChamberHit::Iris) {
      const glm::dvec3 albedo = eye.IrisAlbedo(hit.point);
      const int lightSplits = split ? 1 : std::max(1, lighting.irisLightSplits);
      if (lighting.switches.mnee)
        ev.radiance += gatherWeight * beta *
                       IrisDirectLight(eye, hit.point, albedo, ++irisVertices, lighting, random, lightSplits);
      if (!split && chamberSplits > 1) {
        gatherWeight = gatherScale / chamberSplits;
        const int eventsLeft = lighting.maxChamberEvents - k - 1;
        for (int i = 1; i < chamberSplits; ++i)
          ev.radiance += gatherWeight * beta * albedo * GatherFromIris(eye, hit.point, lighting, random, eventsLeft);
      }
      split = true;
      beta *= albedo;
      if (roulette && !SurvivesRoulette(ior, random, &beta)) return ev;
      d = IrisBounce(random);
      p = hit.point;
      straightFromIris = true;
      continue;
    }
    p = hit.point;
    n = hit.normal;  // outward; the path arrives from inside
    if (ReflectsInside(d, n, ior, random)) {
      d = d - 2 * glm::dot(d, n) * n;
      straightFromIris = false;
      continue;
    }
    if (!eyelib::Refract(-d, -n, 1 / ior, &wt)) return ev;
    ev.kind = EyeEvent::Continue;
    ev.weight = beta * (ior * ior);
    ev.dir = eye.DirToWorld(wt);
    ev.origin = Offset(eye, eye.ToWorld(p), eye.DirToWorld(n));
    ev.skipLightHits = straightFromIris && lighting.switches.mnee;
    return ev;
  }
  ev.walkCapReached = true;
  return ev;
}

}  // namespace

}  // namespace hdeye
