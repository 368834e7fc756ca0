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

EyeGeometry EyeGeometry::AtTime(double time) const {
  EyeGeometry eye = *this;
  if (!motion) return eye;
  const Matrix4d prim = motion->prim->At(time);
  eye.objectToWorld = prim;
  eye.canonicalToWorld = prim * motion->canonicalInPrim;
  eye.worldToCanonical = glm::inverse(eye.canonicalToWorld);
  eye.worldPerMm = std::cbrt(std::abs(glm::determinant(glm::dmat3(eye.canonicalToWorld))));
  return eye;
}

std::vector<glm::dmat4> EyeGeometry::CanonicalToWorldOverShutter(int count) const {
  if (!motion || count < 2) return {canonicalToWorld};
  std::vector<glm::dmat4> frames;
  const Shutter& s = motion->shutter;
  for (int k = 0; k < count; ++k)
    frames.push_back(motion->prim->At(s.open + (s.close - s.open) * k / (count - 1)) * motion->canonicalInPrim);
  return frames;
}

EyeRayExchange& ThisThreadsEyeRays() {
  thread_local EyeRayExchange exchange;
  return exchange;
}

}  // namespace hdeye
