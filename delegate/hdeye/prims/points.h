#pragma once
// A Points rprim (HdPoints' role): spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT) at the points, of diameter "widths"
// (constant or per point, object space; 1 when not authored), in a prototype scene under one instance, shaded by
// the bound material.
#include "hdeye/hd/prim.h"
#include "hdeye/prims/instancedGeometry.h"

namespace hdeye {

class Points final : public Rprim {
 public:
  explicit Points(PrimId id) : Rprim(std::move(id)) {}

  DirtyBits GetInitialDirtyBitsMask() const override;
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  void Finalize(RenderParam* renderParam) override { geometry_.Release(renderParam); }
  PrimId MaterialId() const override { return materialId_; }
  GeometryContext* Context() override { return &context_; }

 private:
  void SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam);

  InstancedGeometry geometry_;
  GeometryContext context_;
  PrimId materialId_;
};

}  // namespace hdeye
