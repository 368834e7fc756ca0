#pragma once
// An eye on a mesh (primTypes::kEyeMesh): a Mesh (the explicit, possibly animated eyeball that rays
// hit) that also carries an eye's parameters. A hit on it maps into the canonical frame
// (eyeMeshMapping.h); its cornea continues against the analytic model, its sclera shades as a surface.
// The analytic model owns the inside of the eyeball: the mesh is invisible to rays that meet it from
// inside (an Embree filter), so rays leaving the analytic cornea, and MNEE's shadow rays from the
// iris, never stop at the mesh they start under.
#include "hdeye/prims/mesh.h"
#include "hdeye/render/eyeGeometry.h"

#include <memory>

namespace hdeye {

class EyeMesh final : public Mesh {
 public:
  using Mesh::Mesh;
  DirtyBits GetInitialDirtyBitsMask() const override { return Mesh::GetInitialDirtyBitsMask() | dirty::DirtyParams; }
  /// Mesh sync, then the eye: EyeParams under DirtyParams (validated; the iris texture loaded through
  /// RenderParam::Textures()), the eye's transforms whenever params or the transform change.
  void Sync(SceneDelegate* sceneDelegate, RenderParam* renderParam, DirtyBits* dirtyBits) override;
  const EyeGeometry& Eye() const { return eye_; }
  /// The scene's level, capped by the render plan's (EyeRenderOptions::refineLevel) when one is applied: the
  /// plan subdivides an eye only as far as its size on screen needs (docs/render_plan.md, sweep refine).
  int RefineLevelFor(int sceneLevel) override;

 private:
  void ConfigureTriangles(RTCGeometry triangles) override;
  /// The eye's frames from the transform, the params and the points (eyeMeshMapping.h): the rigid frame
  /// and the projection (re-projection), or the best-fit affine frame (the baseline); the outward sign.
  void SyncEyeFrames();

  EyeParams params_;
  std::shared_ptr<const Texture> irisTexture_;
  EyeGeometry eye_;
};

}  // namespace hdeye
