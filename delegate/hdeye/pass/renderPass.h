#pragma once
// The render pass (HdRenderPass's role): a thin controller. Execute syncs the render index, commits
// the Embree scene if any prim edited it, hands the renderer the camera view, the light list and
// the bound AOV buffers with the progressive control (passes, callback, stop flag), and returns what the
// renderer did.
#include "hdeye/plan/renderPlan.h"
#include "hdeye/render/renderer.h"

#include <string>
#include <vector>

namespace hdeye {

class RenderIndex;

/// One AOV bound to a render buffer (HdRenderPassAovBinding's role). aovName: color, albedo,
/// normal, depth, primId, irisMnee, limbalArc or hitId (renderer.h: AovBuffers).
struct AovBinding {
  std::string aovName;
  PrimId renderBufferId;
};

class RenderPass {
 public:
  explicit RenderPass(RenderIndex* renderIndex) : index_(renderIndex) {}

  /// Syncs, gathers the materials and lights once, then renders in passes as `control` asks (renderer.h): the
  /// delegate's one progressive loop. Throws std::runtime_error with a one-line message for a missing camera or
  /// buffer, an unknown AOV name, or a prim whose data is bad.
  RenderStats Execute(const PrimId& cameraId, const std::vector<AovBinding>& bindings,
                      const ProgressiveControl& control = {});

  /// The render plan (renderPlan.h) for the camera and a width x height image, without rendering:
  /// syncs the index as Execute does, then measures and decides. Nothing is applied: the caller
  /// passes the plan to ApplyRenderPlan (or only prints it). Throws std::runtime_error like Execute.
  RenderPlan Plan(const PrimId& cameraId, int width, int height, const PlanOverrides& overrides,
                  const PlanRules& rules = {});

  /// The rprim of each primIndex (the primId AOV's and hitId's values) of the last Execute, in index order.
  const std::vector<PrimId>& PrimIdsByIndex() const { return primIdsByIndex_; }

 private:
  RenderIndex* index_;
  std::vector<PrimId> primIdsByIndex_;
  Renderer renderer_;
  std::uint64_t committedVersion_ = ~0ull;
};

}  // namespace hdeye
