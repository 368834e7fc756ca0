#pragma once
// A light sprim (UsdLux subset): sphere, distant, rect, disk, dome. Holds its parameters and
// transform; GatherLights turns the index's lights into the renderer's world-space light list.
#include "hdeye/hd/prim.h"
#include "hdeye/params/motion.h"
#include "hdeye/render/renderLight.h"

#include <memory>
#include <vector>

namespace hdeye {

class Light final : public Sprim {
 public:
  /// The light's kind is its prim type (as in Hydra), not a parameter: LightParams::type is ignored.
  Light(PrimId id, LightType type) : Sprim(std::move(id)), type_(type) {}
  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::DirtyTransform | dirty::DirtyParams; }
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;

  const LightParams& Params() const { return params_; }
  const Matrix4d& Transform() const { return transform_; }
  /// The light's motion over the open shutter (frames), or null: static at Transform().
  const std::shared_ptr<const TransformMotion>& Motion() const { return motion_; }
  /// A dome's texture with its sampling distribution, loaded through RenderParam::Textures() when
  /// the params change; null for other lights and a constant dome.
  std::shared_ptr<const DomeTexture> Dome() const { return dome_; }
  /// A rect light's texture (UsdLux inputs:texture:file), opened through RenderParam::Textures(); null
  /// for other lights and an untextured rect.
  std::shared_ptr<const Texture> RectImage() const { return rectImage_; }

 private:
  LightType type_;
  LightParams params_;
  std::shared_ptr<const DomeTexture> dome_;
  std::shared_ptr<const Texture> rectImage_;
  Matrix4d transform_{1.0};
  std::shared_ptr<const TransformMotion> motion_;
};

class RenderIndex;

/// One light sprim as the renderer sees it: its id, the sprim (for its link collections) and its world-space
/// RenderLight (with its motion over the shutter, where it moves).
struct GatheredLight {
  PrimId id;
  const Light* prim = nullptr;
  RenderLight light;
};

/// The index's lights, the one place they are gathered: in the sprim map's order (by id), which is the order of the
/// list RenderPass::Execute hands the renderer (it marks the link collections), of the lights the render plan
/// measures, and of the plan's per-light switches (RenderLightOrder).
std::vector<GatheredLight> GatherLights(const RenderIndex& index);

}  // namespace hdeye
