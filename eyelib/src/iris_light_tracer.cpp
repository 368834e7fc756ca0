#include "eyelib/iris_light_tracer.h"

#include "eyelib/eye_light.h"
#include "eyelib/optics.h"
#include "eyelib/random.h"
#include "eyelib/sampling.h"

#include <cmath>

namespace eyelib {

namespace {

// A sphere that bounds the cap (r <= 7.54 mm, -3.93 <= z <= 0), so every ray that can reach it is sampled.
const Vec3d kCapCenter(0, 0, -2);
const double kCapRadius = 7.82;

/// One ray from the light towards the cap: origin, direction, and the flux it carries (W).
struct EmittedRay {
  Vec3d origin, dir;
  double flux;
};

/// Samples a point (or direction) on the light, then a direction within the cone that the cap's
/// bounding sphere subtends from there: no ray is wasted on directions that cannot reach the eye.
EmittedRay Emit(const EyeLight& light, double zRim, const double u[4]) {
  const LightSample s = SampleLight(light, u[0], u[1]);
  if (s.end.distant) {
    if (s.end.direction.z <= 0) return {Vec3d(0), Vec3d(0, 0, 1), 0};
    Vec3d t, b;
    OrthonormalBasis(s.end.direction, &t, &b);
    const double phi = 2 * paper::kPi * u[3];
    const double r = kCapRadius * std::sqrt(u[2]);
    const Vec3d o = kCapCenter + r * (std::cos(phi) * t + std::sin(phi) * b) + 4 * kCapRadius * s.end.direction;
    return {o, -s.end.direction, s.weight * paper::kPi * kCapRadius * kCapRadius};
  }
  const Vec3d y = s.end.position;
  if (y.z <= zRim) return {y, Vec3d(0, 0, 1), 0};  // behind the sclera
  const Vec3d toCap = kCapCenter - y;
  const double dist = glm::length(toCap);
  const double cosMax = dist > kCapRadius ? std::sqrt(1 - (kCapRadius / dist) * (kCapRadius / dist)) : -1;
  const Vec3d d = SampleUniformCone(toCap / dist, cosMax, u[2], u[3]);
  const double cosEmit = s.area ? std::max(0.0, glm::dot(s.emitterNormal, d)) : 1.0;
  return {y, d, s.weight * cosEmit / UniformConePdf(cosMax)};
}

}  // namespace

bool CellOnIris(const AnteriorChamber<double>& chamber, const IrisGrid& grid, int i, int j) {
  const Vec2<double> c = grid.CellCenter(i, j);
  const double h = grid.CellSize() / 2;
  const double rMin = std::hypot(std::max(0.0, std::abs(c.x) - h), std::max(0.0, std::abs(c.y) - h));
  const double rMax = std::hypot(std::abs(c.x) + h, std::abs(c.y) + h);
  return rMin >= chamber.PupilRadius() && rMax <= chamber.IrisRadius();
}

IrradianceMap LightTraceIris(const AnteriorChamber<double>& chamber, const EyeLight& light, const IrisGrid& grid,
                             std::int64_t rays, std::uint64_t seed, const CorneaBand& band) {
  IrradianceMap map;
  map.grid = grid;
  map.rays = rays;
  const int n = grid.cells;
  std::vector<double> sum(n * n, 0.0), sumSq(n * n, 0.0);
  const AnteriorSurface<double>& surface = chamber.Surface();
  const double eta = chamber.CorneaIor(), zRim = surface.Sag(surface.RimRadius());
  for (std::int64_t k = 0; k < rays; ++k) {
    const double u[4] = {UniformAt(seed, 0, k), UniformAt(seed, 1, k), UniformAt(seed, 2, k), UniformAt(seed, 3, k)};
    const EmittedRay ray = Emit(light, zRim, u);
    if (!(ray.flux > 0)) continue;
    const auto entry = surface.Intersect({ray.origin, ray.dir});
    if (!entry || !entry->fromOutside || !band.Contains(std::hypot(entry->point.x, entry->point.y))) continue;
    const Vec3d wi = -ray.dir;  // towards the light, on the normal's side
    Vec3d wt;
    if (!Refract(wi, entry->normal, eta, &wt)) continue;
    const double w = ray.flux / double(rays) * (1 - FresnelDielectric(glm::dot(wi, entry->normal), eta));
    const auto iris = chamber.IntersectIris({entry->point, wt});
    if (!iris) continue;
    if (const auto again = surface.Intersect({entry->point, wt}); again && again->t < iris->t) continue;
    const int i = int(std::floor((iris->point.x + grid.halfWidth) / grid.CellSize()));
    const int j = int(std::floor((iris->point.y + grid.halfWidth) / grid.CellSize()));
    if (i < 0 || j < 0 || i >= n || j >= n) continue;
    sum[j * n + i] += w;
    sumSq[j * n + i] += w * w;
  }
  const double area = grid.CellSize() * grid.CellSize();
  map.irradiance.resize(n * n);
  map.stdError.resize(n * n);
  for (int c = 0; c < n * n; ++c) {
    map.irradiance[c] = sum[c] / area;
    // Each ray is an independent Bernoulli-weighted sample: Var(sum) = sum w^2 - (sum w)^2 / N.
    const double var = std::max(0.0, sumSq[c] - sum[c] * sum[c] / double(rays));
    map.stdError[c] = std::sqrt(var) / area;
  }
  return map;
}

}  // namespace eyelib
