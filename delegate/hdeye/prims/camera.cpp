#include "hdeye/prims/camera.h"

#include "hdeye/prims/motionSync.h"
#include "hdeye/prims/renderParam.h"

#include <glm/glm.hpp>

#include <cmath>
#include <stdexcept>

namespace hdeye {

void Camera::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyTransform) {
    const PrimMotion synced = SyncTransformMotion(sceneDelegate, renderParam, Id(), "camera " + Id());
    const Matrix4d m = synced.transform;
    // Any scene delegate's transform: a NaN or singular one would reach Embree as invalid rays.
    const double det = glm::determinant(glm::dmat3(m));
    if (!std::isfinite(det) || det == 0 || !std::isfinite(m[3][0] + m[3][1] + m[3][2]))
      throw std::runtime_error("camera " + Id() + ": transform is singular or not finite");
    view_.transform = m;
    view_.motion = synced.motion;
  }
  if (*dirtyBits & dirty::DirtyParams) {
    const CameraParams p = sceneDelegate->GetCameraParams(Id());
    if (!(p.horizontalAperture > 0) || !(p.verticalAperture > 0) || (!p.orthographic && !(p.focalLength > 0)))
      throw std::runtime_error("camera " + Id() + ": focal length and apertures must be positive");
    if (!(p.fStop >= 0) || !std::isfinite(p.fStop) || !(p.focusDistance >= 0) || !std::isfinite(p.focusDistance) ||
        !(p.focalLengthUnit > 0) || !std::isfinite(p.focalLengthUnit))
      throw std::runtime_error("camera " + Id() + ": fStop and focusDistance must be finite and >= 0");
    if (!std::isfinite(p.shutterOpen) || !std::isfinite(p.shutterClose) || p.shutterClose < p.shutterOpen)
      throw std::runtime_error("camera " + Id() + ": shutter close must be >= open (finite frames)");
    view_.params = p;
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
