#include "hdeye/prims/light.h"

#include "hdeye/hd/renderIndex.h"
#include "hdeye/prims/motionSync.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/render/movingLights.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

void Light::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyTransform) {
    const PrimMotion synced = SyncTransformMotion(sceneDelegate, renderParam, Id(), "light " + Id());
    transform_ = synced.transform;
    motion_ = synced.motion;
    // A NaN position would make the light silently dark; say so instead.
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(transform_[c][0] + transform_[c][1] + transform_[c][2] + transform_[c][3]))
        throw std::runtime_error("light " + Id() + ": transform is not finite");
  }
  if (*dirtyBits & dirty::DirtyParams) {
    LightParams p = sceneDelegate->GetLightParams(Id());
    p.type = type_;
    if (!std::isfinite(p.intensity) || p.intensity < 0)
      throw std::runtime_error("light " + Id() + ": intensity must be >= 0");
    if ((p.type == LightType::Sphere || p.type == LightType::Cylinder) && !(p.radius >= 0))
      throw std::runtime_error("light " + Id() + ": radius must be >= 0");
    if (p.type == LightType::Cylinder && !(p.length >= 0 && std::isfinite(p.length)))
      throw std::runtime_error("light " + Id() + ": length must be finite and >= 0");
    std::shared_ptr<const DomeTexture> dome;
    if (p.type == LightType::Dome && !p.textureFile.empty()) {
      // Repeat around the dome, clamp at the poles (repeat would blend the two poles).
      const TextureParams image = TextureParams::Image(p.textureFile, TextureWrap::Clamp);
      std::shared_ptr<const Texture> texture = renderParam ? renderParam->Textures().Get(image) : Texture::Open(image);
      if (texture->Valid()) {
        dome = DomeTexture::Build(std::move(texture));
      } else {
        // The render goes on with a dome of the fallback colour, which nobody mistakes for the sky.
        if (renderParam)
          renderParam->Warn("light " + Id() + ": textureFile: " + texture->Error() + "; lit by a magenta dome");
        p.color *= glm::vec3(image.fallback);
        p.textureFile.clear();
      }
    }
    std::shared_ptr<const Texture> rectImage;
    if (p.type == LightType::Rect && !p.textureFile.empty()) {
      const TextureParams image = TextureParams::Image(p.textureFile, TextureWrap::Clamp);
      rectImage = renderParam ? renderParam->Textures().Get(image) : Texture::Open(image);
      if (!rectImage->Valid() && renderParam)
        renderParam->Warn("light " + Id() + ": textureFile: " + rectImage->Error() + "; the light emits magenta");
    }
    params_ = p;
    dome_ = std::move(dome);
    rectImage_ = std::move(rectImage);
  }
  *dirtyBits = dirty::Clean;
}

std::vector<GatheredLight> GatherLights(const RenderIndex& index) {
  std::vector<GatheredLight> lights;
  for (const auto& [id, entry] : index.Sprims())
    if (const auto* light = dynamic_cast<const Light*>(entry.prim.get())) {
      GatheredLight g{id, light,
                      RenderLight::FromParams(light->Params(), light->Transform(), light->Dome(), light->RectImage())};
      if (light->Motion())
        g.light.motion = std::make_shared<const LightMotion>(
            LightMotion{light->Motion(), light->Params(), light->Dome(), light->RectImage()});
      lights.push_back(std::move(g));
    }
  return lights;
}

}  // namespace hdeye
