#pragma once
// Lights as the eye's MNEE sees them, in the canonical eye frame (mm), with their sampling:
//  - Point:   `position`, `power` = intensity, W/sr.
//  - Sphere:  `position` (centre), `radius` (mm), `power` = radiance, W/(mm^2 sr).
//  - Disk:    `position` (centre), `normal` (emitting side), `radius` (mm), `power` = radiance.
//  - Rect:    `position` (centre), half-edge vectors `edgeU`, `edgeV` (mm; emits along edgeU x edgeV),
//             `power` = radiance.
//  - Distant: `direction` (unit, towards the light), `angularRadius` (radians, 0 for a parallel beam),
//             `power` = irradiance on a surface facing the light, W/mm^2.
#include "eyelib/mnee.h"

#include <cstdint>

namespace eyelib {

enum class LightShape : std::uint8_t { Point, Sphere, Disk, Rect, Distant };

struct EyeLight {
  LightShape shape = LightShape::Point;
  Vec3d position{0, 0, 100};
  Vec3d normal{0, 0, -1};
  Vec3d direction{0, 0, 1};
  Vec3d edgeU{1, 0, 0}, edgeV{0, 1, 0};
  double radius = 0;
  double angularRadius = 0;
  double power = 1;
};

/// One sampled point (or direction) on a light. The irradiance a converged MNEE path p brings is
/// transfer(p) * weight * EmissionCosine(p): weight folds radiance (or intensity) over the pdf.
struct LightSample {
  LightEnd end;
  double weight = 0;
  bool area = false;  ///< the sample is a point on a surface emitter with normal `emitterNormal`
  Vec3d emitterNormal{0, 0, 0};

  /// Cosine at the emitter towards p (1 for points and distant lights; 0 when p is behind it).
  double EmissionCosine(const Vec3d& p) const {
    if (!area) return 1;
    const double c = glm::dot(emitterNormal, glm::normalize(p - end.position));
    return c > 0 ? c : 0;
  }
};

/// Samples the light from two uniform numbers in [0, 1). Points are uniform in area; distant
/// directions uniform in the cone's solid angle.
LightSample SampleLight(const EyeLight& light, double u1, double u2);

/// Total area of a surface light (mm^2), 0 for points and distant lights.
double LightArea(const EyeLight& light);

/// One-sample estimate of the irradiance at iris point x (W/mm^2) through the cornea from a light.
struct IrisIrradianceEstimate {
  double irradiance = 0;
  int solutions = 0, solves = 0, failures = 0;
};
IrisIrradianceEstimate EstimateIrisIrradiance(const AnteriorChamber<double>& chamber, const Vec3d& x,
                                              const EyeLight& light, double u1, double u2,
                                              const SeedStrategy& seeds = {}, const MneeOptions& options = {});

}  // namespace eyelib
