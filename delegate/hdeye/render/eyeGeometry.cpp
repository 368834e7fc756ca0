#include "hdeye/render/eyeGeometry.h"

#include <cmath>

namespace hdeye {

EyeGeometry::EyeGeometry(const EyeParams& params, const Matrix4d& primTransform)
    : chamber(params.chamber),
      irisColor(params.irisColor),
      scleraColor(params.scleraColor),
      limbalArc(params.limbalArc),
      scleraMeanFreePath(params.scleraMeanFreePath) {
  canonicalToWorld = primTransform * params.modelTransform;
  worldToCanonical = glm::inverse(canonicalToWorld);
  const glm::dmat3 linear(canonicalToWorld);
  worldPerMm = std::cbrt(std::abs(glm::determinant(linear)));
}

}  // namespace hdeye
