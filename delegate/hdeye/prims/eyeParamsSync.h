#pragma once
// What an eye prim (analytic or on a mesh) reads from its scene delegate when its params are dirty.
#include "hdeye/hd/sceneDelegate.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/render/texture.h"

#include <memory>
#include <string>

namespace hdeye {

/// Reads prim `id`'s EyeParams into *params, validates its chamber, and opens its iris texture (nullptr for none)
/// into *irisTexture through the render delegate's texture cache. Throws std::runtime_error naming the prim as
/// "<kind> <id>: ..." (kind "eye", "eye mesh") when the chamber is invalid (*params is then already updated and
/// *irisTexture left as it was). A texture that cannot be read is a RenderParam warning; its lookups are magenta.
void SyncEyeParams(SceneDelegate* sceneDelegate, RenderParam* renderParam, const std::string& kind, const PrimId& id,
                   EyeParams* params, std::shared_ptr<const Texture>* irisTexture);

}  // namespace hdeye
