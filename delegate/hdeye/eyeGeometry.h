#pragma once
// An eye as the renderer sees it: the analytic anterior chamber in the canonical frame (mm, apex at
// the origin, gaze +z) and the similarity transform to world space. The one place where world and
// canonical coordinates meet.
#include "hdeye/sceneDelegate.h"

#include <eyelib/anterior_chamber.h>

namespace hdeye {

struct EyeGeometry {
  /// The parts a ray can hit (the user geometry's primID).
  enum Part : unsigned { kCornea = 0, kBack = 1 };

  eyelib::AnteriorChamber<double> chamber;
  glm::dmat4 canonicalToWorld{1.0}, worldToCanonical{1.0};
  double worldPerMm = 1;  ///< the transform's uniform scale
  glm::dvec3 irisColor{0.35, 0.2, 0.1}, scleraColor{0.8, 0.78, 0.75};

  EyeGeometry() = default;
  EyeGeometry(const EyeParams& params, const Matrix4d& primTransform);

  glm::dvec3 ToCanonical(const glm::dvec3& p) const { return glm::dvec3(worldToCanonical * glm::dvec4(p, 1)); }
  glm::dvec3 ToWorld(const glm::dvec3& p) const { return glm::dvec3(canonicalToWorld * glm::dvec4(p, 1)); }
  /// Directions map by the linear part; the result is normalised (a similarity keeps angles).
  glm::dvec3 DirToCanonical(const glm::dvec3& d) const { return glm::normalize(glm::dvec3(worldToCanonical * glm::dvec4(d, 0))); }
  glm::dvec3 DirToWorld(const glm::dvec3& d) const { return glm::normalize(glm::dvec3(canonicalToWorld * glm::dvec4(d, 0))); }
};

}  // namespace hdeye
