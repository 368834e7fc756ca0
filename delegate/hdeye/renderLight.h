#pragma once
// Lights as the renderer sees them, in world space, with sampling and evaluation (each sampling
// routine has its pdf beside it). Radiance in the scene's radiometric units.
#include "hdeye/sceneDelegate.h"

#include <glm/glm.hpp>

namespace hdeye {

struct RenderLight {
  LightType type = LightType::Sphere;
  glm::dvec3 radiance{0};    ///< emitted radiance (distant: of the sun disk)
  glm::dvec3 position{0};    ///< sphere centre, rect/disk centre
  glm::dvec3 direction{0, 0, 1};  ///< distant: towards the light; rect/disk: emitting normal
  glm::dvec3 axisU{1, 0, 0}, axisV{0, 1, 0};  ///< rect: half-extent vectors; disk: unit in-plane axes
  double radius = 0;         ///< sphere, disk
  double cosHalfAngle = 1;   ///< distant

  /// Builds a light from its parameters and local-to-world transform (UsdLux conventions: rect and
  /// disk emit along their local -z, a distant light shines along -z).
  static RenderLight FromParams(const LightParams& params, const glm::dmat4& transform);
};

/// A sampled direction towards a light from a shading point.
struct LightSample {
  glm::dvec3 dir{0};         ///< unit, towards the light
  double distance = 0;       ///< to the sampled point (infinity for distant and dome)
  glm::dvec3 radiance{0};
  double pdf = 0;            ///< solid angle; 0 if the light cannot be sampled from here
};

/// Samples a direction towards the light from point p, from two uniform numbers.
LightSample SampleLight(const RenderLight& light, const glm::dvec3& p, double u1, double u2);

/// If a ray from p along unit dir meets the light's emitting surface before maxDistance (or, for
/// distant and dome, escapes the scene), the radiance it sees and the solid-angle pdf SampleLight
/// would have given that direction. Returns false otherwise.
bool IntersectLight(const RenderLight& light, const glm::dvec3& p, const glm::dvec3& dir, double maxDistance,
                    glm::dvec3* radiance, double* pdf, double* distance);

}  // namespace hdeye
