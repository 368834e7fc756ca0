#pragma once
// An instancer (HdInstancer's role): the per-instance transforms (and optional displayColors) that the rprims
// it draws are repeated with. It holds data only; each prototype rprim builds its own Embree instances over its
// one prototype scene from it, so memory grows with the prototypes, not with the instances. Nested instancing
// reaches it flattened: every instance transform is already the product down to world space.
#include "hdeye/hd/prim.h"
#include "hdeye/params/motion.h"

#include <memory>
#include <string>

#include <vector>

namespace hdeye {

class Instancer final : public Prim {
 public:
  using Prim::Prim;

  DirtyBits GetInitialDirtyBitsMask() const override { return dirty::DirtyInstancer; }
  /// Pulls the instance transforms and colours. Throws (naming the instancer) on a non-finite transform or a
  /// colour count other than 0 or one per instance.
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;

  /// Instance to world, column vectors; one per instance.
  const std::vector<Matrix4d>& InstanceTransforms() const { return transforms_; }
  /// One linear RGB colour per instance, or empty.
  const std::vector<Vec3f>& InstanceColors() const { return colors_; }
  /// Per instance, its authored motion (frames; SampleInstanceTransforms), or null where it has one sample or does
  /// not move; empty when no instance moves.
  const std::vector<std::shared_ptr<const TransformMotion>>& InstanceMotions() const { return motions_; }
  /// Motion samples skipped at the last sync (NaN, singular, mirrored), one line each; the prototypes' sync reports
  /// them (the render param's warnings live a layer above).
  const std::vector<std::string>& MotionWarnings() const { return motionWarnings_; }
  int SyncCount() const { return syncs_; }

 private:
  /// Per-instance motions from SampleInstanceTransforms (instances that do not move stay null).
  void SyncMotions(SceneDelegate* sceneDelegate, std::size_t count);

  std::vector<Matrix4d> transforms_;
  std::vector<Vec3f> colors_;
  std::vector<std::shared_ptr<const TransformMotion>> motions_;
  std::vector<std::string> motionWarnings_;
  int syncs_ = 0;
};

}  // namespace hdeye
