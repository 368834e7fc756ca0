#include "hdeye/render/eyeShading.h"

#include "hdeye/render/surfacePoint.h"

#include <eyelib/eye_constants.h>
#include <eyelib/mnee.h>
#include <eyelib/optics.h>
#include <eyelib/sampling.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hdeye {

namespace {

using eyelib::paper::kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// World offset for spawning a ray off the eye's surface along world normal n.
glm::dvec3 Offset(const EyeGeometry& eye, const glm::dvec3& p, const glm::dvec3& n) {
  return p + n * (1e-6 * eye.worldPerMm * 8 + 1e-7 * glm::length(p));
}

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

/// The irradiance the walk's `vertex`-th iris vertex x (canonical mm; 1 the first) adds through MNEE, by the
/// lighting's chamber estimator: MNEE at every vertex (Path); MNEE plus the cached chamber light at the first and
/// nothing after (Cache); MNEE plus an unbiased estimate of the cache's chamber light at the first, then at the
/// second MNEE minus the cache's prediction of what this and every later vertex bring, MNEE alone after
/// (ControlVariate: the subtracted term's mean over the first vertex's bounce is what the first added, so the mean
/// is the path's whatever the cache's error).
template <class Random> glm::dvec3 IrisLight(const EyeGeometry& eye, const glm::dvec3& x, int vertex,
                                             const EyeLighting& lighting, const Random& random) {
  const eyelib::IrisChamberCache* cache = lighting.chamberCache.get();
  const ChamberEstimator estimator = cache ? lighting.chamberEstimator : ChamberEstimator::Path;
  if (estimator == ChamberEstimator::Path) return IrisIrradianceMnee(eye, x, lighting, random);
  if (estimator == ChamberEstimator::Cache)
    return vertex == 1 ? IrisIrradianceMnee(eye, x, lighting, random) + cache->Chamber(x) : glm::dvec3(0);
  glm::dvec3 E = IrisIrradianceMnee(eye, x, lighting, random);
  if (vertex == 1) E += PredictedChamberLight(eye, *cache, x, lighting, random);
  if (vertex == 2) E -= cache->Irradiance(x);
  return E;
}

}  // namespace

glm::dvec3 IrisIrradianceMnee(const EyeGeometry& eye, const glm::dvec3& x, const EyeLighting& lighting,
                              const std::function<double()>& random) {
  const std::vector<RenderLight>& lights = *lighting.lights;
  // Only the lights MNEE counts; picking among them alone (not among all lights with zero for the rest)
  // spends every sample on light MNEE is responsible for. The random numbers drawn do not depend on the split.
  const double pick = random(), u1 = random(), u2 = random();
  std::size_t counted = 0;
  for (std::size_t k = 0; k < lights.size(); ++k) counted += MneeCountsLight(lighting, k);
  if (counted == 0) return glm::dvec3(0);
  std::size_t chosen = std::min(counted - 1, std::size_t(pick * double(counted))), index = 0;
  for (;; ++index)
    if (MneeCountsLight(lighting, index) && chosen-- == 0) break;
  const RenderLight& light = lights[index];
  // Sample the light as seen from the corneal apex: a point on it (or a direction), with its pdf.
  const glm::dvec3 apex = eye.ToWorld(glm::dvec3(0));
  const LightSample ls = SampleLight(light, apex, u1, u2);
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
    // A point of radiant intensity I: E = I x transfer, the transfer per mm^2 and I per world unit^2.
    y = light.position;
    end.position = eye.ToCanonical(y);
    weight = 1 / (eye.worldPerMm * eye.worldPerMm);
  } else if (ls.pointLimit) {
    // A sphere too small to sample over its surface: its centre, of intensity radiance x pi r^2.
    y = light.position;
    end.position = eye.ToCanonical(y);
    weight = kPi * (light.radius / eye.worldPerMm) * (light.radius / eye.worldPerMm);
  } else {
    y = apex + ls.dir * ls.distance;
    emitterNormal = light.type == LightType::Sphere ? glm::normalize(y - light.position) : light.direction;
    const double cosY = std::abs(glm::dot(emitterNormal, ls.dir));
    if (!(cosY > 0)) return glm::dvec3(0);
    const double pdfArea = ls.pdf * cosY / (ls.distance * ls.distance);
    end.position = eye.ToCanonical(y);
    // transfer is per mm^2 of iris; a world unit is 1 / worldPerMm mm.
    weight = 1 / (pdfArea * eye.worldPerMm * eye.worldPerMm);
  }
  eyelib::MneeOptions options;
  options.scleraOccludes = false;  // visibility is the renderer's: shadow rays below
  const eyelib::MneeResult paths =
      eyelib::FindRefractionPaths(eye.chamber, x, end, eyelib::SeedStrategy{lighting.allSolutions}, options);
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
    const double transmittance = lighting.transmittance(index, Offset(eye, p, n), toLight, tFar);
    if (!(transmittance > 0)) continue;
    // Emission towards this path's own cornea point (ShapingAPI; the apex sample's radiance for distant
    // lights and domes, which have no shaping).
    const glm::dvec3 le = distant ? ls.radiance : light.radiance * EmissionShaping(light, -toLight);
    E += le * (s.transfer * cosEmit * weight * transmittance);
  }
  return E * double(counted);
}

EyeEvent ScatterAtEye(const EyeGeometry& eye, const glm::dvec3& worldOrigin, const glm::dvec3& worldDir,
                      EyeGeometry::Part part, const EyeLighting& lighting, const std::function<double()>& random) {
  if (part == EyeGeometry::kBack) return EyeEvent{};  // the back of the eye: dark
  const glm::dvec3 d = eye.DirToCanonical(worldDir);
  const auto entry = eye.chamber.Surface().Intersect({eye.ToCanonical(worldOrigin), d});
  if (!entry || !entry->fromOutside) return EyeEvent{};  // Embree's float hit was a graze the exact test rejects
  return ScatterFromCornea(eye, CorneaEntry{entry->point, entry->normal, d}, lighting, random);
}

EyeEvent ScatterAtEyeMesh(const EyeGeometry& eye, const EyeMeshHit& hit, const glm::dvec3& worldDir,
                          const EyeLighting& lighting, const std::function<double()>& random) {
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
  } else if (ev.kind == EyeEvent::Continue && (hit.reprojected || ev.reflectedAtEntry)) {
    // Re-projected: every leaving ray (reflection at entry, exit after the chamber walk) leaves from the
    // deformed hit point, its canonical direction turned back by the hit's local rotation. ScatterFromCornea
    // placed it through the eye's rigid frame; undo that exactly (a similarity) to recover the canonical one.
    // Baseline: a reflection at entry leaves from the mesh point the ray met, in the eye's affine frame;
    // exits leave from the analytic exit point there (the mesh is transparent from inside).
    EyeMeshHit leaving = hit;
    if (!hit.reprojected) leaving.worldToLocal = glm::dmat3(1.0);  // the direction is already the world one
    ev.dir = EyeMeshLeavingDirection(leaving, hit.reprojected ? eye.DirToCanonical(ev.dir) : ev.dir);
    ev.origin = SpawnOrigin(hit.worldPoint, hit.worldNormal, eye.SpawnScale());
  }
  return ev;
}

EyeEvent ScatterFromCornea(const EyeGeometry& eye, const CorneaEntry& entry, const EyeLighting& lighting,
                           const std::function<double()>& random) {
  EyeEvent ev;
  const eyelib::AnteriorSurface<double>& surface = eye.chamber.Surface();
  const double ior = eye.chamber.CorneaIor();
  glm::dvec3 p = entry.point, n = entry.normal, d = entry.dir;
  const glm::dvec3 worldPoint = eye.ToWorld(p);

  // Limbus: the sclera's share of this point is its probability of being shaded as sclera.
  if (random() < eye.chamber.LimbusWeight(std::hypot(p.x, p.y))) {
    ev.kind = EyeEvent::Sclera;
    ev.scleraAlbedo = eye.scleraColor;
    ev.normal = eye.DirToWorld(n);
    return ev;
  }
  const double F = eyelib::FresnelDielectric(glm::dot(-d, n), ior);
  if (random() < F) {  // specular reflection off the cornea
    ev.kind = EyeEvent::Continue;
    ev.reflectedAtEntry = true;
    ev.dir = eye.DirToWorld(eyelib::Reflect(-d, n));
    ev.origin = Offset(eye, worldPoint, eye.DirToWorld(n));
    return ev;
  }
  glm::dvec3 wt;
  if (!eyelib::Refract(-d, n, ior, &wt)) return ev;  // cannot happen from outside; be safe
  d = wt;

  // The walk inside the chamber. Radiance changes by the squared index ratio across the cornea
  // (pbrt's non-symmetric BTDF): a camera path entering sees inside radiance divided by n^2, and
  // multiplies it back on the way out; light that MNEE brings to the iris keeps only the first.
  glm::dvec3 beta(1 / (ior * ior));
  bool straightFromIris = false;
  int irisVertices = 0;
  for (int k = 0; k < lighting.maxChamberEvents; ++k, ++ev.internalEvents) {
    const double tPlane = d.z < 0 ? (eye.chamber.IrisZ() - p.z) / d.z : kInf;
    auto cap = surface.Intersect({p, d});
    if (cap && cap->fromOutside) cap.reset();  // from inside the chamber only exits can be hit
    if (tPlane < (cap ? cap->t : kInf)) {
      glm::dvec3 x = p + tPlane * d;
      x.z = eye.chamber.IrisZ();
      if (std::hypot(x.x, x.y) < eye.chamber.PupilRadius()) return ev;  // into the lens: absorbed
      const glm::dvec3 albedo = eye.IrisAlbedo(x);
      if (lighting.mnee) ev.radiance += beta * (albedo / kPi) * IrisLight(eye, x, ++irisVertices, lighting, random);
      const double u1 = random(), u2 = random();
      d = eyelib::SampleCosineHemisphere(glm::dvec3(0, 0, 1), u1, u2);
      beta *= albedo;
      p = x;
      straightFromIris = true;
      continue;
    }
    if (!cap) return ev;  // through the sub-micrometre gap at the rim: lost
    p = cap->point;
    n = cap->normal;                                                    // outward; the path arrives from inside
    const double Fi = eyelib::FresnelDielectric(glm::dot(-d, n), ior);  // 1 under total internal reflection
    if (random() < Fi) {
      d = d - 2 * glm::dot(d, n) * n;
      straightFromIris = false;
      continue;
    }
    if (!eyelib::Refract(-d, -n, 1 / ior, &wt)) return ev;
    ev.kind = EyeEvent::Continue;
    ev.weight = beta * (ior * ior);
    ev.dir = eye.DirToWorld(wt);
    ev.origin = Offset(eye, eye.ToWorld(p), eye.DirToWorld(n));
    ev.skipLightHits = straightFromIris && lighting.mnee;
    return ev;
  }
  ev.walkCapReached = true;
  return ev;
}

}  // namespace hdeye
