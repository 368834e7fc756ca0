#include "hdeye/light.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

void Light::Sync(SceneDelegate* sceneDelegate, RenderParam*, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyTransform) transform_ = sceneDelegate->GetTransform(Id());
  if (*dirtyBits & dirty::DirtyParams) {
    const LightParams p = sceneDelegate->GetLightParams(Id());
    if (!std::isfinite(p.intensity) || p.intensity < 0) throw std::runtime_error("light " + Id() + ": intensity must be >= 0");
    if (p.type == LightType::Sphere && !(p.radius >= 0)) throw std::runtime_error("light " + Id() + ": radius must be >= 0");
    params_ = p;
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
