#pragma once
// A BasisCurves rprim (HdBasisCurves' role): linear and cubic (bezier, bspline, catmullRom) curves, open,
// periodic or pinned, as Embree curves in a prototype scene under one instance. Without authored normals they
// are round tubes (RTC_GEOMETRY_TYPE_ROUND_*); with normals, ribbons facing them
// (RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_*; linear ribbons are taken as bezier segments with their control points at
// the thirds, the same straight ribbon). Widths ("widths", diameters in object space) per curve, vertex or
// varying. Shaded by the bound material at the curve's surface normal; curves cast shadows like any geometry.
#include "hdeye/hd/prim.h"
#include "hdeye/prims/instancedGeometry.h"

#include <vector>

namespace hdeye {

class BasisCurves final : public Rprim {
 public:
  explicit BasisCurves(PrimId id) : Rprim(std::move(id)) {}

  DirtyBits GetInitialDirtyBitsMask() const override;
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  void Finalize(RenderParam* renderParam) override { geometry_.Release(renderParam); }
  PrimId MaterialId() const override { return materialId_; }
  GeometryContext* Context() override { return &context_; }
  /// Embree segments built at the last sync (tests).
  int SegmentCount() const { return segmentCount_; }

 private:
  void SyncGeometry(SceneDelegate* sceneDelegate, RenderParam* renderParam);

  InstancedGeometry geometry_;
  GeometryContext context_;
  PrimId materialId_;
  int segmentCount_ = 0;
};

}  // namespace hdeye
