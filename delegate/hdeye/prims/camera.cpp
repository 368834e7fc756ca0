#include "hdeye/prims/camera.h"

#include <glm/glm.hpp>

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
    if (!(p.fStop >= 0) || !std::isfinite(p.fStop) || !(p.focusDistance >= 0) || !std::isfinite(p.focusDistance) ||
        !(p.focalLengthUnit > 0) || !std::isfinite(p.focalLengthUnit))
      throw std::runtime_error("camera " + Id() + ": fStop and focusDistance must be finite and >= 0");
    view_.params = p;
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
