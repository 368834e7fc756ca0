#include "hdeye/material.h"

#include <cmath>
#include <stdexcept>

namespace hdeye {

void Material::Sync(SceneDelegate* sceneDelegate, RenderParam*, DirtyBits* dirtyBits) {
  if (*dirtyBits & dirty::DirtyParams) {
    const MaterialParams p = sceneDelegate->GetMaterialParams(Id());
    for (float c : {p.diffuseColor.r, p.diffuseColor.g, p.diffuseColor.b})
      if (!(c >= 0 && c <= 1)) throw std::runtime_error("material " + Id() + ": diffuseColor must be in [0, 1]");
    params_ = p;
  }
  *dirtyBits = dirty::Clean;
}

}  // namespace hdeye
