#pragma once
// What every Sync receives (HdEmbreeRenderParam's role): the one door through which prims edit the
// Embree scene, which also bumps the scene version so render passes know to restart.
#include "hdeye/params/motion.h"
#include "hdeye/render/texture.h"

#include <embree3/rtcore.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace hdeye {

class RenderParam {
 public:
  RenderParam(RTCDevice device, RTCScene scene) : device_(device), scene_(scene) {}

  /// The root scene, for editing. Every call marks the scene changed.
  RTCScene AcquireSceneForEdit() {
    ++sceneVersion_;
    return scene_;
  }
  RTCDevice Device() const { return device_; }
  std::uint64_t SceneVersion() const { return sceneVersion_; }
  /// While set (a render plan will run before rendering), a mesh without a planned level refines to level 0 at
  /// its first topology sync; the plan then raises what needs more (plan/meshRefinePlan.h).
  void SetMeshLevelsAwaitPlan(bool await) { meshLevelsAwaitPlan_ = await; }
  bool MeshLevelsAwaitPlan() const { return meshLevelsAwaitPlan_; }
  /// The shutter of the camera being rendered (RenderPass sets it before syncing): prims with motion samples build
  /// their Embree motion over it, and evaluate their samples at its time when it is closed.
  void SetShutter(const Shutter& shutter) { shutter_ = shutter; }
  const Shutter& GetShutter() const { return shutter_; }
  /// Textures (material, iris, dome) by file path, loaded once per render delegate and shared by the
  /// prims that use them. Thread-safe; lives as long as the render delegate.
  TextureCache& Textures() { return textures_; }
  /// Records a problem that does not stop the render (a texture that cannot be read: its fallback is
  /// used), once per message. Thread-safe.
  void Warn(const std::string& message) {
    std::lock_guard<std::mutex> lock(warningsMutex_);
    for (const std::string& w : warnings_)
      if (w == message) return;
    warnings_.push_back(message);
  }
  /// Every message recorded by Warn, in order.
  std::vector<std::string> Warnings() {
    std::lock_guard<std::mutex> lock(warningsMutex_);
    return warnings_;
  }

 private:
  RTCDevice device_;
  RTCScene scene_;
  std::uint64_t sceneVersion_ = 0;
  bool meshLevelsAwaitPlan_ = false;
  Shutter shutter_;
  TextureCache textures_;
  std::mutex warningsMutex_;
  std::vector<std::string> warnings_;
};

}  // namespace hdeye
