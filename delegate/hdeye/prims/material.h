#pragma once
// A material sprim: the UsdPreviewSurface subset the renderer shades with (see previewSurface.h for
// the BSDF). Sync validates every parameter and loads diffuseTexture through RenderParam::Textures().
#include "hdeye/hd/prim.h"
#include "hdeye/render/texture.h"

#include <memory>

namespace hdeye {

class Material final : public Sprim {
 public:
  using Sprim::Sprim;
  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::DirtyParams; }
  /// Throws std::runtime_error naming the prim and the attribute if a parameter is out of range
  /// (roughness, metallic, opacity outside [0, 1]; ior below 1; a colour negative or not finite) or
  /// the diffuse texture cannot be read. The previous parameters stay in place on failure.
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  const MaterialParams& Params() const { return params_; }
  /// The loaded diffuseTexture, or null if none is set. Owned by the render param's TextureCache
  /// and by this material; valid while the material lives.
  const Texture* DiffuseTexture() const { return diffuseTexture_.get(); }

 private:
  MaterialParams params_;
  std::shared_ptr<const Texture> diffuseTexture_;
};

}  // namespace hdeye
