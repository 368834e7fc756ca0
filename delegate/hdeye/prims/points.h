#pragma once
// A Points rprim (HdPoints' role): spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT) at the points, of diameter "widths"
// (constant or per point, object space; 1 when not authored), in a prototype scene under one instance, shaded by
// the bound material.
#include "hdeye/prims/instancedGeometry.h"

namespace hdeye {

class Points final : public InstancedRprim {
 public:
  explicit Points(PrimId id) : InstancedRprim(std::move(id)) {}

 private:
  DirtyBits GeometryBits() const override { return dirty::DirtyPoints | dirty::DirtyPrimvar; }
  void SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) override;
};

}  // namespace hdeye
