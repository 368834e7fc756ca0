#include "hdeye/prims/camera.h"

#include <stdexcept>

namespace hdeye {

void Camera::Sync(SceneDelegate* sceneDelegate, RenderParam*, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyTransform) view_.transform = sceneDelegate->GetTransform(Id());
  if (*dirtyBits & dirty::DirtyParams) {
    const CameraParams p = sceneDelegate->GetCameraParams(Id());
    if (!(p.horizontalAperture > 0) || !(p.verticalAperture > 0) || (!p.orthographic && !(p.focalLength > 0)))
      throw std::runtime_error("camera " + Id() + ": focal length and apertures must be positive");
    view_.params = p;
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
