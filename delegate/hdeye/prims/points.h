#pragma once
// A Points rprim (HdPoints' role): spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT) at the points, of diameter "widths"
// (constant or per point, object space; 1 when not authored), in a prototype scene under one instance, shaded by
// the bound material, or by displayColor (constant or per point) without one.
#include "hdeye/prims/instancedGeometry.h"

namespace hdeye {

class Points final : public InstancedRprim {
 public:
  explicit Points(PrimId id) : InstancedRprim(std::move(id)) {}

 private:
  DirtyBits GeometryBits() const override { return dirty::DirtyPoints | dirty::DirtyPrimvar; }
  void SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) override;

  std::vector<Vec3f> displayColor_;  ///< GeometryContext::displayColor: 3 equal values per point, or empty
};

}  // namespace hdeye
