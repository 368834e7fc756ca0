#include "hdeye/prims/material.h"

#include "hdeye/prims/renderParam.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

namespace {

constexpr std::array<const char*, kMaterialInputCount> kInputNames = {
    "diffuseColor", "emissiveColor", "roughness",     "metallic",  "opacity",
    "ior",          "normal",        "specularColor", "clearcoat", "clearcoatRoughness"};

void CheckUnit(const PrimId& id, const char* name, float v) {
  if (!(v >= 0 && v <= 1))
    throw std::runtime_error("material " + id + ": " + name + " = " + std::to_string(v) + " must be in [0, 1]");
}

/// Colours are linear radiometric quantities: finite and non-negative (emission may exceed 1).
void CheckColor(const PrimId& id, const char* name, const glm::vec3& c) {
  for (int i = 0; i < 3; ++i)
    if (!(std::isfinite(c[i]) && c[i] >= 0))
      throw std::runtime_error("material " + id + ": " + name + " has component " + std::to_string(i) + " = " +
                               std::to_string(c[i]) + "; colours must be finite and >= 0");
}

}  // namespace

void Material::Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyParams) {
    const MaterialParams p = sceneDelegate->GetMaterialParams(Id());
    CheckColor(Id(), "diffuseColor", p.diffuseColor);
    CheckColor(Id(), "emissiveColor", p.emissiveColor);
    CheckUnit(Id(), "roughness", p.roughness);
    CheckUnit(Id(), "metallic", p.metallic);
    CheckUnit(Id(), "opacity", p.opacity);
    if (!(std::isfinite(p.ior) && p.ior >= 1))
      throw std::runtime_error("material " + Id() + ": ior = " + std::to_string(p.ior) + " must be finite and >= 1");
    CheckUnit(Id(), "opacityThreshold", p.opacityThreshold);
    CheckUnit(Id(), "clearcoat", p.clearcoat);
    CheckUnit(Id(), "clearcoatRoughness", p.clearcoatRoughness);
    CheckColor(Id(), "specularColor", p.specularColor);
    MaterialTextures textures;
    for (int i = 0; i < kMaterialInputCount; ++i) {
      const TextureInput& input = p.textures[std::size_t(i)];
      if (!input.Active()) continue;
      std::shared_ptr<const Texture> texture =
          renderParam ? renderParam->Textures().Get(input.texture) : Texture::Open(input.texture);
      if (!texture->Valid() && renderParam)
        renderParam->Warn("material " + Id() + ": " + kInputNames[std::size_t(i)] + ": " + texture->Error() +
                          "; its fallback is used");
      textures[std::size_t(i)] = {std::move(texture), input};
    }
    params_ = p;
    textures_ = std::move(textures);
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
