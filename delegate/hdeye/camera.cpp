#include "hdeye/camera.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

void Camera::Sync(SceneDelegate* sceneDelegate, RenderParam*, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyTransform) {
    const Matrix4d m = sceneDelegate->GetTransform(Id());
    // Any scene delegate's transform: a NaN or singular one would reach Embree as invalid rays.
    const double det = glm::determinant(glm::dmat3(m));
    if (!std::isfinite(det) || det == 0 || !std::isfinite(m[3][0] + m[3][1] + m[3][2]))
      throw std::runtime_error("camera " + Id() + ": transform is singular or not finite");
    view_.transform = m;
  }
  if (*dirtyBits & dirty::DirtyParams) {
    const CameraParams p = sceneDelegate->GetCameraParams(Id());
    if (!(p.horizontalAperture > 0) || !(p.verticalAperture > 0) || (!p.orthographic && !(p.focalLength > 0)))
      throw std::runtime_error("camera " + Id() + ": focal length and apertures must be positive");
    view_.params = p;
  }
  *dirtyBits = dirty::Clean;
}

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
