// MNEE's light sampling at the iris (IrisIrradianceMnee): a small sphere light sampled as seen from about where its
// light crosses the cornea keeps every sample's weight near the mean, where sampling it from the apex gave iris
// points off the axis a heavy tail (the ratio of the emission cosine towards the path's cornea point to the apex's
// cosine diverges at the light's rim).
#include "hdeye/render/eyeGeometry.h"
#include "hdeye/render/eyeShading.h"
#include "hdeye/render/renderLight.h"
#include "saccade_helpers.h"

#include <eyelib/eye_constants.h>
#include <eyelib/mnee.h>
#include <eyelib/optics.h>
#include <eyelib/random.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace hdeye;

TEST_CASE("a 1 mm sphere light 100 mm away samples with bounded weights at iris points off the axis",
          "[render][mnee]") {
  const EyeGeometry eye{EyeParams{}, Matrix4d(1.0)};
  LightParams sphere;
  sphere.radius = 1;
  sphere.intensity = 1000;
  const std::vector<RenderLight> lights{RenderLight::FromParams(sphere, test::KeyAt(62, 100))};
  LightParams point = sphere;
  point.treatAsPoint = true;  // the same power from the centre: E differs by the light's extent alone
  const std::vector<RenderLight> points{RenderLight::FromParams(point, test::KeyAt(62, 100))};
  EyeLighting lighting;
  lighting.transmittance = [](std::size_t, const glm::dvec3&, const glm::dvec3&, double, const EyeGeometry*) {
    return 1.0;
  };
  int lit = 0;
  for (const double r : {-6.5, -4.0, -2.0, 2.0, 4.0, 6.5}) {
    const glm::dvec3 x(r, 0, eye.chamber.IrisZ());
    lighting.lights = &points;
    const std::function<double()> half = [] { return 0.5; };
    const double limit = IrisIrradianceMnee(eye, x, lighting, half).x;
    lighting.lights = &lights;
    std::uint64_t dim = 0;
    const std::function<double()> random = [&] { return eyelib::UniformAt(7, std::uint64_t(r * 100 + 1000), dim++); };
    const int n = 4000;
    double sum = 0, sum2 = 0, largest = 0;
    for (int i = 0; i < n; ++i) {
      const double e = IrisIrradianceMnee(eye, x, lighting, random).x;
      sum += e, sum2 += e * e, largest = std::max(largest, e);
    }
    const double mean = sum / n, relStd = std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
    std::printf("iris x = %+.1f mm: E %.4g (point limit %.4g), per-sample relative std %.2f%%, largest / mean %.2f\n",
                r, mean, limit, 100 * relStd, largest / mean);
    if (limit == 0) continue;  // no path through the cornea
    ++lit;
    CHECK(std::abs(mean / limit - 1) < 0.005);  // a 0.57 degree light: its extent changes E by well under 1 %
    CHECK(relStd < 0.015);                      // sampled from the apex: 1.7-12.5 %
    CHECK(largest < 1.2 * mean);                // from the apex: 1.25-3.2 times the mean
  }
  CHECK(lit >= 4);
}

TEST_CASE("the approximate entry point lies near the refraction path's own cornea point", "[mnee]") {
  const eyelib::AnteriorChamber<double> chamber;
  for (const double degrees : {0.0, 30.0, 62.0, 80.0})
    for (const double r : {-6.0, -3.0, 0.0, 3.0, 6.0}) {
      const double a = degrees * eyelib::paper::kPi / 180;
      const eyelib::LightEnd light{false, {100 * std::sin(a), 0, 100 * std::cos(a)}, {}};
      const eyelib::Vec3d x(r, 1, chamber.IrisZ());
      const eyelib::MneeResult paths = eyelib::FindRefractionPaths(chamber, x, light);
      if (paths.solutions.empty()) continue;  // in the limbus's shadow
      const eyelib::Vec3d p = paths.solutions.front().p, guess = eyelib::ApproximateEntryPoint(chamber, x, light);
      INFO("light " << degrees << " degrees, x = " << r << " mm");
      CHECK(glm::length(guess - p) < (degrees <= 62 ? 0.1 : 0.6));  // mm; 3 steps (the default) from the apex
    }
}

TEST_CASE("the cornea's Fresnel choice at a camera path's entry picks the path's way on, not its iris light",
          "[render][mnee]") {
  // A point light: each path's iris light is then one MNEE evaluation, the same in every path that refracts in.
  const EyeGeometry eye{EyeParams{}, Matrix4d(1.0)};
  LightParams point;
  point.intensity = 1000;
  point.treatAsPoint = true;
  const std::vector<RenderLight> lights{RenderLight::FromParams(point, test::KeyAt(40, 100))};
  EyeLighting lighting;
  lighting.lights = &lights;
  lighting.transmittance = [](std::size_t, const glm::dvec3&, const glm::dvec3&, double, const EyeGeometry*) {
    return 1.0;
  };
  lighting.switches.mnee = true;
  lighting.maxChamberEvents = 1;  // the first iris vertex's light alone
  // A camera ray 60 degrees off the gaze at the cornea: F is about 16 %.
  const double a = 60 * eyelib::paper::kPi / 180;
  const glm::dvec3 from(40 * std::sin(a), 0, 40 * std::cos(a)), towards(-3, 0, -1);
  const glm::dvec3 dir = glm::normalize(towards - from);
  const auto entry = eye.chamber.Surface().Intersect({from, dir});
  REQUIRE(entry);
  const double F = eyelib::FresnelDielectric(glm::dot(-dir, entry->normal), eye.chamber.CorneaIor());
  const int n = 2000;
  int reflected = 0;
  double minLight = 1e300, maxLight = 0;
  for (int i = 0; i < n; ++i) {
    std::uint64_t dim = 0;
    const std::function<double()> random = [&] { return eyelib::UniformAt(3, std::uint64_t(i), dim++); };
    const EyeEvent ev = ScatterFromCornea(eye, CorneaEntry{entry->point, entry->normal, dir}, lighting, random);
    reflected += ev.reflectedAtEntry;
    minLight = std::min(minLight, ev.radiance.x), maxLight = std::max(maxLight, ev.radiance.x);
  }
  std::printf("entry at 60 degrees: F %.4f, reflected continuations %.4f, iris light %.6g to %.6g\n", F,
              double(reflected) / n, minLight, maxLight);
  CHECK(F > 0.02);
  CHECK(std::abs(double(reflected) / n - F) < 4 * std::sqrt(F * (1 - F) / n));  // the way on: reflected w.p. F
  CHECK(minLight > 0);                                                          // every path brings the iris light
  CHECK(maxLight == Approx(minLight).epsilon(1e-12));                           // ... weighted by 1 - F, no noise
}

TEST_CASE(
    "MNEE picks among lights by their predicted iris light: the same irradiance, less noise under a key and fills",
    "[render][mnee]") {
  // A bright key 40 degrees off the gaze, a dim fill 30 degrees the other way and a constant dome: the dome is
  // estimated in every sample, never picked; picked uniformly, half the other estimates go to a fill that brings 1 %,
  // picked by prediction the key takes most. Each light alone gives the reference sum (one light: no choice).
  const EyeGeometry eye{EyeParams{}, Matrix4d(1.0)};
  LightParams key, fill, dome;
  key.radius = 2, key.intensity = 1000;
  fill.radius = 2, fill.intensity = 20;
  dome.type = LightType::Dome, dome.intensity = 0.2f;
  const std::vector<RenderLight> lights{RenderLight::FromParams(key, test::KeyAt(40, 100)),
                                        RenderLight::FromParams(fill, test::KeyAt(-30, 100)),
                                        RenderLight::FromParams(dome, Matrix4d(1.0))};
  EyeLighting lighting;
  lighting.transmittance = [](std::size_t, const glm::dvec3&, const glm::dvec3&, double, const EyeGeometry*) {
    return 1.0;
  };
  lighting.lights = &lights;
  const std::vector<double> pick = MneeLightPick(eye, lighting);
  std::printf("MNEE light pick: key %.3f, fill %.3f, dome %.3f\n", pick[0], pick[1], pick[2]);
  REQUIRE(pick.size() == 3);
  CHECK(pick[0] + pick[1] + pick[2] == Approx(1.0));
  CHECK(pick[0] > 0.8);
  CHECK(pick[1] < 0.15);
  CHECK(pick[1] >= 0.2 / 2 - 1e-12);  // every picked light keeps its uniform share
  CHECK(pick[2] == 0);                // the dome: in every estimate
  const glm::dvec3 x(-2.0, 1.0, eye.chamber.IrisZ());
  struct Estimate {
    double mean, se, relStd;
  };
  auto estimate = [&](const std::vector<RenderLight>& set, const std::vector<double>* weights, std::uint64_t seed) {
    EyeLighting l = lighting;
    l.lights = &set;
    l.mneePick = weights;
    std::uint64_t dim = 0;
    const std::function<double()> random = [&] { return eyelib::UniformAt(seed, 1, dim++); };
    const int n = 20000;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
      const double e = IrisIrradianceMnee(eye, x, l, random).x;
      sum += e, sum2 += e * e;
    }
    const double mean = sum / n, var = std::max(0.0, sum2 / n - mean * mean);
    return Estimate{mean, std::sqrt(var / n), std::sqrt(var) / mean};
  };
  double reference = 0, referenceSe2 = 0;
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const Estimate alone = estimate({lights[k]}, nullptr, 11 + k);
    std::printf("  light %zu alone: %.5g (relative std %.3f)\n", k, alone.mean, alone.relStd);
    reference += alone.mean, referenceSe2 += alone.se * alone.se;
  }
  const Estimate uniform = estimate(lights, nullptr, 21), picked = estimate(lights, &pick, 22);
  std::printf(
      "MNEE over three lights: each alone %.5g, uniform pick %.5g (relative std %.3f), predicted pick %.5g "
      "(%.3f)\n",
      reference, uniform.mean, uniform.relStd, picked.mean, picked.relStd);
  CHECK(std::abs(picked.mean - reference) < 4 * std::sqrt(picked.se * picked.se + referenceSe2));
  CHECK(std::abs(uniform.mean - reference) < 4 * std::sqrt(uniform.se * uniform.se + referenceSe2));
  CHECK(picked.relStd < 0.8 * uniform.relStd);
}
