#pragma once
// What the renderer knows of a piece of geometry (HdEmbreePrototypeContext's role), stored as Embree
// geometry user data. The renderer sees these, never prim classes.
#include "hdeye/params/motion.h"
#include "hdeye/params/primParams.h"
#include "hdeye/render/eyeRenderOptions.h"
#include "hdeye/render/texture.h"

#include <embree3/rtcore.h>

#include <array>
#include <memory>
#include <vector>

namespace hdeye {

struct EyeGeometry;

/// A textured input as the renderer uses it: the opened texture (null: not textured) and its input.
struct BoundTexture {
  std::shared_ptr<const Texture> texture;
  TextureInput input;
};
using MaterialTextures = std::array<BoundTexture, kMaterialInputCount>;

/// A material as the renderer shades it: its parameters and its textured inputs (owned by the Material sprim).
struct SurfaceMaterial {
  MaterialParams params;
  const MaterialTextures* textures = nullptr;
  /// False for the fallback material (no material sprim bound), which shows the displayColor primvar as Hydra's
  /// fallback surface does; a bound UsdPreviewSurface shows its own diffuseColor.
  bool bound = false;
};

struct GeometryContext {
  int primIndex = -1;  ///< the primId AOV value
  /// Inverse transpose of the transform's linear part: analytic eyes and meshes drawn once (eye meshes, which are
  /// never instanced, map hits with it); an instanced mesh's are per instance, in InstanceContext.
  glm::dmat3 normalToWorld{1.0};
  SurfaceMaterial surface;  ///< the bound material (or the fallback), its textured inputs
  /// displayColor per rendered triangle corner (3 per triangle, corner order), or null.
  const std::vector<Vec3f>* displayColor = nullptr;
  const std::vector<int>* triangleVertices = nullptr;  ///< 3 per triangle: indices into points, normals, rest
  /// The rendered points (object space), for mapping a hit to its surface point exactly (eye meshes).
  const std::vector<Vec3f>* points = nullptr;
  /// Unit shading normals per vertex of the rendered triangles, object space (refined meshes: the limit
  /// normals; polygon meshes: smooth vertex normals), or null: the renderer then shades with the flat
  /// geometric normal. A zero normal (degenerate vertex) is allowed; the renderer falls back there too.
  const std::vector<Vec3f>* vertexNormals = nullptr;
  /// A mesh deforming over the shutter: its vertex normals at Embree's time steps 1.. (vertexNormals holds step 0's;
  /// the steps are uniform over the shutter), so shading normals follow the hit's time as its position does. Null:
  /// one step.
  const std::vector<std::vector<Vec3f>>* laterStepNormals = nullptr;
  /// Authored normals per rendered triangle corner (3 per triangle), object space, unit or zero; when
  /// set they replace vertexNormals (polygon meshes only: subdivided meshes keep their limit normals).
  const std::vector<Vec3f>* cornerNormals = nullptr;
  const std::vector<Vec2f>* st = nullptr;  ///< 3 per rendered triangle (corner order), or null
  /// Rest positions per rendered point (object space; refined to the limit like the points), or null.
  const std::vector<Vec3f>* restPoints = nullptr;
  const EyeGeometry* eye = nullptr;  ///< set for analytic eyes (user geometry): shaded through the analytic model
  /// Set for eye meshes: a hit maps into the eye's canonical frame (EyeMeshHitToCanonical) and continues
  /// against the analytic model; hits from inside the mesh are ignored (the analytic model owns the inside).
  const EyeGeometry* meshEye = nullptr;
  /// Per-face materials (geomSubsets): per rendered triangle, an index into subsetMaterials, or -1 for the
  /// prim's own `surface`; null when the prim has no subsets.
  const std::vector<int>* triangleSubsets = nullptr;
  std::vector<SurfaceMaterial> subsetMaterials;
  /// The mesh's own Embree scene (object space, its triangles alone), or null: an eye mesh's sclera walk
  /// finds the eyeball's boundary in it, never in the rest of the scene.
  RTCScene prototypeScene = nullptr;
  /// Eyes (analytic and mesh): the render plan's per-eye switches, written by ApplyRenderPlan. Kept here,
  /// in the rprim's context, because the context outlives sync while EyeGeometry is rebuilt by it.
  EyeRenderOptions eyeOptions;
  /// The mesh is an open surface (it has boundary edges): its glass part, if its material has opacity < 1, is a
  /// thin sheet that transmits straight through and lets shadow rays pass (thinWalls.h).
  bool thinWalled = false;
};

/// What the renderer knows of one Embree instance of a mesh (HdEmbreeInstanceContext's role), stored as the
/// instance geometry's user data: the prototype's context, shared by all its instances, and what differs per
/// instance. A mesh drawn once has one; an instanced mesh one per instance over the same prototype scene.
struct InstanceContext {
  const GeometryContext* geometry = nullptr;  ///< the prototype mesh's context
  glm::dmat3 normalToWorld{1.0};              ///< inverse transpose of this instance's object-to-world linear part
  /// The instancer's displayColor for this instance (linear RGB), replacing the mesh's colour when hasColor.
  Vec3f color{0};
  bool hasColor = false;
  int instanceIndex = 0;  ///< the instance's index in its instancer (0 when drawn once)
  /// The instance's object-to-world motion over the open shutter, on the steps Embree interpolates (frames), or null:
  /// static. Its normals then follow the hit's time.
  std::shared_ptr<const TransformMotion> motion;
};

}  // namespace hdeye
