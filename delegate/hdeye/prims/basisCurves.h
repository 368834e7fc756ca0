#pragma once
// A BasisCurves rprim (HdBasisCurves' role): linear and cubic (bezier, bspline, catmullRom) curves, open,
// periodic or pinned, as Embree curves in a prototype scene under one instance. Without authored normals they
// are round tubes (RTC_GEOMETRY_TYPE_ROUND_*); with normals, ribbons facing them
// (RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_*; linear ribbons are taken as bezier segments with their control points at
// the thirds, the same straight ribbon). Widths ("widths", diameters in object space) per curve, vertex or
// varying. Shaded by the bound material at the curve's surface normal, or by displayColor (constant, uniform, vertex
// or varying; blended along each segment) without one; curves cast shadows like any geometry.
#include "hdeye/prims/instancedGeometry.h"

namespace hdeye {

class BasisCurves final : public InstancedRprim {
 public:
  explicit BasisCurves(PrimId id) : InstancedRprim(std::move(id)) {}
  /// Embree segments built at the last sync (tests).
  int SegmentCount() const { return segmentCount_; }

 private:
  DirtyBits GeometryBits() const override { return dirty::DirtyTopology | dirty::DirtyPoints | dirty::DirtyPrimvar; }
  void SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam) override;

  int segmentCount_ = 0;
  std::vector<Vec3f> displayColor_;  ///< GeometryContext::displayColor: 3 per segment (SegmentEndColors), or empty
};

}  // namespace hdeye
