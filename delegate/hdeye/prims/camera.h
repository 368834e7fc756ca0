#pragma once
// A camera sprim (HdCamera's role): perspective or orthographic, looking down its local -z axis.
#include "hdeye/hd/prim.h"
#include "hdeye/render/cameraView.h"

namespace hdeye {

class Camera final : public Sprim {
 public:
  using Sprim::Sprim;
  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::DirtyTransform | dirty::DirtyParams; }
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;

  const CameraView& View() const { return view_; }

 private:
  CameraView view_;
};

}  // namespace hdeye
