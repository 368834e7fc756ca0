#include "eyelib/eye_light.h"

#include "eyelib/sampling.h"

#include <cmath>

namespace eyelib {

double LightArea(const EyeLight& light) {
  switch (light.shape) {
    case LightShape::Sphere: return 4 * paper::kPi * light.radius * light.radius;
    case LightShape::Disk: return paper::kPi * light.radius * light.radius;
    case LightShape::Rect: return 4 * glm::length(glm::cross(light.edgeU, light.edgeV));
    default: return 0;
  }
}

LightSample SampleLight(const EyeLight& light, double u1, double u2) {
  LightSample s;
  const double phi = 2 * paper::kPi * u2;
  switch (light.shape) {
    case LightShape::Point:
      s.end.position = light.position;
      s.weight = light.power;
      break;
    case LightShape::Sphere: {
      const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z));
      s.emitterNormal = {r * std::cos(phi), r * std::sin(phi), z};
      s.end.position = light.position + light.radius * s.emitterNormal;
      s.area = true;
      s.weight = light.power * LightArea(light);
      break;
    }
    case LightShape::Disk: {
      Vec3d t, b;
      OrthonormalBasis(light.normal, &t, &b);
      const double r = light.radius * std::sqrt(u1);
      s.end.position = light.position + r * (std::cos(phi) * t + std::sin(phi) * b);
      s.emitterNormal = light.normal;
      s.area = true;
      s.weight = light.power * LightArea(light);
      break;
    }
    case LightShape::Rect:
      s.end.position = light.position + (2 * u1 - 1) * light.edgeU + (2 * u2 - 1) * light.edgeV;
      s.emitterNormal = glm::normalize(glm::cross(light.edgeU, light.edgeV));
      s.area = true;
      s.weight = light.power * LightArea(light);
      break;
    case LightShape::Distant: {
      s.end.distant = true;
      if (light.angularRadius <= 0) {
        s.end.direction = light.direction;
        s.weight = light.power;
        break;
      }
      // Uniform in the cone; radiance L = E / (pi sin^2 alpha), pdf = 1 / (2 pi (1 - cos alpha)).
      const double cosMax = std::cos(light.angularRadius), sinA = std::sin(light.angularRadius);
      s.end.direction = SampleUniformCone(light.direction, cosMax, u1, u2);
      s.weight = light.power / (paper::kPi * sinA * sinA) / UniformConePdf(cosMax);
      break;
    }
  }
  return s;
}

IrisIrradianceEstimate EstimateIrisIrradiance(const AnteriorChamber<double>& chamber, const Vec3d& x,
                                              const EyeLight& light, double u1, double u2, const SeedStrategy& seeds,
                                              const MneeOptions& options) {
  IrisIrradianceEstimate est;
  const LightSample sample = SampleLight(light, u1, u2);
  const MneeResult paths = FindRefractionPaths(chamber, x, sample.end, seeds, options);
  est.solves = paths.solves;
  est.failures = paths.failures;
  est.solutions = int(paths.solutions.size());
  for (const MneeSolution& s : paths.solutions) est.irradiance += s.transfer * sample.EmissionCosine(s.p);
  est.irradiance *= sample.weight;
  return est;
}

}  // namespace eyelib
