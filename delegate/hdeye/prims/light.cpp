#include "hdeye/prims/light.h"

#include "hdeye/prims/renderParam.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

void Light::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyTransform) {
    transform_ = sceneDelegate->GetTransform(Id());
    // A NaN position would make the light silently dark; say so instead.
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(transform_[c][0] + transform_[c][1] + transform_[c][2] + transform_[c][3]))
        throw std::runtime_error("light " + Id() + ": transform is not finite");
  }
  if (*dirtyBits & dirty::DirtyParams) {
    LightParams p = sceneDelegate->GetLightParams(Id());
    p.type = type_;
    if (!std::isfinite(p.intensity) || p.intensity < 0) throw std::runtime_error("light " + Id() + ": intensity must be >= 0");
    if (p.type == LightType::Sphere && !(p.radius >= 0)) throw std::runtime_error("light " + Id() + ": radius must be >= 0");
    std::shared_ptr<const DomeTexture> dome;
    if (p.type == LightType::Dome && !p.textureFile.empty()) {
      try {
        dome = DomeTexture::Build(renderParam ? renderParam->Textures().Get(p.textureFile) : Texture::Load(p.textureFile));
      } catch (const std::exception& e) {
        throw std::runtime_error("light " + Id() + ": textureFile: " + e.what());
      }
    }
    params_ = p;
    dome_ = std::move(dome);
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
