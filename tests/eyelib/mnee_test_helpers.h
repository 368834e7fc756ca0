#pragma once
// Shared set-up for the MNEE tests: lights placed around the eye, and MNEE irradiance averaged over
// the cells of a light-tracing grid, so the two are compared on the same footing.
#include "eyelib/eye_light.h"
#include "eyelib/iris_light_tracer.h"
#include "eyelib/random.h"

#include <cmath>

namespace test {

/// A point light of unit intensity `distance` mm from the apex, `degrees` off the gaze axis towards +x.
inline eyelib::EyeLight PointLightAt(double degrees, double distance = 100) {
  const double t = degrees * eyelib::paper::kPi / 180;
  eyelib::EyeLight light;
  light.shape = eyelib::LightShape::Point;
  light.position = {distance * std::sin(t), 0, distance * std::cos(t)};
  light.power = 1;
  return light;
}

/// The default seed strategy with the all-solutions search on or off.
inline eyelib::SeedStrategy Seeds(bool allSolutions) {
  eyelib::SeedStrategy seeds;
  seeds.allSolutions = allSolutions;
  return seeds;
}

/// MNEE irradiance averaged over cell (i, j) from k x k stratified iris points with `lightSamples`
/// light samples each: the mean and its standard error (zero for point lights, which MNEE solves
/// exactly; the quadrature error of the k x k points is not included).
struct CellEstimate {
  double mean = 0, stdError = 0;
};

inline CellEstimate CellAverageMnee(const eyelib::AnteriorChamber<double>& chamber, const eyelib::IrisGrid& grid, int i,
                                    int j, const eyelib::EyeLight& light, const eyelib::SeedStrategy& seeds, int k = 8,
                                    int lightSamples = 1) {
  const eyelib::Vec2<double> c = grid.CellCenter(i, j);
  const double h = grid.CellSize();
  double sum = 0, sumSq = 0;
  for (int a = 0; a < k; ++a)
    for (int b = 0; b < k; ++b) {
      const eyelib::Vec3d x(c.x - h / 2 + (a + 0.5) * h / k, c.y - h / 2 + (b + 0.5) * h / k, chamber.IrisZ());
      for (int s = 0; s < lightSamples; ++s) {
        const std::uint64_t idx = ((std::uint64_t(j) * grid.cells + i) * k * k + a * k + b) * lightSamples + s;
        // Stratify the light samples in u1 so few of them still cover the light.
        const double u1 = (s + eyelib::UniformAt(5, 0, idx)) / lightSamples, u2 = eyelib::UniformAt(5, 1, idx);
        const double e = eyelib::EstimateIrisIrradiance(chamber, x, light, u1, u2, seeds).irradiance;
        sum += e;
        sumSq += e * e;
      }
    }
  const double n = double(k) * k * lightSamples;
  CellEstimate est;
  est.mean = sum / n;
  if (lightSamples > 1) est.stdError = std::sqrt(std::max(0.0, sumSq / n - est.mean * est.mean) / (n - 1));
  return est;
}

}  // namespace test
