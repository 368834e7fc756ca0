#pragma once
// A material sprim: the UsdPreviewSurface subset the renderer shades with (see previewSurface.h for
// the BSDF). Sync validates every parameter and opens the textured inputs through RenderParam::Textures();
// a texture that cannot be read is a warning (RenderParam::Warn) and its fallback is used.
#include "hdeye/hd/prim.h"
#include "hdeye/render/renderContext.h"

#include <memory>

namespace hdeye {

class Material final : public Sprim {
 public:
  using Sprim::Sprim;
  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::DirtyParams; }
  /// Throws std::runtime_error naming the prim and the attribute if a parameter is out of range
  /// (roughness, metallic, opacity, opacityThreshold, clearcoat, clearcoatRoughness outside [0, 1]; ior
  /// below 1; a colour negative or not finite). The previous parameters stay in place on failure.
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  const MaterialParams& Params() const { return params_; }
  /// The textured inputs, indexed by MaterialInput; valid while the material lives.
  const MaterialTextures& Textures() const { return textures_; }

 private:
  MaterialParams params_;
  MaterialTextures textures_;
};

}  // namespace hdeye
