#pragma once
// An eye with no mesh (the EyeAPI schema applied to an Xform): the analytic anterior segment alone,
// the cornea cap out to the 15.08 mm chord, closed below by the iris disk. It lives in Embree as user
// geometry whose intersection runs eyelib's exact kernel in the canonical frame.
#include "hdeye/hd/prim.h"
#include "hdeye/render/eyeGeometry.h"
#include "hdeye/render/renderContext.h"

#include <embree3/rtcore.h>

namespace hdeye {

class AnalyticEye final : public Rprim {
 public:
  using Rprim::Rprim;
  DirtyBits GetInitialDirtyBitsMask() const override {
    return dirty::InitRepr | dirty::DirtyParams | dirty::DirtyTransform | dirty::DirtyVisibility;
  }
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  void Finalize(RenderParam* renderParam) override;
  GeometryContext* Context() override { return &context_; }

 private:
  EyeParams params_;
  std::shared_ptr<const Texture> irisTexture_;  ///< EyeParams::irisTexture, loaded under DirtyParams
  Matrix4d transform_{1.0};
  std::shared_ptr<const TransformMotion> motion_;  ///< over the open shutter, or null
  EyeGeometry eye_;
  GeometryContext context_;
  RTCGeometry geometry_ = nullptr;
  unsigned geometryId_ = RTC_INVALID_GEOMETRY_ID;
};

}  // namespace hdeye
