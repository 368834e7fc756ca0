#pragma once
// One Embree geometry in a prototype scene of its own, placed in the root scene by one instance: what the
// rprims that are not meshes (curves, points) share. Mesh keeps its own (its eye-mesh filters and refit).
#include "hdeye/hd/prim.h"
#include "hdeye/prims/motionSync.h"
#include "hdeye/prims/renderParam.h"
#include "hdeye/render/renderContext.h"

#include <embree3/rtcore.h>

namespace hdeye {

class InstancedGeometry {
 public:
  InstancedGeometry() = default;
  InstancedGeometry(const InstancedGeometry&) = delete;
  InstancedGeometry& operator=(const InstancedGeometry&) = delete;

  /// Replaces the geometry (a new, uncommitted Embree geometry whose buffers are filled; ownership taken) and
  /// commits it in a new prototype scene under a new instance whose user data is an InstanceContext of `context`.
  void Reset(RenderParam* renderParam, RTCGeometry geometry, GeometryContext* context);
  /// The instance's object-to-world transform (and the context's normal transform); `motion` (on Embree's steps,
  /// SteppedMotion), when set, moves it over the shutter.
  void SetTransform(RenderParam* renderParam, const Matrix4d& transform, GeometryContext* context,
                    std::shared_ptr<const TransformMotion> motion = nullptr);
  void SetVisible(RenderParam* renderParam, bool visible);
  /// Detaches and releases everything (safe to call twice).
  void Release(RenderParam* renderParam);
  bool Empty() const { return instance_ == nullptr; }

 private:
  RTCScene prototype_ = nullptr;
  RTCGeometry geometry_ = nullptr;
  RTCGeometry instance_ = nullptr;
  unsigned instanceId_ = RTC_INVALID_GEOMETRY_ID;
  Matrix4d transform_{1.0};
  std::shared_ptr<const TransformMotion> motion_;
  bool visible_ = true;
  InstanceContext instanceContext_;  ///< the instance's user data, as the renderer reads every instance's
};

/// An rprim drawn as one InstancedGeometry (curves, points): Sync rebuilds the geometry when `GeometryBits()` are
/// dirty (SyncGeometry), and updates the transform (with its motion over the shutter), visibility and material
/// binding in place. XXX: their points render at the shutter's opening (no deformation blur for curves and points).
class InstancedRprim : public Rprim {
 public:
  explicit InstancedRprim(PrimId id) : Rprim(std::move(id)) {}

  DirtyBits GetInitialDirtyBitsMask() const override;
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  void Finalize(RenderParam* renderParam) override { geometry_.Release(renderParam); }
  PrimId MaterialId() const override { return materialId_; }
  GeometryContext* Context() override { return &context_; }

 protected:
  /// The dirty bits whose data the geometry is built from (points, primvars, topology).
  virtual DirtyBits GeometryBits() const = 0;
  /// Builds the Embree geometry from the scene delegate's data and hands it to Geometry().Reset.
  virtual void SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) = 0;
  InstancedGeometry& Geometry() { return geometry_; }
  GeometryContext& ContextData() { return context_; }

 private:
  InstancedGeometry geometry_;
  GeometryContext context_;
  PrimId materialId_;
};

}  // namespace hdeye
