#pragma once
// A material sprim: the UsdPreviewSurface subset the renderer shades with.
#include "hdeye/prim.h"

namespace hdeye {

class Material final : public Sprim {
 public:
  using Sprim::Sprim;
  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::DirtyParams; }
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  const MaterialParams& Params() const { return params_; }

 private:
  MaterialParams params_;
};

}  // namespace hdeye
