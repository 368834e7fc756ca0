#include "hdeye/render/cameraView.h"

#include <glm/glm.hpp>

namespace hdeye {

WorldRay CameraView::GenerateRay(double u, double v, double imageAspect) const {
  const double halfW = params.horizontalAperture / 2, halfH = halfW / imageAspect;
  const double fx = (2 * u - 1) * halfW, fy = (1 - 2 * v) * halfH;
  glm::dvec3 o(0), d;
  if (params.orthographic) {
    o = {fx, fy, 0};
    d = {0, 0, -1};
  } else {
    d = glm::normalize(glm::dvec3(fx, fy, -params.focalLength));
  }
  const glm::dvec3 wo(transform * glm::dvec4(o, 1)), wd(transform * glm::dvec4(d, 0));
  const double len = glm::length(wd);
  // Clipping distances are along the view axis; convert to the ray parameter of a unit direction.
  const double cosAxis = params.orthographic ? 1.0 : -d.z;
  return {wo, wd / len, params.nearClip / cosAxis, params.farClip / cosAxis};
}

}  // namespace hdeye
